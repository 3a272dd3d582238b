"""The dimensional scene: schema (version 1), validation, JSON files and conversion.

A *scene* describes one physical problem in SI units with time in days: the punch, the
coating layers, the aging base, the loading and the output times (the schema is
documented in ``core/SCENES.md``). :func:`scene_from_dict` validates a JSON-like dict
and builds a :class:`Scene`; :func:`solve` converts it to the dimensionless problem of
:func:`core.solver.solve_dimensionless` (model notes, "Dimensionless problem") and the
answer back to a :class:`SceneSolution` in SI units.

Conversion (``a`` half-width, ``H`` base thickness, ``nu`` base Poisson ratio,
``tau0`` age at loading, ``E0 = E(tau0)``, ``t`` days after loading, ``age = tau0 + t``):

    x* = x / a,    lam = a / H,    t* = age / tau0 = (tau0 + t) / tau0,
    m*(x*) = E0 / (2 (1 - nu^2) a) * sum_k (1 - nu_k^2) h_k / E_k,
    g(x) = f(x) - sum_k h_k(x) - min over [-a, a] of the same,   g* = g / a,
    c(t*) = E(age) / E0,   delta* = delta / a,   alpha* = alpha,
    P* = 2 (1 - nu^2) P / (E(age) a),   M* = 2 (1 - nu^2) M / (E(age) a^2),
    q = E(age) q* / (2 (1 - nu^2)).

The base is taken to be made at age 0 (the seed's ``tau_b = 0``), so ages are counted
from its casting and the loading starts at ``age = tau0``. ``E0`` is the modulus at
loading so that ``c(1) = 1``.
"""

from __future__ import annotations

import copy
import difflib
import hashlib
import json
import math
import numbers
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np

from core import limits
from core.cache import StageCache, fingerprint
from core.coating_model import (
    DEFAULT_INTERFACE,
    DEFAULT_MODEL_TOL,
    INTERFACES,
    MODEL_TOL_RANGE,
    layer_compliance,
    model_error_estimate,
    tilt_share,
)
from core.creep import Elastic, UserKernel, creep_model_from_spec
from core.files import atomic_write_text, read_regular_file  # noqa: F401 (re-exported)
from core.golden_section import golden_minimum
from core.load_rates import check_step_limit, oscillations
from core.profiles import Profile, check_range, profile_from_spec
from core.scene_files import (  # noqa: F401 (re-exported: core.scene is the public path)
    load_scene,
    parse_scene_json,
    read_scene_json,
    save_scene,
    scene_to_json,
)
from core.statements import QUANTITIES, STATEMENTS  # noqa: F401 (re-exported)
from core.validation import (
    MAX_MAGNITUDE,
    NumberTooLarge,
    finite_number,
    positive_number,
    show_value,
)

if TYPE_CHECKING:
    from core.solver import ContactSolution

#: The schema version this program writes and reads.
SCHEMA_VERSION = 1
#: Largest scene file accepted by :func:`load_scene` [bytes].
MAX_SCENE_BYTES = limits.MAX_SCENE_BYTES
#: Number of coating layers accepted.
MAX_LAYERS = 10
#: Largest number of output times.
MAX_TIMES = limits.MAX_SCENE_TIMES
#: Accepted range of the solver's relative tolerance, and its default.
TOL_RANGE = (1e-12, 1e-2)
DEFAULT_TOL = 1e-6
#: The thin-coating model is doubtful where sum h_k exceeds this fraction of 2a.
THICK_COATING_RATIO = 0.1
#: Tilts beyond this many radians are not small.
LARGE_TILT = 0.01
#: Points of the default plotting grid :attr:`SceneSolution.x`.
PLOT_POINTS = 201
#: Most points of (-a, a) where a profile may jump or kink (see ``_check_breakpoints``).
MAX_BREAKPOINTS = limits.MAX_BREAKPOINTS
#: Accepted range of the dimensionless coating compliance m*: physical coatings are far
#: inside it; the solver was measured finite for 1e-100 to 1e100.
M_STAR_RANGE = (1e-30, 1e30)
# Shared between scenes (a slider step makes a new scene and changes one field): each
# keyed on exactly what it depends on. A validated profile holds its spec and a closure
# (a 10000-row table ~0.5 MB); the samples of one geometry are ~4100 points, 33 kB.
_PROFILES = StageCache("profiles", max_items=512, max_bytes=32 * 2**20)
_SAMPLE_X = StageCache("sample_x", max_items=128, max_bytes=16 * 2**20)
_GAP_MINIMUM = StageCache("gap_minimum", max_items=256, max_bytes=2**20)
#: Largest accepted gap between punch and coating surface, in half-widths a.
MAX_GAP_RATIO = 1e3
#: Accepted range of a / H (the limits and their measured cost: core/limits.py).
LAM_RANGE = (limits.MIN_LAM, limits.MAX_SCENE_LAM)
#: Largest accepted creep coefficient E(tau0) C(t_end, tau0) (concrete: 1 to 5). The
#: time stepping was measured at 1.9 s for 1000 (tol 1e-8), 32 s for 1e4 (tol 1e-8) and
#: 13 s for 9e7 (tol 1e-3), the last two stopping at the step limit.
MAX_CREEP_COEFFICIENT = 1e3
#: Uniform samples of [-a, a] for the gap minimum and the coating checks (on top of each
#: profile's own sample points).
DENSE_SAMPLES = 4001

#: One-line explanations of the flags a solution may carry.
FLAG_MESSAGES: dict[str, str] = {
    "contact_lost": "The computed pressure is negative somewhere: part of the punch base "
                    "lifts off, so this full-contact answer is not physical.",
    "thick_coating": f"The coating is thicker than {THICK_COATING_RATIO:g} of the punch width "
                     "somewhere: the thin (Winkler) coating model is doubtful.",
    "stiff_coating": "A coating layer is stiffer than the base at loading somewhere: the "
                     "thin-coating model assumes soft coatings.",
    "large_tilt": f"The tilt exceeds {LARGE_TILT:g} rad: the small-angle assumption is "
                  "doubtful.",
    "model_error": "The estimated error of the thin-coating model (info.model_error_estimate, "
                   "from measurements against a resolved finite-element model) exceeds "
                   "solver.model_tol: check the coating model (python -m core check).",
    "tol_not_met": "The solver could not reach the requested tolerance: see info.message.",
    "unresolved_input": "A profile has features finer than the quadrature resolves: "
                        "see info.message.",
    "contact_set_unverified": "The unilateral contact set failed its final check (q < 0 "
                              "on it, or the surfaces overlap off it): see info.message.",
}

UNITS: dict[str, str] = {
    "times": "day (after loading)",
    "settlement": "m",
    "tilt": "rad",
    "force": "N/m",
    "moment": "N",
    "x": "m (from the punch centre)",
    "pressure": "Pa (rows: x, columns: times)",
}

#: Migrations from older schema versions: version -> function returning the next version.
#: Version 1 is the first; there is nothing to migrate yet.
_MIGRATIONS: dict[int, Callable[[dict], dict]] = {}


# --------------------------------------------------------------------- small validators


def _join(parent: str, key: str) -> str:
    return f"{parent}.{key}" if parent else key


def _check_fields(obj: Any, path: str, required: Sequence[str],
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
    if not -1.0 < x < 0.5:
        raise ValueError(f"{path}: must be in (-1, 0.5), got {show_value(value)}")
    return x


def _integer(value: Any, path: str, lo: int, hi: int) -> int:
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


# ---------------------------------------------------------------------------- the scene


@dataclass(frozen=True, eq=False)
class Layer:
    """One coating layer: profiles of x [m] for ``thickness`` [m], ``modulus`` [Pa], ``poisson``;
    ``interface``: how it is joined to what lies under it (``"smooth"`` or ``"bonded"``)."""

    thickness: Profile
    modulus: Profile
    poisson: Profile
    interface: str = DEFAULT_INTERFACE


@dataclass(frozen=True, eq=False)
class Scene:
    """A validated scene (build it with :func:`scene_from_dict` or :func:`load_scene`).

    Lengths in metres, moduli in pascals, times in days. ``shape`` and the layer
    profiles are functions of ``x`` [m] on ``[-a, a]``; the loads are functions of the time
    after loading [day]; ``times`` are the output times [day after loading]. Two scenes are
    equal when their canonical dicts (:meth:`to_dict`) are equal.
    """

    name: str
    description: str
    half_width: float
    shape: Profile
    coating: tuple[Layer, ...]
    base_thickness: float
    base_poisson: float
    age_at_loading: float
    creep: Any
    loading: Mapping[str, Profile]
    times: np.ndarray
    tol: float
    _data: dict = field(repr=False)
    #: Contact model: "auto" (full contact unless it is lost), "full" or "unilateral".
    contact: str = "auto"

    def to_dict(self) -> dict[str, Any]:
        """The canonical JSON-able dict of the scene (schema version 1, defaults filled in)."""
        return copy.deepcopy(self._data)

    @cached_property
    def key(self) -> str:
        """A content hash of the canonical dict (hex), equal for equal scenes."""
        text = json.dumps(self._data, sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Scene) and other.key == self.key

    def __hash__(self) -> int:
        return hash(self.key)

    @property
    def given(self) -> frozenset[str]:
        """The two given quantities (of settlement, tilt, force, moment)."""
        return frozenset(self.loading)

    @property
    def statement(self) -> int:
        """The statement number (1-4) of the seed, section 3."""
        return STATEMENTS[self.given]

    @cached_property
    def breakpoints(self) -> tuple[float, ...]:
        """Points of (-a, a) [m] where the punch shape or a coating profile may jump."""
        points: list[float] = []
        profiles = [self.shape] + [p for layer in self.coating
                                   for p in (layer.thickness, layer.modulus, layer.poisson)]
        a = self.half_width
        for profile in profiles:
            points.extend(float(b) for b in getattr(profile, "breakpoints", ()))
        inside = sorted(b for b in points if -a < b < a)
        merged: list[float] = []
        for b in inside:
            # two profiles breaking at the same place would give a zero-width panel
            if not merged or b - merged[-1] > 1e-12 * a:
                merged.append(b)
        return tuple(merged)

    @cached_property
    def _geometry_key(self) -> str:
        """Content hash of the punch and the coating (what the x-profiles depend on)."""
        return fingerprint("geometry", json.dumps(
            [self._data["punch"], self._data["coating"]], sort_keys=True,
            separators=(",", ":")))

    @cached_property
    def sample_x(self) -> np.ndarray:
        """Dense points of [-a, a] [m] where the x-profiles show their extremes: a uniform
        grid, both sides of every breakpoint and each family's known extremes (shared,
        read-only, by scenes of the same geometry)."""
        return _SAMPLE_X.get_or_compute(self._geometry_key, self._sample_points)[0]

    def _sample_points(self) -> np.ndarray:
        a = self.half_width
        profiles = [self.shape] + [p for layer in self.coating
                                   for p in (layer.thickness, layer.modulus, layer.poisson)]
        parts = [np.linspace(-a, a, DENSE_SAMPLES)]
        parts += [p.sample_points((-a, a)) for p in profiles]
        points = np.unique(np.concatenate(parts))
        points.setflags(write=False)
        return points

    def modulus_at_loading(self) -> float:
        """``E0 = E(age_at_loading)`` [Pa], the base modulus when the load is applied."""
        return float(np.asarray(self.creep.modulus(self.age_at_loading), dtype=float))

    @property
    def model_tol(self) -> float:
        """``solver.model_tol``: the coating-model error a result may carry unflagged [-]."""
        return float(self._data["solver"]["model_tol"])

    def coating_compliance(self, x: Any) -> np.ndarray:
        """``sum_k c_k`` [m/Pa] at points ``x`` [m] (vectorized): ``c_k = (1 - nu_k^2) h_k /
        E_k`` for a smooth interface, the laterally constrained ``(1 + nu_k)(1 - 2 nu_k) h_k
        / ((1 - nu_k) E_k)`` for a bonded one (:mod:`core.coating_model`)."""
        x = np.asarray(x, dtype=float)
        total = np.zeros(x.shape)
        for layer in self.coating:
            total = total + layer_compliance(_values(layer.thickness, x),
                                             _values(layer.modulus, x),
                                             _values(layer.poisson, x), layer.interface)
        return total

    def coating_thickness(self, x: Any) -> np.ndarray:
        """``sum_k h_k`` [m] at points ``x`` [m] (vectorized)."""
        x = np.asarray(x, dtype=float)
        total = np.zeros(x.shape)
        for layer in self.coating:
            total = total + _values(layer.thickness, x)
        return total

    @cached_property
    def _gap_parts(self) -> tuple[Profile, ...]:
        """``f`` and the ``h_k`` less their constant parts (see :func:`_without_offset`)."""
        return (_without_offset(self.shape),) + tuple(
            _without_offset(layer.thickness) for layer in self.coating)

    def gap_variation(self, x: Any) -> np.ndarray:
        """``f(x) - sum_k h_k(x)`` [m] at points ``x`` [m], up to a constant.

        The gap of a crowned punch on a 12 mm coating is micrometres: computed as
        ``f - 0.012 + 0.012`` it would carry rounding noise of ~1e-13 of itself, which the
        solver's resolution test on ``g`` takes for unresolved features. Dropping the
        constant parts first keeps the gap accurate to rounding of its own size.
        """
        x = np.asarray(x, dtype=float)
        shape, *layers = self._gap_parts
        total = _values(shape, x)
        for part in layers:
            total = total - _values(part, x)
        return total

    @cached_property
    def gap_minimum(self) -> float:
        """``min over [-a, a]`` of :meth:`gap_variation` [m]: dense samples, refined locally.

        Shared by scenes of the same geometry (a load slider makes a new scene each
        step; the search costs ~4 ms of the ~15 ms such a step takes)."""
        # the samples depend on every x-profile (their breakpoints and extremes)
        return _GAP_MINIMUM.get_or_compute(self._geometry_key, self._search_gap_minimum)[0]

    def _search_gap_minimum(self) -> float:
        x = self.sample_x
        values = self.gap_variation(x)
        i = int(np.argmin(values))
        best = float(values[i])
        lo, hi = x[max(i - 1, 0)], x[min(i + 1, x.size - 1)]
        if hi > lo:
            # a smooth minimum can fall between samples: golden-section search on the
            # bracket; any value it finds is a true value of the function, so taking the
            # smaller one is always safe (also next to a jump)
            best = min(best, golden_minimum(
                lambda s: float(self.gap_variation(np.array([s]))[0]), float(lo), float(hi)))
        return best

    def gap(self, x: Any) -> np.ndarray:
        """The gap ``g(x) = f(x) - sum_k h_k(x) - min(...)`` [m] at points ``x`` [m]."""
        return self.gap_variation(x) - self.gap_minimum

    @cached_property
    def dimensionless(self) -> DimensionlessProblem:
        """The dimensionless problem of this scene (built once, see the module docstring)."""
        return _to_dimensionless(self)


def _values(profile: Profile, x: np.ndarray) -> np.ndarray:
    """A profile's values at ``x`` as a float array of x's shape."""
    return np.broadcast_to(np.asarray(profile(x), dtype=float), np.shape(x)).astype(float)


def _without_offset(profile: Profile) -> Profile:
    """The profile less a constant part that its spec separates exactly.

    ``constant`` gives 0; ``sine`` and ``bump`` drop ``mean``, ``polynomial`` its
    constant coefficient, ``linear``, ``step`` and ``table`` their first value (the
    differences of nearby values are exact in floating point). Formulas are kept as they
    are. Only differences of the result are meaningful.
    """
    spec = profile.spec
    kind = profile.kind
    if kind == "constant":
        return profile_from_spec(0.0, field="gap", variable=profile.variable,
                                 domain=profile.domain)
    if not isinstance(spec, dict):
        return profile
    spec = dict(spec)
    if kind in ("sine", "bump"):
        spec["mean"] = 0.0
    elif kind == "polynomial":
        spec["coefficients"] = [0.0] + list(spec["coefficients"][1:])
    elif kind == "linear":
        spec["start"], spec["end"] = 0.0, spec["end"] - spec["start"]
    elif kind == "step":
        first = spec["values"][0]
        spec["values"] = [v - first for v in spec["values"]]
    elif kind == "table":
        first = spec["points"][0][1]
        spec["points"] = [[v, y - first] for v, y in spec["points"]]
    else:
        return profile
    return profile_from_spec(spec, field="gap", variable=profile.variable,
                             domain=profile.domain)


# ---------------------------------------------------------------------------- validation


def _profile(spec: Any, path: str, variable: str, domain: tuple[float, float], *,
             lower: float | None = None, upper: float | None = None) -> Profile:
    """Build a profile and check that its values lie in the open range (lower, upper).

    Profiles are immutable, so a validated one is shared by every scene that has it: a
    slider step changes one field, and checking every profile again on thousands of
    points was as costly as the solve itself (measured under 20 sessions)."""
    try:
        key = fingerprint("profile", json.dumps(spec, sort_keys=True, separators=(",", ":"),
                                                allow_nan=False),
                          path, variable, domain, lower, upper)
    except (TypeError, ValueError):  # not plain JSON: validated without the memo
        return _checked_profile(spec, path, variable, domain, lower, upper)
    return _PROFILES.get_or_compute(
        key, lambda: _checked_profile(spec, path, variable, domain, lower, upper))[0]


def _checked_profile(spec: Any, path: str, variable: str, domain: tuple[float, float],
                     lower: float | None, upper: float | None) -> Profile:
    profile = profile_from_spec(spec, field=path, variable=variable, domain=domain)
    try:
        check_range(profile, field=path, domain=domain, lower=lower, upper=upper)
    except ValueError as exc:
        message = str(exc)
        # the position is in metres (x) or days after loading (t): say so
        unit = " m" if variable == "x" else " days after loading"
        if re.search(rf" at {variable} = \S+$", message):
            message += unit
        raise ValueError(message) from None
    return profile


def _times(spec: Any, path: str) -> tuple[np.ndarray, Any]:
    """The output times [day after loading] and their canonical spec."""
    if isinstance(spec, Mapping):
        _check_fields(spec, path, ("end", "count"), ("spacing",))
        end = positive_number(spec["end"], f"{path}.end")
        count = _integer(spec["count"], f"{path}.count", 1, MAX_TIMES)
        spacing = spec.get("spacing", "linear")
        if spacing not in ("linear", "log"):
            raise ValueError(f"{path}.spacing: must be 'linear' or 'log', "
                             f"got {show_value(spacing)}")
        if count == 1:
            times = np.array([end])
        elif spacing == "linear":
            times = np.linspace(0.0, end, count)
        else:
            # the instant of loading, then count - 1 times geometrically spaced over the
            # last three decades before ``end`` (creep is fastest just after loading)
            times = np.concatenate([[0.0], np.geomspace(end * 1e-3, end, count - 1)])
        times[-1] = end
        return times, {"end": end, "count": count, "spacing": spacing}
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
        return np.array(values), values
    raise ValueError(f"{path}: must be an object {{end, count, spacing}} or a list of days "
                     f"after loading, got {show_value(spec)}")


def scene_from_dict(d: Mapping[str, Any] | Scene) -> Scene:
    """Validate a scene dict (schema in ``core/SCENES.md``) and build a :class:`Scene`.

    Units: SI (m, Pa, N/m, N, rad), times in days. Every field is checked; a problem
    raises ``ValueError`` whose message starts with the full path of the field, e.g.
    ``coating[1].modulus: must be > 0, ...``. A :class:`Scene` is returned unchanged.
    """
    if isinstance(d, Scene):
        return d
    d = migrate(d)
    _check_fields(d, "", ("schema_version", "name", "punch", "coating", "base", "loading",
                          "times"), ("description", "solver"))
    name = _text(d["name"], "name", allow_empty=False, most=limits.MAX_NAME_CHARS)
    description = _text(d.get("description", ""), "description", allow_empty=True,
                        most=limits.MAX_DESCRIPTION_CHARS)

    punch = _check_fields(d["punch"], "punch", ("half_width",), ("shape",))
    a = positive_number(punch["half_width"], "punch.half_width")
    x_domain = (-a, a)
    shape_spec = punch.get("shape", 0.0)
    shape = _profile(shape_spec, "punch.shape", "x", x_domain)

    layers_spec = d["coating"]
    if not isinstance(layers_spec, (list, tuple)):
        raise ValueError(f"coating: must be a list of layers, got {show_value(layers_spec)}")
    if not 1 <= len(layers_spec) <= MAX_LAYERS:
        raise ValueError(f"coating: must hold 1 to {MAX_LAYERS} layers, got {len(layers_spec)}")
    layers = []
    for k, spec in enumerate(layers_spec):
        path = f"coating[{k}]"
        _check_fields(spec, path, ("thickness", "modulus", "poisson"), ("interface",))
        interface = spec.get("interface", DEFAULT_INTERFACE)
        if interface not in INTERFACES:
            raise ValueError(f"{path}.interface: must be 'smooth' or 'bonded', got "
                             f"{show_value(interface)}")
        layers.append(Layer(
            thickness=_profile(spec["thickness"], f"{path}.thickness", "x", x_domain,
                               lower=0.0),
            modulus=_profile(spec["modulus"], f"{path}.modulus", "x", x_domain, lower=0.0),
            poisson=_profile(spec["poisson"], f"{path}.poisson", "x", x_domain, lower=-1.0,
                             upper=0.5),
            interface=interface,
        ))

    base = _check_fields(d["base"], "base", ("thickness", "poisson", "age_at_loading", "creep"))
    h_base = positive_number(base["thickness"], "base.thickness")
    nu = _poisson(base["poisson"], "base.poisson")
    tau0 = positive_number(base["age_at_loading"], "base.age_at_loading")
    try:
        creep = creep_model_from_spec(base["creep"], field="base.creep")
    except NumberTooLarge:
        raise  # a ValueError that names the parameter (base.creep.modulus)
    except OverflowError:
        # an overflow in a creep computation, with no parameter to name
        raise ValueError("base.creep: a number is too large for a double (must be a finite "
                         "number)") from None
    if not math.isfinite(a / h_base) or not LAM_RANGE[0] <= a / h_base <= LAM_RANGE[1]:
        raise ValueError(f"base.thickness: the ratio punch.half_width / base.thickness must be "
                         f"in [{LAM_RANGE[0]:g}, {LAM_RANGE[1]:g}], got {a / h_base:.6g}")

    times, times_spec = _times(d["times"], "times")

    loading = d["loading"]
    _check_fields(loading, "loading", (), QUANTITIES)
    given = frozenset(loading)
    if len(given) != 2:
        raise ValueError("loading: exactly two of settlement, tilt, force, moment are needed, "
                         "got " + (", ".join(q for q in QUANTITIES if q in given) or "none"))
    if given not in STATEMENTS:
        raise ValueError("loading: " + " and ".join(q for q in QUANTITIES if q in given)
                         + " is not one of the four statements (settlement+tilt, "
                         "settlement+moment, tilt+force, force+moment)")
    t_domain = (0.0, float(times[-1]))
    loads = {q: _profile(loading[q], f"loading.{q}", "t", t_domain)
             for q in QUANTITIES if q in given}
    # the solver's time is the age over tau0: times closer than its rounding would merge
    ages = (tau0 + times) / tau0
    if np.any(np.diff(ages) <= 0):
        i = int(np.argmax(np.diff(ages) <= 0)) + 1
        raise ValueError(f"times[{i}]: too close to the time before it to be told apart at "
                         f"an age at loading of {tau0:g} days")

    solver = _check_fields(d.get("solver", {}), "solver", (), ("tol", "contact", "model_tol"))
    tol = finite_number(solver.get("tol", DEFAULT_TOL), "solver.tol")
    if not TOL_RANGE[0] <= tol <= TOL_RANGE[1]:
        raise ValueError(f"solver.tol: must be in [{TOL_RANGE[0]:g}, {TOL_RANGE[1]:g}], "
                         f"got {show_value(tol)}")
    contact = solver.get("contact", "auto")
    if contact != "auto":
        from core.contact import CONTACT_MODELS  # the solver's list (loaded only when asked)

        if not isinstance(contact, str) or contact not in CONTACT_MODELS:
            raise ValueError(f"solver.contact: must be one of {', '.join(CONTACT_MODELS)}, "
                             f"got {show_value(contact)}")
    model_tol = finite_number(solver.get("model_tol", DEFAULT_MODEL_TOL), "solver.model_tol")
    if not MODEL_TOL_RANGE[0] <= model_tol <= MODEL_TOL_RANGE[1]:
        raise ValueError(f"solver.model_tol: must be in [{MODEL_TOL_RANGE[0]:g}, "
                         f"{MODEL_TOL_RANGE[1]:g}], got {show_value(model_tol)}")

    data = {
        "schema_version": SCHEMA_VERSION,
        "name": name,
        "description": description,
        "punch": {"half_width": a, "shape": _jsonable(_spec_of(shape, shape_spec))},
        "coating": [{"thickness": _jsonable(_spec_of(layer.thickness, s["thickness"])),
                     "modulus": _jsonable(_spec_of(layer.modulus, s["modulus"])),
                     "poisson": _jsonable(_spec_of(layer.poisson, s["poisson"])),
                     "interface": layer.interface}
                    for layer, s in zip(layers, layers_spec, strict=True)],
        "base": {"thickness": h_base, "poisson": nu, "age_at_loading": tau0,
                 "creep": _jsonable(creep.spec)},
        "loading": {q: _jsonable(_spec_of(loads[q], loading[q])) for q in loads},
        "times": _jsonable(times_spec),
        # the default contact model is left out, so existing scenes keep their keys
        "solver": ({"tol": tol, "model_tol": model_tol} if contact == "auto" else
                   {"tol": tol, "model_tol": model_tol, "contact": contact}),
    }
    times.setflags(write=False)
    scene = Scene(name, description, a, shape, tuple(layers), h_base, nu, tau0, creep,
                  MappingProxyType(loads), times, tol, data, contact)
    _check_breakpoints(scene)
    _check_solvable(scene)
    _check_load_rates(scene)
    return scene


def _check_load_rates(scene: Scene) -> None:
    """Refuse a load that varies faster than the time stepping can follow (an elastic
    base has no time stepping; a formula kernel's grid has its own point limit)."""
    if isinstance(scene.creep, Elastic):
        return
    general = isinstance(scene.creep, UserKernel)
    check_step_limit({f"loading.{q}": p for q, p in scene.loading.items()}, 0.0,
                     float(scene.times[-1]), scene.tol,
                     limits.MAX_KERNEL_GRID_POINTS if general else limits.MAX_TIME_STEPS,
                     "the time grid's limit" if general else "the time stepping's limit")


def _x_profiles(scene: Scene) -> list[tuple[str, Profile]]:
    """The x-profiles of a scene with their field paths."""
    return [("punch.shape", scene.shape)] + [
        (f"coating[{k}].{name}", getattr(layer, name))
        for k, layer in enumerate(scene.coating) for name in ("thickness", "modulus", "poisson")]


def _check_breakpoints(scene: Scene) -> None:
    """Refuse more jumps and kinks across the punch than the solver can afford.

    Each breakpoint adds a graded cluster of quadrature panels (about 140 nodes), and the
    kernel operator is dense in the nodes: 16 breakpoints measured 2448 nodes, 1.9 s and
    360 MB for one solve, 40 breakpoints 9 s and 1.7 GB, a 10000-row table asked for a
    15 TiB matrix. A served explorer must not let one scene take the machine.
    """
    count = len(scene.breakpoints)
    if count <= MAX_BREAKPOINTS:
        return
    a = scene.half_width
    path, most = max(((p, sum(1 for b in prof.breakpoints if -a < b < a))
                      for p, prof in _x_profiles(scene)), key=lambda item: item[1])
    raise ValueError(
        f"{path}: has {most} points where its value or slope jumps (table rows, step "
        f"breaks or formula switches), {count} in the whole scene, more than the "
        f"{MAX_BREAKPOINTS} the solver allows: use fewer rows or breaks, a 'pchip' table "
        "(smooth between its end rows) or a smooth formula")


def _check_solvable(scene: Scene) -> None:
    """Refuse a scene whose dimensionless problem leaves double precision or the range the
    solver handles, naming the field to change.

    Every value may pass its own check (a coating modulus of 1e300 Pa is > 0) while the
    combination is not computable: ``m*`` underflows, a load over ``E a`` overflows, an
    aging term ``A / age^2`` is infinite at a tiny age at loading. Such scenes are far from
    physical sizes; refusing them here keeps NaN out of results and bounds the work.
    """
    with np.errstate(all="ignore"):
        problem = scene.dimensionless
        a = scene.half_width
        x = scene.sample_x
        xs = x / a
        m = np.broadcast_to(problem.m(xs) if callable(problem.m) else problem.m, xs.shape)
        lo, hi = M_STAR_RANGE
        bad = ~np.isfinite(m) | (m < lo) | (m > hi)
        if bad.any():
            i = int(np.argmax(bad))
            raise ValueError(
                f"coating: the coating compliance relative to the base, m* = E0 sum_k (1 - "
                f"nu_k^2) h_k / E_k / (2 (1 - nu^2) a), is {m[i]:.3g} at x = {x[i]:.6g} m, "
                f"outside [{lo:g}, {hi:g}]: the layers are too stiff or soft, thin or thick "
                "against the base to be solved in double precision")
        if callable(problem.g):
            g = problem.g(xs)
            bad = ~np.isfinite(g) | (np.abs(g) > MAX_GAP_RATIO)
            if bad.any():
                i = int(np.argmax(bad))
                f_range = float(np.ptp(_values(scene.shape, x)))
                h_range = float(np.ptp(scene.coating_thickness(x)))
                where = "punch.shape" if not f_range < h_range else "coating"
                raise ValueError(
                    f"{where}: the gap between the punch base and the coating surface is "
                    f"{g[i]:.3g} half-widths at x = {x[i]:.6g} m (at most "
                    f"{MAX_GAP_RATIO:g}): far beyond the shallow contact of this model")
        _check_creep(scene, problem)
        ts = problem.times
        for name, load in problem.loads.items():
            values = np.broadcast_to(load(ts) if callable(load) else load, ts.shape)
            bad = ~np.isfinite(values) | (np.abs(values) > MAX_MAGNITUDE)
            if bad.any():
                i = int(np.argmax(bad))
                raise ValueError(
                    f"loading.{name}: cannot be scaled by the base modulus and the "
                    f"half-width in double precision at t = {scene.times[i]:.6g} days after "
                    "loading (the sizes in the scene are too far apart)")


def _check_creep(scene: Scene, problem: DimensionlessProblem) -> None:
    """The relative modulus and the creep kernel at the ages of the solve: finite, and for
    a kernel given as a formula, never positive (a positive ``K`` makes the compliance
    decrease in time)."""
    tau0 = scene.age_at_loading
    ts = problem.times
    c = np.broadcast_to(problem.c(ts) if callable(problem.c) else problem.c, ts.shape)
    bad = ~np.isfinite(c) | (c <= 0)
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(
            f"base.creep: the modulus E(age) / E(age at loading) is {c[i]:.3g} at the age "
            f"{tau0 * ts[i]:.6g} days: the creep parameters or base.age_at_loading are "
            "too extreme for double precision")
    kernel = problem.kernel
    if kernel is None:
        return
    # the output times and a few between, all pairs t >= tau
    grid = np.unique(np.concatenate([ts[np.linspace(0, ts.size - 1, min(ts.size, 17))
                                        .round().astype(int)],
                                     np.linspace(ts[0], ts[-1], 17)]))
    t_star, tau_star = np.meshgrid(grid, grid, indexing="ij")
    keep = t_star >= tau_star
    t_star, tau_star = t_star[keep], tau_star[keep]
    try:
        k = np.asarray(kernel(t_star, tau_star), dtype=float)
    except ValueError as exc:  # a formula kernel refuses its own non-finite values
        where = "base.creep.expr" if isinstance(scene.creep, UserKernel) else "base.creep"
        raise ValueError(f"{where}: {exc}") from None
    bad = ~np.isfinite(k)
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(
            f"base.creep: the creep kernel K(t, tau) is {k[i]} at the ages t = "
            f"{tau0 * t_star[i]:.6g}, tau = {tau0 * tau_star[i]:.6g} days: the creep "
            "parameters or base.age_at_loading are too extreme for double precision")
    user = isinstance(scene.creep, UserKernel)
    if user:
        # the shipped models are <= 0 by their coefficient checks; a formula is checked
        # on samples, with room for rounding of a kernel that is 0 somewhere
        scale = float(np.max(np.abs(k))) if k.size else 0.0
        bad = k > 1e-9 * scale
        if bad.any():
            i = int(np.argmax(bad))
            raise ValueError(
                f"base.creep.expr: K(t, tau) must be <= 0 (the base creeps), is "
                f"{k[i] / tau0:.3g} per day at the ages t = {tau0 * t_star[i]:.6g}, tau = "
                f"{tau0 * tau_star[i]:.6g} days: a positive kernel makes the compliance "
                "decrease in time")
        # creep strain per elastic strain under a unit stress held from loading:
        # -int_1^t* K*(t*, s) ds, on points graded toward s = t* where a fast kernel lives
        u = np.concatenate([[0.0], np.geomspace(1e-12, 1.0, 400)])
        s = ts[-1] - (ts[-1] - ts[0]) * u
        line = np.asarray(kernel(np.full(s.shape, ts[-1]), s), dtype=float)
        phi = float(np.sum(0.5 * (line[1:] + line[:-1]) * (s[:-1] - s[1:])))
        phi = -phi
    else:
        phi = float(scene.modulus_at_loading()
                    * np.asarray(scene.creep.compliance(tau0 * ts[-1], tau0), dtype=float))
    if not phi <= MAX_CREEP_COEFFICIENT:
        raise ValueError(
            f"{'base.creep.expr' if user else 'base.creep'}: the creep coefficient (creep "
            "strain over elastic strain under a stress held from loading to the last output "
            f"time) is {phi:.3g}, more than {MAX_CREEP_COEFFICIENT:g}: far beyond real "
            "materials, and beyond what the time stepping can follow in reasonable time")


def _spec_of(profile: Profile, given: Any) -> Any:
    """The canonical spec of a profile (its ``spec`` when it has one, else what was given)."""
    spec = getattr(profile, "spec", None)
    return given if spec is None else spec


# -------------------------------------------------------------------------- conversion


@dataclass(frozen=True, eq=False)
class DimensionlessProblem:
    """The arguments of :func:`core.solver.solve_dimensionless` for one scene.

    ``m``, ``g`` are numbers or vectorized callables of ``x*``; ``c`` and the ``loads``
    numbers or callables of ``t*``; ``times`` are ``t*`` values; ``breakpoints`` in ``x*``.
    The reference values convert back: ``half_width`` [m], ``modulus_at_loading`` E0 [Pa],
    ``age_at_loading`` tau0 [day], ``plane_factor`` ``2 (1 - nu^2)`` [-].
    """

    lam: float
    m: float | Callable[[np.ndarray], np.ndarray]
    g: float | Callable[[np.ndarray], np.ndarray]
    c: float | Callable[[np.ndarray], np.ndarray]
    kernel: Any
    loads: Mapping[str, float | Callable[[np.ndarray], np.ndarray]]
    times: np.ndarray
    breakpoints: tuple[float, ...]
    tol: float
    half_width: float
    modulus_at_loading: float
    age_at_loading: float
    plane_factor: float
    modulus: Callable[[np.ndarray], np.ndarray]
    contact: str = "auto"
    #: ``t*`` where a given history jumps or kinks (the time stepper lands on them).
    time_breaks: tuple[float, ...] = ()

    def modulus_after_loading(self, t: Any) -> np.ndarray:
        """``E(tau0 + t)`` [Pa] at ``t`` days after loading."""
        return np.asarray(self.modulus(self.age_at_loading + np.asarray(t, dtype=float)),
                          dtype=float)

    def pressure_scale(self, t: Any) -> np.ndarray:
        """``q / q* = E(age) / (2 (1 - nu^2))`` [Pa] at ``t`` days after loading."""
        return self.modulus_after_loading(t) / self.plane_factor

    def solve(self) -> ContactSolution:
        """Run :func:`core.solver.solve_dimensionless` on these arguments."""
        # imported here: validating a scene should not load the numerical pipeline
        from core.solver import solve_dimensionless

        return solve_dimensionless(self.lam, self.m, self.g, self.times, c=self.c,
                                   kernel=self.kernel, breakpoints=self.breakpoints,
                                   tol=self.tol, contact=self.contact,
                                   time_breaks=self.time_breaks, **self.loads)


def _is_constant(profile: Profile) -> bool:
    return getattr(profile, "kind", None) == "constant"


def _to_dimensionless(scene: Scene) -> DimensionlessProblem:
    """Convert a scene (see the module docstring for the formulas)."""
    a = scene.half_width
    nu = scene.base_poisson
    tau0 = scene.age_at_loading
    plane = 2.0 * (1.0 - nu * nu)
    e0 = scene.modulus_at_loading()
    creep = scene.creep
    t_end = float(scene.times[-1])

    def modulus(age: Any) -> np.ndarray:
        return np.asarray(creep.modulus(age), dtype=float)

    # Every callable below is a pure function of the scene, so the solver's caches, which
    # key on sampled values, see equal inputs for equal scenes.
    m_factor = e0 / (plane * a)
    coating_constant = all(_is_constant(p) for layer in scene.coating
                           for p in (layer.thickness, layer.modulus, layer.poisson))
    if coating_constant:
        m_value: Any = float(m_factor * scene.coating_compliance(np.zeros(1))[0])
    else:
        def m_value(xs: np.ndarray) -> np.ndarray:
            x = a * np.asarray(xs, dtype=float)
            values = m_factor * scene.coating_compliance(x)
            if not np.all(np.isfinite(values) & (values > 0)):
                _check_x_profiles_at(scene, x)
            return values

    if coating_constant and _is_constant(scene.shape):
        g_value: Any = 0.0
    else:
        g_min = scene.gap_minimum

        def g_value(xs: np.ndarray) -> np.ndarray:
            x = a * np.asarray(xs, dtype=float)
            values = (scene.gap_variation(x) - g_min) / a
            if not np.all(np.isfinite(values)):
                _check_x_profiles_at(scene, x)
            return values

    c_value = creep.relative_modulus(tau0, field="base.age_at_loading")
    aging = callable(c_value)

    def days(ts: np.ndarray) -> np.ndarray:
        # the solver may probe a hair outside [1, t*_end]; profiles are defined on [0, end]
        return np.clip(tau0 * (np.asarray(ts, dtype=float) - 1.0), 0.0, t_end)

    loads: dict[str, Any] = {}
    for name, profile in scene.loading.items():
        if name in ("settlement", "tilt"):
            scale = 1.0 / a if name == "settlement" else 1.0
            if _is_constant(profile):
                loads[name] = float(scale * _values(profile, np.zeros(1))[0])
            else:
                loads[name] = _kinematic_load(profile, scale, days)
        else:
            # a * a, not a**2: Python's float power raises OverflowError for a huge a,
            # products give inf, which the checks of scene_from_dict report
            a_power = a if name == "force" else a * a
            if _is_constant(profile) and not aging:
                loads[name] = float(plane * _values(profile, np.zeros(1))[0] / (e0 * a_power))
            else:
                loads[name] = _static_load(profile, plane / a_power, days, modulus, tau0)

    times_star = (tau0 + np.asarray(scene.times, dtype=float)) / tau0
    times_star[0] = max(times_star[0], 1.0)
    jumps = sorted({(tau0 + d) / tau0 for profile in scene.loading.values()
                    if hasattr(profile, "nonsmooth_points")
                    for d in profile.nonsmooth_points(0.0, t_end)})
    return DimensionlessProblem(
        lam=a / scene.base_thickness,
        m=m_value,
        g=g_value,
        c=c_value,
        kernel=creep.dimensionless_kernel(tau0, field="base.age_at_loading"),
        loads=loads,
        times=times_star,
        breakpoints=tuple(b / a for b in scene.breakpoints),
        tol=scene.tol,
        contact=scene.contact,
        time_breaks=tuple(jumps),
        half_width=a,
        modulus_at_loading=e0,
        age_at_loading=tau0,
        plane_factor=plane,
        modulus=modulus,
    )


#: Open bounds of the values of each x-profile of a layer, as the loader checks them.
_LAYER_BOUNDS = {"thickness": (0.0, None), "modulus": (0.0, None), "poisson": (-1.0, 0.5)}


def _check_x_profiles_at(scene: Scene, x: np.ndarray) -> None:
    """Refuse, naming the field, an x-profile that is not finite or out of its range at
    points ``x`` [m] the solver asked for: the loader checks profiles on samples, and a
    formula's pole or spike between them would otherwise surface under the solver's
    internal names (``m``, ``g``)."""
    candidates = [("punch.shape", scene.shape, (None, None))] + [
        (f"coating[{k}].{name}", getattr(layer, name), bounds)
        for k, layer in enumerate(scene.coating) for name, bounds in _LAYER_BOUNDS.items()]
    for path, profile, (lower, upper) in candidates:
        values = _values(profile, x)
        checks = [(~np.isfinite(values), "must be finite")]
        if lower is not None:
            checks.append((values <= lower, f"must be > {lower:g}"))
        if upper is not None:
            checks.append((values >= upper, f"must be < {upper:g}"))
        for bad, rule in checks:
            if bad.any():
                i = int(np.argmax(bad))
                raise ValueError(
                    f"{path}: {rule}, is {values.flat[i]:.6g} at x = {x.flat[i]:.10g} m, "
                    f"between the points where the scene was checked (a pole or a spike "
                    "of a formula narrower than the checks): keep it finite and in range "
                    "on the whole punch")


def _kinematic_load(profile: Profile, scale: float,
                    days: Callable[[np.ndarray], np.ndarray]) -> Callable:
    def load(ts: np.ndarray) -> np.ndarray:
        t = days(ts)
        return scale * _values(profile, t)
    return load


def _static_load(profile: Profile, scale: float, days: Callable[[np.ndarray], np.ndarray],
                 modulus: Callable[[Any], np.ndarray], tau0: float) -> Callable:
    def load(ts: np.ndarray) -> np.ndarray:
        t = days(ts)
        return scale * _values(profile, t) / modulus(tau0 + t)
    return load


# ---------------------------------------------------------------------------- solution


def plotting_grid(half_width: float, count: int = PLOT_POINTS) -> np.ndarray:
    """``count`` points of ``[-a, a]`` [m], clustered toward the edges (Chebyshev-Lobatto)."""
    x = -half_width * np.cos(np.pi * np.arange(count) / (count - 1))
    x[0], x[-1] = -half_width, half_width
    if count % 2:
        x[count // 2] = 0.0
    return x


class SceneSolution:
    """The answer for a scene in SI units (see :func:`solve`).

    ``times`` [day after loading], ``settlement`` [m], ``tilt`` [rad], ``force`` [N/m],
    ``moment`` [N] are arrays over ``times``; ``pressure(x)`` gives q [Pa] at points
    ``x`` [m] of ``[-a, a]``; ``x`` is a default plotting grid [m]; ``flags`` names what
    makes the answer doubtful or unphysical (``flag_messages`` explains each).
    ``contact_set[k]`` lists the ``(start, end)`` intervals [m] where q > 0 at ``times[k]``
    (``[(-a, a)]`` in full contact); ``info["contact"]`` names the contact model that
    answered (``"full"`` or ``"unilateral"``).
    """

    def __init__(self, scene: Scene, problem: DimensionlessProblem,
                 solution: ContactSolution) -> None:
        self.scene = scene
        self.problem = problem
        self.dimensionless = solution
        a = scene.half_width
        self.times = np.array(scene.times, dtype=float)
        modulus = problem.modulus_after_loading(self.times)
        self._pressure_scale = modulus / problem.plane_factor
        self.settlement = a * np.asarray(solution.settlement, dtype=float)
        self.tilt = np.asarray(solution.tilt, dtype=float).copy()
        self.force = np.asarray(solution.force, dtype=float) * self._pressure_scale * a
        self.moment = np.asarray(solution.moment, dtype=float) * self._pressure_scale * a * a
        self.x = plotting_grid(a)
        self.contact_set = [[(a * lo, a * hi) for lo, hi in zones]
                            for zones in getattr(solution, "contact_set", [])]
        self.model_error = model_error_estimate(
            scene, tilt_share(a, self.settlement, self.tilt))
        self.flags = self._flags(solution)
        self.flag_messages = {
            name: FLAG_MESSAGES.get(name, f"{name}: {solution.info.get('message', '')}")
            for name in self.flags}
        self.info = dict(solution.info)
        self.info["flags"] = list(self.flags)
        self.info["model_error_estimate"] = self.model_error["estimate"]
        # the default solve answers with the thin-layer model everywhere so far; the exact
        # layered kernel (core.layered_kernel) is not yet wired into it
        self.info["coating_model"] = "thin layer"
        self.info["model_error"] = dict(self.model_error)
        self.info["dimensional"] = self._extras()

    def _flags(self, solution: ContactSolution) -> list[str]:
        scene = self.scene
        flags = [str(f) for f in solution.info.get("flags", [])]
        x = scene.sample_x
        if np.max(scene.coating_thickness(x)) / (2 * scene.half_width) > THICK_COATING_RATIO:
            flags.append("thick_coating")
        if self.model_error["estimate"] > scene.model_tol:
            flags.append("model_error")
        e0 = self.problem.modulus_at_loading
        if any(np.max(_values(layer.modulus, x)) > e0 for layer in scene.coating):
            flags.append("stiff_coating")
        # between the output times too (the default engine samples the load histories)
        largest_tilt = max(float(np.max(np.abs(self.tilt))) if self.tilt.size else 0.0,
                           float(solution.info.get("max_abs_tilt", 0.0)))
        if largest_tilt > LARGE_TILT:
            flags.append("large_tilt")
        return list(dict.fromkeys(flags))

    def _extras(self) -> dict[str, Any]:
        scene, problem = self.scene, self.problem
        x = scene.sample_x
        m_star = problem.m(x / scene.half_width) if callable(problem.m) \
            else np.full(x.shape, problem.m)
        return {
            "scene_key": scene.key,
            "statement": scene.statement,
            "lam": problem.lam,
            "modulus_at_loading_Pa": problem.modulus_at_loading,
            "age_at_loading_days": problem.age_at_loading,
            "m_star_min": float(np.min(m_star)),
            "m_star_max": float(np.max(m_star)),
            "gap_max_m": float(np.max(scene.gap(x))),
            "coating_thickness_max_m": float(np.max(scene.coating_thickness(x))),
            "breakpoints_m": list(scene.breakpoints),
            "min_pressure_Pa": float(np.min(self.pressure_on_grid)),
            "max_pressure_Pa": float(np.max(self.pressure_on_grid)),
        }

    @property
    def contact_lost(self) -> bool:
        """Whether the pressure is negative somewhere (the answer is then not physical)."""
        return "contact_lost" in self.flags

    def pressure(self, x: Any) -> np.ndarray:
        """Contact pressure q [Pa] at points ``x`` [m] of ``[-a, a]``, shape (len(x), len(times)).

        Points outside ``[-a, a]`` are refused (ValueError), and so are more points than
        :data:`core.limits.MAX_PRESSURE_VALUES` values allow (checked before any work).
        """
        a = self.scene.half_width
        xs = np.atleast_1d(np.asarray(x, dtype=float))
        if xs.size * self.times.size > limits.MAX_PRESSURE_VALUES:
            raise ValueError(
                f"x: {xs.size} points at {self.times.size} times are more than the "
                f"{limits.MAX_PRESSURE_VALUES} pressure values one call may compute; ask "
                "for fewer points (or in several calls)")
        if np.any(~np.isfinite(xs)) or np.any(np.abs(xs) > a * (1 + 1e-12)):
            raise ValueError(f"x: the pressure is defined on [-a, a] = [{-a:g}, {a:g}] m only")
        # x = +-a can land a rounding error outside [-1, 1] after the division
        q_star = self.dimensionless.pressure(np.clip(xs / a, -1.0, 1.0))
        return q_star * self._pressure_scale[None, :]

    @cached_property
    def pressure_on_grid(self) -> np.ndarray:
        """``pressure(x)`` on the plotting grid, shape (201, len(times)) [Pa]."""
        return self.pressure(self.x)

    def to_dict(self) -> dict[str, Any]:
        """A JSON-able dict: the scene, the histories, q on ``x`` at every time, info, flags.

        Units are listed under ``units``; non-finite numbers become ``null``.
        """
        return _jsonable({
            "format": "coated-punch solution",
            "schema_version": SCHEMA_VERSION,
            "scene": self.scene.to_dict(),
            "units": UNITS,
            "times": self.times,
            "settlement": self.settlement,
            "tilt": self.tilt,
            "force": self.force,
            "moment": self.moment,
            "x": self.x,
            "pressure": self.pressure_on_grid,
            "flags": self.flags,
            "flag_messages": self.flag_messages,
            "contact_set": [[list(zone) for zone in zones] for zones in self.contact_set],
            "info": self.info,
        })

    def to_json(self) -> str:
        """:meth:`to_dict` as compact JSON text."""
        return json.dumps(self.to_dict(), separators=(",", ":"), allow_nan=False)

    def to_csv(self) -> str:
        """The histories as CSV: time [day], settlement [m], tilt [rad], force [N/m], moment [N].

        When the unilateral contact model answered, the contact set follows: the contact
        length [m] and the ends of each zone [m] (``zone1_start_m, zone1_end_m, ...``,
        ``nan`` where a time has fewer zones).
        """
        header = "time_day,settlement_m,tilt_rad,force_N_per_m,moment_N"
        zones = max((len(z) for z in self.contact_set), default=0)
        unilateral = self.info.get("contact") == "unilateral"
        if unilateral:
            header += ",contact_length_m" + "".join(
                f",zone{k + 1}_start_m,zone{k + 1}_end_m" for k in range(zones))
        lines = [header]
        for k, row in enumerate(zip(self.times, self.settlement, self.tilt, self.force,
                                    self.moment, strict=True)):
            values = [float(v) for v in row]
            if unilateral:
                current = self.contact_set[k]
                values.append(sum(hi - lo for lo, hi in current))
                for j in range(zones):
                    values.extend(current[j] if j < len(current) else (math.nan, math.nan))
            lines.append(",".join(repr(float(v)) for v in values))
        return "\n".join(lines) + "\n"

    def pressure_csv(self, x: Any = None) -> str:
        """q(x, t) as CSV in long form: time [day], x [m], pressure [Pa] (default x: ``.x``)."""
        xs = self.x if x is None else np.atleast_1d(np.asarray(x, dtype=float))
        q = self.pressure_on_grid if x is None else self.pressure(xs)
        lines = ["time_day,x_m,pressure_Pa"]
        for j, t in enumerate(self.times):
            tt = repr(float(t))
            lines.extend(f"{tt},{float(xi)!r},{float(qi)!r}" for xi, qi in zip(xs, q[:, j],
                                                                               strict=True))
        return "\n".join(lines) + "\n"


def solve(scene: Scene | Mapping[str, Any]) -> SceneSolution:
    """Solve a scene (a :class:`Scene` or a scene dict, validated first).

    Returns a :class:`SceneSolution` in SI units (m, rad, N/m, N, Pa; days after loading).
    """
    scene = scene_from_dict(scene)
    # a load no contact can carry is refused in every contact mode, in the scene's units
    from core.load_contact import check_loads_touch

    check_loads_touch(scene)
    import time  # here: validating a scene needs no clock

    started = time.thread_time()
    problem = scene.dimensionless
    with np.errstate(all="ignore"):
        result = SceneSolution(scene, problem, problem.solve())
    # CPU time of this thread [s]: what the scene costs, whatever else the machine runs
    # (info["seconds"] is the solver's wall time)
    result.info["cpu_seconds"] = time.thread_time() - started
    _check_finite(result)
    return result


def _check_finite(result: SceneSolution) -> None:
    """Refuse an answer with a non-finite value: the last guard of the promise that a
    result never holds NaN or infinity (the checks of :func:`scene_from_dict` catch the
    known causes first, with the field to change)."""
    parts = [(q, getattr(result, q)) for q in QUANTITIES]
    parts.append(("pressure", result.pressure_on_grid))
    for name, values in parts:
        bad = ~np.isfinite(np.asarray(values, dtype=float))
        if bad.any():
            j = int(np.argwhere(bad)[0][-1])  # the time index (last axis)
            message = str(result.info.get("message", ""))
            if "stopped at its limit" in message:
                # the stepper gave up, which says nothing of double precision
                raise ValueError(f"{_fastest_load(result.scene)}: the time stepping could "
                                 "not follow the loads: "
                                 + message.split("time stepping: ", 1)[-1])
            raise ValueError(
                f"scene: the computed {name} is not finite at t = {result.times[j]:.6g} days "
                "after loading: the sizes in this scene (moduli, loads, lengths) are too far "
                "apart for double precision")


def _fastest_load(scene: Scene) -> str:
    """The field of the load that oscillates most over the solved times (``loading``
    when none oscillates)."""
    end = float(scene.times[-1])
    counts = {q: oscillations(p, 0.0, end) + len(p.breakpoints)
              for q, p in scene.loading.items()}
    name = max(counts, key=lambda q: counts[q])
    return f"loading.{name}" if counts[name] > 0 else "loading"
