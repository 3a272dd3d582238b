"""The scene schema: its version and migrations, the accepted ranges of its fields, and
the validators of single fields (objects, integers, texts, output times, profiles).

:func:`core.scene.scene_from_dict` (built in :mod:`core.scene.validate`) checks a whole
scene with these; every refusal is a ``ValueError`` whose message starts with the path of
the field (``coating[1].modulus: ...``). The schema itself is documented in
``core/SCENES.md``.
"""

from __future__ import annotations

import copy
import difflib
import json
import math
import numbers
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np

from core import limits
from core.cache import StageCache, fingerprint
from core.coating import DEFAULT_INTERFACE, DEFAULT_MODEL_TOL, INTERFACES, MODEL_TOL_RANGE
from core.contact import CONTACT_MODELS
from core.problem import QUANTITIES
from core.profiles import Profile, check_range, profile_from_spec
from core.validation import finite_number, positive_number, show_value

#: The schema version this program writes and reads.
SCHEMA_VERSION = 1
#: Largest scene file accepted by :func:`core.scene.load_scene` [bytes].
MAX_SCENE_BYTES = limits.MAX_SCENE_BYTES
#: Number of coating layers accepted.
MAX_LAYERS = 10
#: Largest number of output times.
MAX_TIMES = limits.MAX_SCENE_TIMES
#: Latest output time [day after loading].
MAX_DAYS = limits.MAX_SCENE_DAYS
#: Oldest base at loading [day].
MAX_AGE = limits.MAX_SCENE_AGE
#: Accepted range of the solver's relative tolerance, and its default.
TOL_RANGE = (1e-12, 1e-2)
DEFAULT_TOL = 1e-6
#: Most points of (-a, a) where a profile may jump or kink (see
#: ``core.scene.validate._check_breakpoints``).
MAX_BREAKPOINTS = limits.MAX_BREAKPOINTS
#: Accepted range of the dimensionless coating compliance m*: physical coatings are far
#: inside it; the solver was measured finite for 1e-100 to 1e100.
M_STAR_RANGE = (1e-30, 1e30)
#: Accepted range of a Young's modulus [Pa], of each coating layer everywhere and of the
#: base at loading: the softest gels (~1e4 Pa) to beyond diamond (~1.2e12 Pa). A modulus
#: given in MPa or GPa where Pa is asked (800 for an 800 MPa polymer, 30 for C30/37's
#: 33 GPa) falls below it; a coating of 1e-3 Pa was solved to a settlement of 5265 km.
MODULUS_RANGE = (1e4, 1e13)
#: Largest accepted gap between punch and coating surface, in half-widths a.
MAX_GAP_RATIO = 1e3
#: Accepted range of a / H (the limits and their measured cost: core/limits.py).
LAM_RANGE = (limits.MIN_LAM, limits.MAX_SCENE_LAM)
#: Largest accepted creep coefficient E(tau0) C(t_end, tau0) (concrete: 1 to 5). The
#: time stepping was measured at 1.9 s for 1000 (tol 1e-8), 32 s for 1e4 (tol 1e-8) and
#: 13 s for 9e7 (tol 1e-3), the last two stopping at the step limit.
MAX_CREEP_COEFFICIENT = 1e3

#: The key a scene or study file may carry to name its JSON Schema (any string; ignored
#: by the validation, see core/SCENES.md "JSON Schema").
SCHEMA_KEY = "$schema"


@dataclass(frozen=True)
class FieldRule:
    """One field of an object of a scene file: the table :data:`FIELDS` holds them all.

    ``kind`` says what the value is: ``"number"``, ``"integer"``, ``"text"``,
    ``"choice"`` (one of ``choices``), ``"x_profile"`` (a function of x [m] on [-a, a]),
    ``"t_profile"`` (a function of t [day after loading]), ``"object"`` (the object of
    that name in :data:`FIELDS`), ``"layers"`` (a list of ``"coating[k]"`` objects),
    ``"times"``, ``"creep"`` or ``"punches"`` (a list of ``"punches[k]"`` objects; see
    core/SCENES.md). ``low``/``high`` bound a number
    (or every value of a profile), exclusive where ``low_open``/``high_open``; ``least``
    and ``most`` bound a text's length or a list's entries. The validator
    (:func:`core.scene.scene_from_dict`) and the JSON Schema
    (:mod:`core.scene.json_schema`) both read this table.
    """

    name: str
    kind: str
    unit: str
    description: str
    required: bool = True
    low: float | None = None
    high: float | None = None
    low_open: bool = False
    high_open: bool = False
    choices: tuple[str, ...] = ()
    least: int | None = None
    most: int | None = None
    default: Any = None


def _rule(name: str, kind: str, unit: str, description: str, **rest: Any) -> FieldRule:
    return FieldRule(name, kind, unit, description, **rest)


#: Accepted range of a Poisson ratio, both ends open (a stable isotropic solid).
POISSON_RANGE = (-1.0, 0.5)
_POISSON = {"low": POISSON_RANGE[0], "high": POISSON_RANGE[1], "low_open": True,
            "high_open": True}

#: The fields of each object of a scene file, by the object's path (``"coating[k]"`` for
#: every layer): names, whether required, units, ranges and meaning.
FIELDS: Mapping[str, tuple[FieldRule, ...]] = MappingProxyType({
    "scene": (
        _rule("schema_version", "integer", "-", f"Version of the scene schema: "
              f"{SCHEMA_VERSION}.", low=SCHEMA_VERSION, high=SCHEMA_VERSION),
        _rule("name", "text", "-", "Name of the scene (not empty).", least=1,
              most=limits.MAX_NAME_CHARS),
        _rule("description", "text", "-", "Teaching text shown in the explorer.",
              required=False, most=limits.MAX_DESCRIPTION_CHARS, default=""),
        _rule("punch", "object", "-", "The rigid punch (or give punches instead of punch "
              "and loading)."),
        _rule("coating", "layers", "-", f"Coating layers, top (under the punch) first, 0 to "
              f"{MAX_LAYERS} (none: the punch on the bare base, in full contact).", least=0,
              most=MAX_LAYERS),
        _rule("base", "object", "-", "The aging viscoelastic base layer."),
        _rule("loading", "object", "-", "Exactly two of settlement [m], tilt [rad], force "
              "[N/m], moment [N·m/m], each a function of t [day after loading], forming one of "
              "the four statements."),
        _rule("times", "times", "day", "Output times after loading: {end, count, spacing} "
              f"or a list of 1 to {MAX_TIMES} increasing days after loading."),
        _rule("solver", "object", "-", "Solver settings.", required=False),
        _rule("limits", "object", "-", "Limits of the design check (each optional; a limit "
              "left out is not checked).", required=False),
        _rule("punches", "punches", "-", f"Several rigid punches on the one foundation, 1 to "
              f"{limits.MAX_PUNCHES}, each with its centre, half-width, shape and loading "
              "(instead of punch and loading; core/SCENES.md 'Several punches').",
              required=False, least=1, most=limits.MAX_PUNCHES),
    ),
    "punches[k]": (
        _rule("center", "number", "m", "Position of the punch's centre along the surface "
              "(the zones of two punches must not overlap or touch)."),
        _rule("half_width", "number", "m", "Half-width a of the punch.", low=0.0,
              low_open=True),
        _rule("shape", "x_profile", "m", "Height f(x) of the punch base above its lowest "
              "point, x [m] from its own centre on [-a, a] (0: a flat punch).",
              required=False, default=0.0),
        _rule("loading", "object", "-", "This punch's loading: exactly two of settlement "
              "[m], tilt [rad], force [N/m], moment [N] (about its own centre), each a "
              "function of t [day after loading]."),
    ),
    "punch": (
        _rule("half_width", "number", "m", "Half-width a of the punch.", low=0.0,
              low_open=True),
        _rule("shape", "x_profile", "m", "Height f(x) of the punch base above its lowest "
              "point, x [m] from the centre on [-a, a] (0: a flat punch).", required=False,
              default=0.0),
    ),
    "coating[k]": (
        _rule("thickness", "x_profile", "m", "Thickness h_k(x) of the layer, > 0.", low=0.0,
              low_open=True),
        _rule("modulus", "x_profile", "Pa", "Young's modulus E_k(x) of the layer, in "
              f"[{MODULUS_RANGE[0]:g}, {MODULUS_RANGE[1]:g}].", low=MODULUS_RANGE[0],
              high=MODULUS_RANGE[1]),
        _rule("poisson", "x_profile", "-", "Poisson ratio nu_k(x) of the layer, in (-1, 0.5).",
              **_POISSON),
        _rule("interface", "choice", "-", "How the layer is joined to what lies under it.",
              required=False, choices=INTERFACES, default=DEFAULT_INTERFACE),
    ),
    "base": (
        _rule("thickness", "number", "m", f"Thickness H of the base (a/H in [{LAM_RANGE[0]:g}, "
              f"{LAM_RANGE[1]:g}]).", low=0.0, low_open=True),
        _rule("poisson", "number", "-", "Poisson ratio nu of the base, in (-1, 0.5).",
              **_POISSON),
        _rule("age_at_loading", "number", "day", "Age tau0 of the base when the load is "
              "applied (the base is made at age 0).", low=0.0, low_open=True, high=MAX_AGE),
        _rule("creep", "creep", "-", "Creep model of the base (core/SCENES.md, 'Creep "
              "models')."),
    ),
    "loading": tuple(
        _rule(q, "t_profile", unit, f"Given {q} [{unit}], a function of t [day after "
              "loading].", required=False)
        for q, unit in zip(QUANTITIES, ("m", "rad", "N/m", "N·m/m"), strict=True)),
    "times": (
        _rule("end", "number", "day", "Last output time after loading.", low=0.0,
              low_open=True, high=MAX_DAYS),
        _rule("count", "integer", "-", "Number of output times.", low=1, high=MAX_TIMES),
        _rule("spacing", "choice", "-", "linear: equally spaced from 0; log: 0, then "
              "geometrically spaced from start to end.", required=False,
              choices=("linear", "log"), default="linear"),
        _rule("start", "number", "day", "First output time after 0 with log spacing "
              "(default end / 1000: the last three decades).", required=False, low=0.0,
              low_open=True, high=MAX_DAYS),
    ),
    "solver": (
        _rule("tol", "number", "-", "Relative tolerance of the solver (default 1e-6; with "
              "a design code's creep law the smallest of 1e-6, 1e-5, 1e-4, 1e-3 that its "
              "fit by exponentials can meet).", required=False,
              low=TOL_RANGE[0], high=TOL_RANGE[1], default=DEFAULT_TOL),
        _rule("contact", "choice", "-", "Contact model: auto (full contact unless it is "
              "lost), full or unilateral.", required=False,
              choices=("auto", *(c for c in CONTACT_MODELS if c != "auto")), default="auto"),
        _rule("model_tol", "number", "-", "Coating-model error a result may carry "
              "unflagged (flag model_error).", required=False, low=MODEL_TOL_RANGE[0],
              high=MODEL_TOL_RANGE[1], default=DEFAULT_MODEL_TOL),
    ),
    "limits": (
        _rule("allowable_pressure", "number", "Pa", "Allowable bearing pressure: the "
              "largest contact pressure q over x and the whole history must not exceed it.",
              required=False, low=0.0),
        _rule("settlement_limit", "number", "m", "Largest settlement allowed (its "
              "magnitude, over the whole history).", required=False, low=0.0),
        _rule("tilt_limit", "number", "rad", "Largest tilt allowed, either way (its "
              "magnitude, over the whole history).", required=False, low=0.0),
    ),
})


def required_fields(obj: str) -> tuple[str, ...]:
    """The required fields of the object ``obj`` of :data:`FIELDS` (``"punch"``, ...)."""
    return tuple(r.name for r in FIELDS[obj] if r.required)


def optional_fields(obj: str) -> tuple[str, ...]:
    """The optional fields of the object ``obj`` of :data:`FIELDS`."""
    return tuple(r.name for r in FIELDS[obj] if not r.required)


def field_rule(obj: str, name: str) -> FieldRule:
    """The rule of field ``name`` of the object ``obj`` of :data:`FIELDS`."""
    return next(r for r in FIELDS[obj] if r.name == name)


#: Migrations from older schema versions: version -> function returning the next version.
#: Version 1 is the first; there is nothing to migrate yet.
_MIGRATIONS: dict[int, Callable[[dict], dict]] = {}

# Shared between scenes (a slider step makes a new scene and changes one field), keyed on
# exactly what it depends on. A validated profile holds its spec and a closure (a
# 10000-row table ~0.5 MB).
_PROFILES = StageCache("profiles", max_items=512, max_bytes=32 * 2**20)


# --------------------------------------------------------------------- small validators


def _join(parent: str, key: str) -> str:
    return f"{parent}.{key}" if parent else key


def check_fields(obj: Any, path: str, required: Sequence[str],
                  optional: Sequence[str] = ()) -> Mapping[str, Any]:
    """``obj`` as a mapping with exactly the allowed fields, or a ValueError."""
    where = path or "scene"
    if not isinstance(obj, Mapping):
        raise ValueError(f"{where}: must be an object, got {show_value(obj)}")
    allowed = list(required) + list(optional)
    for key in obj:
        if key not in allowed:
            hint = difflib.get_close_matches(str(key), allowed, n=1)
            extra = f" (did you mean '{hint[0]}'?)" if hint else \
                f" (allowed: {', '.join(allowed)})"
            raise ValueError(f"{where}: unknown field {str(key)[:40]!r}{extra}")
    for key in required:
        if key not in obj:
            raise ValueError(f"{_join(path, key)}: required field is missing")
    return obj


def _poisson(value: Any, path: str) -> float:
    x = finite_number(value, path)
    lo, hi = POISSON_RANGE
    if not lo < x < hi:
        raise ValueError(f"{path}: must be in ({lo:g}, {hi:g}), got {show_value(value)}")
    return x


def integer_in_range(value: Any, path: str, lo: int, hi: int) -> int:
    x = finite_number(value, path)
    if not x.is_integer():
        raise ValueError(f"{path}: must be an integer, got {show_value(value)}")
    if not lo <= x <= hi:
        raise ValueError(f"{path}: must be an integer from {lo} to {hi}, got {int(x)}")
    return int(x)


def _text(value: Any, path: str, *, allow_empty: bool, most: int) -> str:
    if not isinstance(value, str):
        raise ValueError(f"{path}: must be a string, got {show_value(value)}")
    # checked first: a text field is echoed into titles, links and file names
    if len(value) > most:
        raise ValueError(f"{path}: must be at most {most} characters, has {len(value)}")
    if not allow_empty and not value.strip():
        raise ValueError(f"{path}: must not be empty")
    return value


def _jsonable(obj: Any) -> Any:
    """A deep copy of ``obj`` with numpy and tuple values turned into plain JSON types."""
    if isinstance(obj, Mapping):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _jsonable(obj.tolist())
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, numbers.Integral):
        return int(obj)
    if isinstance(obj, numbers.Real):
        x = float(obj)
        # JSON has no NaN or infinity; null marks a value that could not be computed
        return x if math.isfinite(x) else None
    return copy.deepcopy(obj)


# ------------------------------------------------------------------------ schema versions


def migrate(d: Mapping[str, Any]) -> dict[str, Any]:
    """Bring a scene dict of an older schema version to :data:`SCHEMA_VERSION`.

    Returns a new dict (the input is not modified). Version 1 is the first version of the
    schema, so today this only checks ``schema_version``; later versions will register
    one step per version in ``_MIGRATIONS``.
    """
    if not isinstance(d, Mapping):
        raise ValueError(f"scene: must be a JSON object, got {show_value(d)}")
    if "schema_version" not in d:
        raise ValueError(f"schema_version: required field is missing (this program reads "
                         f"{SCHEMA_VERSION})")
    raw = d["schema_version"]
    if isinstance(raw, bool) or not isinstance(raw, numbers.Real):
        raise ValueError(f"schema_version: must be an integer, got {show_value(raw)}")
    if isinstance(raw, numbers.Integral):
        version = int(raw)  # float() of a huge integer would overflow
    elif not math.isfinite(float(raw)) or not float(raw).is_integer():
        raise ValueError(f"schema_version: must be an integer, got {show_value(raw)}")
    else:
        version = int(raw)
    if version > SCHEMA_VERSION:
        raise ValueError(f"schema_version: unsupported version {version} "
                         f"(this program reads {SCHEMA_VERSION})")
    if version < 1:
        raise ValueError(f"schema_version: version {version} does not exist (the first "
                         f"version of the schema is 1; this program reads {SCHEMA_VERSION})")
    out = dict(d)
    while version < SCHEMA_VERSION:
        out = _MIGRATIONS[version](out)
        version += 1
        out["schema_version"] = version
    return out


# ------------------------------------------------------------------ profiles and times


def _profile(spec: Any, path: str, variable: str, domain: tuple[float, float], *,
             lower: float | None = None, upper: float | None = None,
             inclusive: bool = False) -> Profile:
    """Build a profile and check that its values lie in the open range (lower, upper)
    (closed with ``inclusive``).

    Profiles are immutable, so a validated one is shared by every scene that has it: a
    slider step changes one field, and checking every profile again on thousands of
    points was as costly as the solve itself (measured under 20 sessions)."""
    try:
        key = fingerprint("profile", json.dumps(spec, sort_keys=True, separators=(",", ":"),
                                                allow_nan=False),
                          path, variable, domain, lower, upper, inclusive)
    except (TypeError, ValueError):  # not plain JSON: validated without the memo
        return _checked_profile(spec, path, variable, domain, lower, upper, inclusive)
    return _PROFILES.get_or_compute(
        key, lambda: _checked_profile(spec, path, variable, domain, lower, upper,
                                      inclusive))[0]


def _checked_profile(spec: Any, path: str, variable: str, domain: tuple[float, float],
                     lower: float | None, upper: float | None,
                     inclusive: bool = False) -> Profile:
    profile = profile_from_spec(spec, field=path, variable=variable, domain=domain)
    try:
        check_range(profile, field=path, domain=domain, lower=lower, upper=upper,
                    lower_inclusive=inclusive, upper_inclusive=inclusive)
    except ValueError as exc:
        message = str(exc)
        # the position is in metres (x) or days after loading (t), the value in the
        # field's unit: say so
        unit = " m" if variable == "x" else " days after loading"
        if re.search(rf" at {variable} = \S+$", message):
            message += unit
        value_unit = _unit_of(path)
        if value_unit:
            message = re.sub(rf"(, is -?\d[\d.]*(?:e[+-]?\d+)?) at {variable} = ",
                             rf"\1 {value_unit} at {variable} = ", message, count=1)
        raise ValueError(message) from None
    return profile


def _unit_of(path: str) -> str:
    """The unit of the field at ``path`` (``coating[0].thickness``: ``m``) by its rule in
    :data:`FIELDS`; '' for a field without one (a ratio) or not in it."""
    obj, _, name = path.rpartition(".")
    obj = re.sub(r"\[\d+\]", "[k]", obj)
    if obj not in FIELDS or name not in {r.name for r in FIELDS[obj]}:
        return ""
    unit = field_rule(obj, name).unit
    return "" if unit == "-" else unit


def _times(spec: Any, path: str) -> tuple[np.ndarray, Any]:
    """The output times [day after loading] and their canonical spec (a list, a 1-D
    NumPy array of them, or ``{end, count, spacing}``)."""
    if isinstance(spec, np.ndarray) and spec.ndim == 1:
        spec = spec.tolist()  # as the profiles' tables take them
    if isinstance(spec, Mapping):
        check_fields(spec, path, ("end", "count"), ("spacing", "start"))
        end = positive_number(spec["end"], f"{path}.end")
        check_last_time(end, f"{path}.end")
        count = integer_in_range(spec["count"], f"{path}.count", 1, MAX_TIMES)
        spacing = spec.get("spacing", "linear")
        if spacing not in ("linear", "log"):
            raise ValueError(f"{path}.spacing: must be 'linear' or 'log', "
                             f"got {show_value(spacing)}")
        start = None
        if spec.get("start") is not None:
            start = positive_number(spec["start"], f"{path}.start")
            if spacing != "log":
                raise ValueError(f"{path}.start: sets the first time of log spacing only "
                                 f"(spacing is {show_value(spacing)}); remove it, or set "
                                 f"{path}.spacing 'log'")
            if not start < end:
                raise ValueError(f"{path}.start: must be < {path}.end ({end:g} days), got "
                                 f"{show_value(spec['start'])}")
        if count == 1:
            times = np.array([end])
        elif spacing == "linear":
            times = np.linspace(0.0, end, count)
        else:
            # the instant of loading, then count - 1 times geometrically spaced from start
            # (default: over the last three decades before ``end``; creep is fastest just
            # after loading, and over 50 years those begin at 18 days)
            first = end * 1e-3 if start is None else start
            if not first > 0.0:
                raise ValueError(f"{path}.end: too small for log-spaced times (a thousandth "
                                 f"of it is 0 in double precision), got {show_value(end)}")
            times = np.concatenate([[0.0], np.geomspace(first, end, count - 1)])
        times[-1] = end
        canonical = {"end": end, "count": count, "spacing": spacing}
        if start is not None:
            canonical["start"] = start
        return times, canonical
    if isinstance(spec, (list, tuple)):
        if not 1 <= len(spec) <= MAX_TIMES:
            raise ValueError(f"{path}: must list 1 to {MAX_TIMES} times, got {len(spec)}")
        values = []
        for i, value in enumerate(spec):
            t = finite_number(value, f"{path}[{i}]")
            if t < 0:
                raise ValueError(f"{path}[{i}]: must be >= 0 days after loading (times before "
                                 f"loading are not part of the problem), got {show_value(value)}")
            if values and t <= values[-1]:
                raise ValueError(f"{path}[{i}]: times must increase, got {show_value(value)} after "
                                 f"{show_value(values[-1])}")
            values.append(t)
        if values[-1] <= 0:
            raise ValueError(f"{path}: the last time must be > 0 days after loading (the "
                             "loads are functions of time on [0, last time])")
        check_last_time(values[-1], last_time_field(values, len(values), path))
        return np.array(values), values
    raise ValueError(f"{path}: must be an object {{end, count, spacing}} or a list of days "
                     f"after loading, got {show_value(spec)}")


def last_time_field(spec: Any, count: int, path: str = "times") -> str:
    """The field that holds the last output time of the times ``spec`` with ``count``
    times: ``times.end``, or the list's last entry ``times[k]``."""
    return f"{path}.end" if isinstance(spec, Mapping) else f"{path}[{count - 1}]"


def check_last_time(end: float, field: str, most: float = MAX_DAYS,
                    why: str = f"about {MAX_DAYS / limits.DAYS_PER_YEAR:.0f} years") -> None:
    """Refuse a last output time ``end`` [day after loading] past ``most``, naming
    ``field`` and saying ``why`` that bound."""
    if end > most:
        raise ValueError(f"{field}: must be <= {most:g} days after loading ({why}), got "
                         f"{end:g}")


def _spec_of(profile: Profile, given: Any) -> Any:
    """The canonical spec of a profile (its ``spec`` when it has one, else what was given)."""
    spec = getattr(profile, "spec", None)
    return given if spec is None else spec

