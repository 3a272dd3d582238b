"""Design studies: one base scene and the scene fields to vary (grids or distributions).

A *study* (format in ``core/SCENES.md``, "Study files") names a base scene, the numeric
scene fields to vary by their path (``coating[0].modulus``, ``loading.moment``,
``base.age_at_loading``), each as a grid (``values``, ``linspace``, ``logspace``) or a
distribution (``normal``, ``lognormal``, ``uniform``, drawn with ``seed``), the outputs
wanted and the output times. Grids combine as a Cartesian product; when a distribution is
present every grid point gets the same ``samples`` draws (common random numbers), so a
percentile along a grid axis compares like with like.

Everything here is pure: :func:`study_from_dict` validates (a ``ValueError`` whose message
starts with the field), :func:`point_table` expands a study into its points,
:class:`StudyPoints` makes any of them on demand, and
:func:`apply_point` makes the scene dict of one point. Running a study is
:mod:`core.sweep`'s job.
"""

from __future__ import annotations

import copy
import hashlib
import json
import math
import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from core.presets import PRESET_PREFIX, shipped_file
from core.scene import (
    MAX_SCENE_BYTES,
    SCHEMA_KEY,
    PunchesScene,
    Scene,
    check_fields,
    check_loads_touch,
    has_punches,
    integer_in_range,
    load_scene,
    punches_from_dict,
    read_scene_json,
    scene_from_dict,
)
from core.validation import finite_number, positive_number, show_value

#: The study format version this program reads and writes.
STUDY_VERSION = 1
#: Most points in one study (grid product times samples): each point is one solve and a
#: row of the result; 1e6 points of one output time are ~100 MB of results on disk.
MAX_STUDY_POINTS = 1_000_000
#: Most fields varied in one study (each is an axis of the result).
MAX_PARAMETERS = 8
#: Outputs a study can ask for, with their units; flags, error estimates and the failure
#: message of every point are always recorded.
OUTPUT_UNITS: dict[str, str] = {
    "settlement": "m",
    "tilt": "rad",
    "force": "N/m",
    "moment": "N",
    "q_max": "Pa",
    "q_min": "Pa",
    "contact_width": "m",
}
#: What each output is (the ``long_name`` of its variable in a study's dataset).
OUTPUT_NAMES: dict[str, str] = {
    "settlement": "settlement of the punch centre",
    "tilt": "tilt of the punch",
    "force": "force on the punch per metre",
    "moment": "moment on the punch per metre (N m/m)",
    "q_max": "largest contact pressure (201 points of the base)",
    "q_min": "smallest contact pressure (201 points of the base)",
    "contact_width": "length of the contact set",
}
#: What a study says of the base scene's design limits, which it does not check.
LIMITS_NOT_CHECKED = ("the base scene's design limits are not checked point by point: "
                      "compare q_max, settlement and tilt with them (utilisation = value / "
                      "limit), or solve a point's scene for its design check")
#: An output of one punch of several: ``punches[k].<output>`` (k as the scene file's).
PUNCH_OUTPUT = re.compile(r"punches\[(\d{1,4})\]\.([a-z_]+)")
GRID_KINDS = ("values", "linspace", "logspace")
DISTRIBUTIONS = ("normal", "lognormal", "uniform")
#: Whole subtrees a study may not vary: the output times are the study's own axis, and
#: the design-check limits do not change an answer.
FIXED_ROOTS = ("schema_version", "name", "description", "times", "limits")
#: Units of the numeric scene fields, by the last name of their path (the units of a
#: varied or fitted field; the design codes' creep inputs are in the codes' units).
FIELD_UNITS: dict[str, str] = {
    "half_width": "m", "center": "m", "thickness": "m", "modulus": "Pa", "modulus_final": "Pa",
    "poisson": "1", "age_at_loading": "day", "force": "N/m", "moment": "N",
    "settlement": "m", "tilt": "rad", "tol": "1", "rate": "1/day", "compliance": "1/Pa",
    "compliance_final": "1/Pa", "aging": "day/Pa", "relative_humidity": "%",
    "notional_size": "mm", "temperature": "degC", "shape": "m", "alpha": "1/day",
    "beta": "1", "fcm": "MPa", "model_tol": "1",
}
#: The fields whose value may be a profile object: its numbers' units follow from the
#: field's (:func:`field_unit`).
PROFILED = ("shape", "thickness", "modulus", "poisson", "force", "moment", "settlement",
            "tilt")
#: A profile's numbers in the profiled field's unit, and those that are positions (m
#: along the surface, days in time for a load; core/profiles/build.py FAMILIES).
PROFILE_VALUES = ("value", "start", "end", "values", "mean", "amplitude")
PROFILE_POSITIONS = ("breaks", "wavelength", "center", "width", "duration")
#: One part of a field path: a name and its list items (``coating[0]``).
PATH_PART = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)((?:\[\d{1,4}\])*)")


@dataclass(frozen=True)
class Parameter:
    """One varied field: ``path`` in the scene dict and either grid ``values`` or a
    ``distribution`` (``kind`` in :data:`DISTRIBUTIONS`, ``args`` its parameters)."""

    path: str
    kind: str
    values: tuple[float, ...] = ()
    args: tuple[tuple[str, float], ...] = ()

    @property
    def is_grid(self) -> bool:
        """Whether this parameter is a grid axis (else a distribution sampled per point)."""
        return self.kind in GRID_KINDS

    @property
    def is_load(self) -> bool:
        """Whether the field is a load: points differing only in loads share the solver's
        prepared geometry (operator, basis, Galerkin matrices)."""
        return self.path.startswith("loading.")


@dataclass(frozen=True)
class Study:
    """A validated study: ``base`` is the canonical scene dict (its ``times`` set to the
    study's), ``times`` the output times [day after loading]."""

    name: str
    base: dict
    parameters: tuple[Parameter, ...]
    samples: int
    seed: int
    outputs: tuple[str, ...]
    times: tuple[float, ...]

    @property
    def grid_shape(self) -> tuple[int, ...]:
        """Lengths of the grid axes, in the order of the study file."""
        return tuple(len(p.values) for p in self.parameters if p.is_grid)

    @property
    def n_points(self) -> int:
        """Number of points: the product of the grid lengths times the samples."""
        return math.prod(self.grid_shape) * self.samples

    @property
    def key(self) -> str:
        """A content hash (hex) of everything that defines the points and their results."""
        data = {"base": self.base, "parameters": [vars(p) for p in self.parameters],
                "samples": self.samples, "seed": self.seed, "outputs": self.outputs,
                "times": self.times}
        text = json.dumps(data, sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()

    def to_dict(self) -> dict[str, Any]:
        """The study as a study file's dict (format in ``core/SCENES.md``): the base scene
        inline (its ``times`` are the study's), each grid as it was given (a
        ``linspace``/``logspace`` by its ends and count), each distribution with its
        parameters. :func:`study_from_dict` of it gives a study with the same :attr:`key`."""
        vary: list[dict[str, Any]] = []
        for p in self.parameters:
            if p.kind == "values":
                spec: Any = list(p.values)
            elif p.is_grid:
                # linspace and geomspace return their ends exactly: the grid is rebuilt
                spec = {"start": p.values[0], "stop": p.values[-1], "count": len(p.values)}
            else:
                spec = dict(p.args)
            vary.append({"field": p.path, p.kind: spec})
        d: dict[str, Any] = {"study_version": STUDY_VERSION, "name": self.name,
                             "scene": copy.deepcopy(self.base), "vary": vary}
        if any(not p.is_grid for p in self.parameters):
            d["samples"] = self.samples
        d |= {"seed": self.seed, "outputs": list(self.outputs)}
        return d


# ---------------------------------------------------------------------------- paths


def parse_path(path: Any, field: str = "field") -> tuple[str | int, ...]:
    """``"coating[0].modulus"`` as ``("coating", 0, "modulus")``; ValueError naming ``field``."""
    if not isinstance(path, str) or not path or len(path) > 200:
        raise ValueError(f"{field}: must be a field path such as 'coating[0].modulus', got "
                         f"{show_value(path)}")
    parts: list[str | int] = []
    for piece in path.split("."):
        match = PATH_PART.fullmatch(piece)
        if match is None:
            raise ValueError(f"{field}: {path!r} is not a field path (names joined by '.', "
                             "list items as [k], e.g. 'coating[0].modulus')")
        parts.append(match.group(1))
        parts.extend(int(k) for k in re.findall(r"\[(\d+)\]", match.group(2)))
    return tuple(parts)


def get_field(scene: Mapping[str, Any], path: str) -> Any:
    """The value at ``path`` in a scene dict; ValueError naming the path if it is absent."""
    node: Any = scene
    for part in parse_path(path):
        if isinstance(part, int):
            if not isinstance(node, list) or part >= len(node):
                raise ValueError(f"{path}: no such field in the scene (no item [{part}])")
        elif not isinstance(node, Mapping) or part not in node:
            raise ValueError(f"{path}: no such field in the scene (no {part!r})")
        node = node[part]
    return node


def output_unit(name: str) -> str:
    """The unit of a study output: one of :data:`OUTPUT_UNITS`, or of one punch of several
    (``punches[1].tilt``: rad)."""
    match = PUNCH_OUTPUT.fullmatch(name)
    return OUTPUT_UNITS[match[2] if match else name]


def field_unit(path: str) -> str:
    """The unit of the scene field at ``path`` (:data:`FIELD_UNITS`; "" when unknown),
    a number inside a profile object included (``coating[0].modulus.start`` in Pa,
    ``loading.force.breaks[0]`` in days, ``punch.shape.coefficients[2]`` in 1/m)."""
    parts = parse_path(path)
    names = [part for part in parts if isinstance(part, str)]
    last = names[-1]
    if len(names) < 2 or names[-2] not in PROFILED:
        return FIELD_UNITS.get(last, "")
    owner = FIELD_UNITS.get(names[-2], "")
    along = "day" if "loading" in names else "m"
    if last in PROFILE_VALUES:
        return owner
    if last in PROFILE_POSITIONS:
        return along
    if last == "phase":
        return "rad"
    if last == "coefficients" and isinstance(parts[-1], int):  # of (x or t)^k
        k = parts[-1]
        if k == 0 or not owner:
            return owner
        if owner == along:  # a shape's: m / m^k
            return "1" if k == 1 else f"1/{along}" + (f"^{k - 1}" if k > 2 else "")
        return f"{owner}/{along}" + (f"^{k}" if k > 1 else "")
    if last == "points" and len(parts) >= 2 and isinstance(parts[-1], int) \
            and isinstance(parts[-2], int):
        return along if parts[-1] == 0 else owner
    return ""


def apply_point(scene: Mapping[str, Any], values: Mapping[str, float]) -> dict[str, Any]:
    """A copy of the scene dict with each ``path -> value`` of ``values`` set (not validated)."""
    out = copy.deepcopy(dict(scene))
    for path, value in values.items():
        parts = parse_path(path)
        get_field(out, path)  # the whole path must exist
        node: Any = out
        for part in parts[:-1]:
            node = node[part]
        node[parts[-1]] = float(value)
    return out


# ------------------------------------------------------------------------ validation


def _count(value: Any, field: str) -> int:
    return integer_in_range(value, field, 1, MAX_STUDY_POINTS)


def _grid(kind: str, spec: Any, field: str) -> tuple[float, ...]:
    if kind == "values":
        if not isinstance(spec, (list, tuple)) or not spec:
            raise ValueError(f"{field}: must be a non-empty list of numbers, got "
                             f"{show_value(spec)}")
        if len(spec) > MAX_STUDY_POINTS:
            raise ValueError(f"{field}: at most {MAX_STUDY_POINTS} values, got {len(spec)}")
        values = tuple(finite_number(v, f"{field}[{i}]") for i, v in enumerate(spec))
        first: dict[float, int] = {}
        for j, v in enumerate(values):
            if v in first:
                raise ValueError(f"{field}[{j}]: repeats {field}[{first[v]}] "
                                 f"({show_value(v)}): equal points would repeat one solve")
            first[v] = j
        return values
    check_fields(spec, field, ("start", "stop", "count"))
    count = _count(spec["count"], f"{field}.count")
    if kind == "linspace":
        lo = finite_number(spec["start"], f"{field}.start")
        hi = finite_number(spec["stop"], f"{field}.stop")
        grid = np.linspace(lo, hi, count)
    else:
        lo = positive_number(spec["start"], f"{field}.start")
        hi = positive_number(spec["stop"], f"{field}.stop")
        grid = np.geomspace(lo, hi, count)
    if count > 1 and lo == hi:
        raise ValueError(f"{field}.stop: equals start ({show_value(lo)}): {count} equal "
                         "points would repeat one solve")
    if count == 1 and lo != hi:
        raise ValueError(f"{field}.count: 1 point is start alone, and stop "
                         f"({show_value(hi)}) would be ignored; give a count of 2 or more, "
                         f"or values: [{show_value(lo)}]")
    return tuple(float(v) for v in grid)


def _distribution(kind: str, spec: Any, field: str) -> tuple[tuple[str, float], ...]:
    if kind == "normal":
        check_fields(spec, field, ("mean", "std"))
        mean = finite_number(spec["mean"], f"{field}.mean")
        std = positive_number(spec["std"], f"{field}.std")
        return (("mean", mean), ("std", std))
    if kind == "lognormal":
        check_fields(spec, field, ("median", "sigma"))
        median = positive_number(spec["median"], f"{field}.median")
        sigma = positive_number(spec["sigma"], f"{field}.sigma")
        if sigma > 5:
            raise ValueError(f"{field}.sigma: must be at most 5 (the spread of log values), "
                             f"got {show_value(sigma)}")
        return (("median", median), ("sigma", sigma))
    check_fields(spec, field, ("low", "high"))
    low = finite_number(spec["low"], f"{field}.low")
    high = finite_number(spec["high"], f"{field}.high")
    if not high > low:
        raise ValueError(f"{field}.high: must be greater than low ({show_value(low)}), got "
                         f"{show_value(high)}")
    return (("low", low), ("high", high))


def number_at(scene: Mapping[str, Any], path: Any, field: str, use: str,
              note: str = "") -> float:
    """The number at ``path`` of a scene dict that a study may vary or a fit may fit
    (``use``: "varied", "fitted"), else a ValueError starting with ``field``; ``note``:
    a hint of the caller's for a fixed field (say where else it is set)."""
    parts = parse_path(path, field)
    if parts[0] in FIXED_ROOTS:
        raise ValueError(f"{field}: {path!r} cannot be {use} (names and versions are not "
                         "numbers, design limits do not change an answer"
                         + (f"; {note})" if note else ")"))
    try:
        value = get_field(scene, path)
    except ValueError as exc:
        raise ValueError(f"{field}: {exc}") from None
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"{field}: {path!r} holds {show_value(value)} in the scene, not a "
                         "number; choose a number inside it (for a profile object, e.g. "
                         "'.value' or '.start')")
    return float(value)


def _parameter(spec: Any, field: str, base: Mapping[str, Any]) -> Parameter:
    kinds = GRID_KINDS + DISTRIBUTIONS
    check_fields(spec, field, ("field",), kinds)
    given = [k for k in kinds if k in spec]
    if len(given) != 1:
        raise ValueError(f"{field}: give exactly one of {', '.join(kinds)}, got "
                         + (", ".join(given) or "none"))
    kind = given[0]
    path = spec["field"]
    number_at(base, path, f"{field}.field", "varied",
              "the output times are the study's 'times'")
    if kind in GRID_KINDS:
        return Parameter(path, kind, values=_grid(kind, spec[kind], f"{field}.{kind}"))
    return Parameter(path, kind, args=_distribution(kind, spec[kind], f"{field}.{kind}"))


def _extremes(p: Parameter) -> list[tuple[str, float]]:
    """Values of ``p`` whose scene must be valid: the grid's ends, a distribution's centre
    (a normal or lognormal draw may still leave the valid range: that point fails alone)."""
    if p.is_grid:
        i_lo, i_hi = int(np.argmin(p.values)), int(np.argmax(p.values))
        return [(f"{p.kind}", p.values[i_lo]), (f"{p.kind}", p.values[i_hi])]
    args = dict(p.args)
    if p.kind == "uniform":
        return [(f"{p.kind}.low", args["low"]), (f"{p.kind}.high", args["high"])]
    centre = "mean" if p.kind == "normal" else "median"
    return [(f"{p.kind}.{centre}", args[centre])]


def _read_json_file(path: Path, what: str) -> Any:
    size = path.stat().st_size
    if size > MAX_SCENE_BYTES:
        raise ValueError(f"{path}: file is {size} bytes, over the limit of {MAX_SCENE_BYTES} "
                         f"bytes for a {what} file")
    with path.open("rb") as fh:
        raw = fh.read(MAX_SCENE_BYTES + 1)
    if len(raw) > MAX_SCENE_BYTES:
        raise ValueError(f"{path}: file is over the limit of {MAX_SCENE_BYTES} bytes")
    try:
        return read_scene_json(raw.decode("utf-8-sig"), str(path))
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a text file in UTF-8") from None


def validated_scene(d: Mapping[str, Any]) -> Scene | PunchesScene:
    """A scene dict of either form validated: one punch (:func:`core.scene.scene_from_dict`)
    or several (``punches``: :func:`core.scene.punches_from_dict`)."""
    return punches_from_dict(d) if has_punches(d) else scene_from_dict(d)


def _base_scene(spec: Any, base_dir: Path | None) -> dict[str, Any]:
    if isinstance(spec, str):
        if spec.startswith(PRESET_PREFIX):  # as load_scene and the commands read it
            try:
                return load_scene(spec).to_dict()
            except ValueError as exc:
                raise ValueError(f"scene: {exc}") from None
        if base_dir is None and not os.path.isabs(spec):
            raise ValueError("scene: a relative scene file path needs the study's "
                             "directory (use load_study, give an absolute path or "
                             "preset:NAME, or give the scene inline)")
        path = Path(spec) if os.path.isabs(spec) else base_dir / spec
        try:
            return load_scene(path).to_dict()
        except ValueError as exc:
            raise ValueError(f"scene: {exc}") from None
        except OSError as exc:
            raise ValueError(f"scene: cannot read {spec!r} ({exc.strerror or exc})") from None
    if not isinstance(spec, Mapping):
        raise ValueError(f"scene: must be a scene object or the path of a scene file, got "
                         f"{show_value(spec)}")
    try:
        return validated_scene(spec).to_dict()
    except ValueError as exc:
        raise ValueError(f"scene: {exc}") from None


def study_from_dict(d: Mapping[str, Any], base_dir: str | os.PathLike | None = None, *,
                    max_points: int = MAX_STUDY_POINTS) -> Study:
    """Validate a study dict (format in ``core/SCENES.md``) and build a :class:`Study`.

    ``base_dir`` resolves a relative ``scene`` path. Every problem raises ``ValueError``
    whose message starts with the field (``vary[1].linspace.count: ...``); the base scene's
    own problems are prefixed ``scene:``. The scene at each end of every grid (and at the
    centre of every distribution) must be valid; the number of points is at most
    ``max_points`` (default and upper bound :data:`MAX_STUDY_POINTS`; a server offering
    studies to untrusted users passes a smaller one).
    """
    max_points = min(int(max_points), MAX_STUDY_POINTS)
    try:
        check_fields(d, "", ("study_version", "name", "scene", "vary"),
                      ("description", "samples", "seed", "outputs", "times", SCHEMA_KEY))
    except ValueError as exc:
        # the scene checker names the top level "scene", which in a study is the field
        # holding the base scene: a stray study field must not be blamed on it
        msg = str(exc)
        if msg.startswith("scene: "):
            raise ValueError("study: " + msg[len("scene: "):]) from None
        raise
    integer_in_range(d["study_version"], "study_version", STUDY_VERSION, STUDY_VERSION)
    name = d["name"]
    if not isinstance(name, str) or not name.strip():
        raise ValueError(f"name: must be a non-empty string, got {show_value(name)}")
    for key in ("description", SCHEMA_KEY):
        if key in d and not isinstance(d[key], str):
            raise ValueError(f"{key}: must be a string, got {show_value(d[key])}")
    base = _base_scene(d["scene"], None if base_dir is None else Path(base_dir))
    if "times" in d:
        base["times"] = d["times"]
        try:
            base = validated_scene(base).to_dict()
        except ValueError as exc:
            msg = str(exc)
            raise ValueError(msg if msg.startswith("times") else f"times: {msg}") from None
    times = tuple(float(t) for t in validated_scene(base).times)

    vary = d["vary"]
    if not isinstance(vary, (list, tuple)) or not 1 <= len(vary) <= MAX_PARAMETERS:
        raise ValueError(f"vary: must be a list of 1 to {MAX_PARAMETERS} fields to vary, got "
                         + (f"{len(vary)}" if isinstance(vary, (list, tuple))
                            else show_value(vary)))
    params = tuple(_parameter(spec, f"vary[{i}]", base) for i, spec in enumerate(vary))
    # one field however its path is spelt (coating[00] is coating[0]): the later value
    # would overwrite the earlier one, whose column would then name values never solved
    seen: dict[tuple[str | int, ...], int] = {}
    for i, p in enumerate(params):
        parts = parse_path(p.path)
        if parts in seen:
            raise ValueError(f"vary[{i}].field: {p.path!r} is already varied by "
                             f"vary[{seen[parts]}] (as {params[seen[parts]].path!r})")
        seen[parts] = i

    random = any(not p.is_grid for p in params)
    if random and "samples" not in d:
        raise ValueError("samples: required when a field follows a distribution")
    if not random and "samples" in d:
        raise ValueError("samples: only for distributions (every field here is a grid)")
    samples = _count(d["samples"], "samples") if random else 1
    seed = integer_in_range(d.get("seed", 0), "seed", 0, 2**63 - 1)

    outputs = _outputs(d.get("outputs", list(OUTPUT_UNITS)), base)

    n = math.prod(len(p.values) for p in params if p.is_grid) * samples
    if n > max_points:
        raise ValueError(f"vary: the study has {n:,} points (grid sizes times samples), more "
                         f"than the limit of {max_points:,}")

    for i, p in enumerate(params):
        for where, value in _extremes(p):
            try:
                # the loads as a solve checks them too (a pulled punch, a resultant
                # outside the base): validate said "ok" to grids every solve refuses
                check_loads_touch(validated_scene(apply_point(base, {p.path: value})))
            except ValueError as exc:
                raise ValueError(f"vary[{i}].{where}: the scene is invalid at {p.path} = "
                                 f"{value:.6g} ({exc})") from None
    return Study(name.strip(), base, params, samples, seed, outputs, times)


def _outputs(spec: Any, base: Mapping[str, Any]) -> tuple[str, ...]:
    """The outputs a study records, checked (ValueError naming ``outputs[i]``). Of a base
    scene of several punches, every output is one punch's, ``punches[k].<output>``: a
    plain name stands for it under every punch; the order is by punch, then as given."""
    if not isinstance(spec, (list, tuple)) or not spec:
        raise ValueError(f"outputs: must be a non-empty list of {', '.join(OUTPUT_UNITS)}")
    count = len(base["punches"]) if has_punches(base) else 0
    wanted: list[tuple[int | None, str]] = []
    for i, o in enumerate(spec):
        # a list or object in the list is unhashable: test the type before the lookup
        match = PUNCH_OUTPUT.fullmatch(o) if isinstance(o, str) else None
        name = match[2] if match else o
        if not isinstance(name, str) or name not in OUTPUT_UNITS:
            raise ValueError(f"outputs[{i}]: unknown output {show_value(o)} (known: "
                             f"{', '.join(OUTPUT_UNITS)}"
                             + (", each also as punches[k].<output>)" if count else ")"))
        if match and not count:
            raise ValueError(f"outputs[{i}]: {o!r} is an output of one punch of several; the "
                             "base scene has one punch (give the plain name)")
        if match and int(match[1]) >= count:
            raise ValueError(f"outputs[{i}]: {o!r}: the base scene has {count} punches "
                             f"(punches[0] to punches[{count - 1}])")
        wanted.append((int(match[1]) if match else None, name))
    if not count:
        return tuple(dict.fromkeys(name for _, name in wanted))
    return tuple(dict.fromkeys(f"punches[{k}].{name}" for k in range(count)
                               for which, name in wanted if which in (None, k)))


def numeric_fields(scene: Mapping[str, Any], prefix: str = "") -> list[tuple[str, float]]:
    """Every field of a scene dict that a study can vary, with its current value: the
    numbers outside ``times`` and the schema fields, as ``(path, value)`` in document
    order (``[("punch.half_width", 1.0), ("coating[0].thickness", 0.02), ...]``)."""
    out: list[tuple[str, float]] = []
    items = scene.items() if isinstance(scene, Mapping) else enumerate(scene)
    for key, value in items:
        path = (f"{prefix}[{key}]" if isinstance(key, int)
                else f"{prefix}.{key}" if prefix else str(key))
        if not prefix and key in FIXED_ROOTS:
            continue
        if isinstance(value, (Mapping, list)):
            out.extend(numeric_fields(value, path))
        elif isinstance(value, (int, float)) and not isinstance(value, bool):
            out.append((path, float(value)))
    return out


def load_study(path: str | os.PathLike) -> Study:
    """Read and validate a study file (JSON, at most 1 MB); a relative ``scene`` path is
    taken from the study file's directory. ``"preset:NAME"`` reads the shipped study of
    that name (:mod:`core.presets`)."""
    path = Path(shipped_file(path, "studies"))
    return study_from_dict(_read_json_file(path, "study"), base_dir=path.parent)


# ------------------------------------------------------------------------- expansion


def point_values(table: Mapping[str, np.ndarray], i: int,
                 paths: Sequence[str]) -> dict[str, float]:
    """The field values of point ``i`` of a :func:`point_table`."""
    return {path: float(table[path][i]) for path in paths}
