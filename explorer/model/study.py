"""The explorer's design studies: one or two fields of the scene on screen over a range.

A study of the Study tab is a :class:`core.study.Study` built from the scene on screen:
:func:`study_choices` lists the fields worth varying (with their units on screen),
:func:`plan_study` checks the ranges the user typed and builds the study (a ``ValueError``
naming the field of the tab, e.g. ``parameter 2, points: ...``), and a
:class:`StudyResult` holds the answers on the grid, in SI units, with the flags of every
point. Running it is :mod:`explorer.solving.study_runner`'s job; its CSV file is
:func:`explorer.files.exports.study_csv`.

A scene of several punches (``punches``) is studied as one of a punch: its punches'
centres (the spacing), half-widths and loads are offered besides the coating and base,
and every output is one punch's (``punches[k].settlement``, :func:`study_outputs`).

Nothing here imports Panel (the study's process imports this module).
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from core.study import Study, numeric_fields, study_from_dict

#: Most points of a study started from the page (grid product). The page is served to
#: untrusted users on a shared machine: a point differing only in its loads costs a few
#: ms, a new geometry 10-40 ms on an elastic base (benchmarks/results/sweep.md) and
#: ~0.3 s of CPU for the default preset's creeping base at 40 output times (measured),
#: up to 0.7 s for the slowest valid scene: 400 points are seconds to about two minutes
#: of one core. Larger studies belong to ``python -m core sweep``.
MAX_POINTS = 400
#: Most values along one parameter (a line of more points shows nothing new on screen).
MAX_AXIS_POINTS = 200
#: The outputs a study of the page computes (all at once: switching the one shown costs
#: no new run) and how the page shows them: name, unit on screen, factor from SI.
OUTPUTS: dict[str, tuple[str, str, float]] = {
    "settlement": ("settlement", "mm", 1e3),
    "tilt": ("tilt", "mrad", 1e3),
    "q_max": ("largest pressure q_max", "kPa", 1e-3),
    "q_min": ("smallest pressure q_min", "kPa", 1e-3),
    "contact_width": ("contact width", "m", 1.0),
}
#: The key of the derived parameter e = M/P (it sets ``loading.moment``).
ECCENTRICITY = "eccentricity"
SPACINGS = ("linear", "log")

# fields offered, by path pattern: name on screen, unit on screen, SI per screen unit.
# Other numbers of a scene (profile details, a Prony series' terms, solver settings) are
# varied from a study file (python -m core sweep). The creep coefficients are offered:
# they are what a back-analysis fits (docs/guides/back_analysis.md; the Fit tab offered
# none, not even a design code's relative humidity).
_FIELDS: tuple[tuple[str, str, str, float], ...] = (
    (r"loading\.force", "loading: force P", "kN/m", 1e3),
    (r"loading\.moment", "loading: moment M", "kN·m/m", 1e3),
    (r"loading\.settlement", "loading: settlement", "mm", 1e-3),
    (r"loading\.tilt", "loading: tilt", "mrad", 1e-3),
    (r"punches\[(\d+)\]\.loading\.force", "punch {k}: force P", "kN/m", 1e3),
    (r"punches\[(\d+)\]\.loading\.moment", "punch {k}: moment M", "kN·m/m", 1e3),
    (r"punches\[(\d+)\]\.loading\.settlement", "punch {k}: settlement", "mm", 1e-3),
    (r"punches\[(\d+)\]\.loading\.tilt", "punch {k}: tilt", "mrad", 1e-3),
    (r"coating\[(\d+)\]\.thickness", "coating {k}: thickness", "mm", 1e-3),
    (r"coating\[(\d+)\]\.modulus", "coating {k}: Young's modulus", "MPa", 1e6),
    (r"coating\[(\d+)\]\.poisson", "coating {k}: Poisson ratio", "-", 1.0),
    (r"base\.age_at_loading", "base: age at loading", "day", 1.0),
    (r"base\.creep\.modulus(_final)?", "base: Young's modulus", "GPa", 1e9),
    (r"base\.creep\.compliance(_final)?", "base: final creep compliance C∞", "1/GPa",
     1e-9),
    (r"base\.creep\.rate", "base: creep rate γ", "1/day", 1.0),
    (r"base\.creep\.aging", "base: aging creep A", "day/GPa", 1e-9),
    (r"base\.creep\.beta", "base: modulus aging β", "-", 1.0),
    (r"base\.creep\.alpha", "base: modulus aging rate α", "1/day", 1.0),
    (r"base\.creep\.relative_humidity", "base: relative humidity RH", "%", 1.0),
    (r"base\.creep\.notional_size", "base: notional size h", "mm", 1.0),
    (r"base\.thickness", "base: thickness H", "m", 1.0),
    (r"base\.poisson", "base: Poisson ratio", "-", 1.0),
    (r"punch\.half_width", "punch: half-width a", "m", 1.0),
    (r"punches\[(\d+)\]\.center", "punch {k}: centre x", "m", 1.0),
    (r"punches\[(\d+)\]\.half_width", "punch {k}: half-width a", "m", 1.0),
)


@dataclass(frozen=True)
class Choice:
    """A field the tab can vary: ``key`` (its scene path, or :data:`ECCENTRICITY`), its
    name and unit on screen, ``scale`` (SI units per screen unit) and its value in the
    scene on screen [screen units]."""

    key: str
    label: str
    unit: str
    scale: float
    value: float

    @property
    def title(self) -> str:
        """Name and unit, as on an axis."""
        return f"{self.label} [{self.unit}]"


@dataclass(frozen=True)
class Axis:
    """A parameter as typed in the tab: ``key`` of a :class:`Choice`, ``start`` and
    ``stop`` [screen units], ``count`` values, ``spacing`` (``linear`` or ``log``)."""

    key: str
    start: float
    stop: float
    count: int
    spacing: str = "linear"


@dataclass(frozen=True)
class PlannedStudy:
    """A study ready to run: the core study, the choices varied and their values
    [screen units], in the order of the grid (the last fastest)."""

    study: Study
    choices: tuple[Choice, ...]
    values: tuple[np.ndarray, ...]
    spacings: tuple[str, ...] = ()
    outputs: dict[str, tuple[str, str, float]] = field(default_factory=lambda: dict(OUTPUTS))

    def is_log(self, k: int) -> bool:
        """Whether parameter ``k`` is spaced evenly in log."""
        return k < len(self.spacings) and self.spacings[k] == "log"

    @property
    def shape(self) -> tuple[int, ...]:
        """The grid's shape."""
        return tuple(len(v) for v in self.values)


#: Creep models whose answers do not depend on the age at loading (their compliance is
#: a function of the time since loading alone, or constant).
NON_AGING = frozenset({"elastic", "exponential", "prony"})


def study_choices(scene: Mapping[str, Any]) -> list[Choice]:
    """The fields of ``scene`` (a scene dict) the tab offers, loads first: each number
    the scene holds at a path of the table above, and the eccentricity e = M/P [m] when
    force and moment are both given as constants with P > 0."""
    out: list[Choice] = []
    fields = dict(numeric_fields(scene))
    creep = scene.get("base", {}).get("creep", {})
    model = creep.get("model") if isinstance(creep, Mapping) else None
    for pattern, label, unit, scale in _FIELDS:
        for path, value in fields.items():
            match = re.fullmatch(pattern, path)
            if match is None:
                continue
            if path == "base.age_at_loading" and model in NON_AGING:
                continue  # it changes nothing (a study drew a constant, a fit "no reading")
            k = int(match.group(1)) + 1 if "{k}" in label else 0
            out.append(Choice(path, label.format(k=k), unit, scale, value / scale))
        if pattern == r"loading\.moment":
            force, moment = fields.get("loading.force"), fields.get("loading.moment")
            if force is not None and moment is not None and force > 0:
                out.append(Choice(ECCENTRICITY, "loading: eccentricity e = M/P", "m", 1.0,
                                  moment / force))
    return out


def study_outputs(scene: Mapping[str, Any]) -> dict[str, tuple[str, str, float]]:
    """The outputs a study of ``scene`` computes, as :data:`OUTPUTS` (key: name on screen,
    unit on screen, factor from SI): those of :data:`OUTPUTS` for a scene of one punch;
    of a scene of several, each of them for every punch (``punches[k].settlement``:
    "punch 1: settlement"), by punch."""
    punches = scene.get("punches")
    if not isinstance(punches, (list, tuple)):
        return dict(OUTPUTS)
    return {f"punches[{k}].{key}": (f"punch {k + 1}: {name}", unit, factor)
            for k in range(len(punches)) for key, (name, unit, factor) in OUTPUTS.items()}


def _room(scene: Mapping[str, Any], k: int) -> tuple[float, float]:
    """The free surface on each side of punch ``k`` of a scene of several [m]: the gaps
    to the nearest neighbour's edge on its left and its right (inf where it has none)."""
    punches = scene["punches"]
    c, a = float(punches[k]["center"]), float(punches[k]["half_width"])
    left = right = math.inf
    for j, other in enumerate(punches):
        if j == k:
            continue
        cj, aj = float(other["center"]), float(other["half_width"])
        if cj < c:
            left = min(left, (c - a) - (cj + aj))
        else:
            right = min(right, (cj - aj) - (c + a))
    return left, right


def default_range(choice: Choice, scene: Mapping[str, Any] | None = None) -> Axis:
    """A first range for ``choice`` around its value on screen in ``scene`` (its first
    punch's half-width a [m], 1 m without a scene, sizes the eccentricity range when it is
    zero): moduli and the age over a decade each way (log), the Poisson ratio +-0.1, loads
    0 to the middle third's edge (e = a/3) when zero, anything else half to one and a half
    times its value. A punch's
    centre of a scene of several (``scene`` given) moves away from its nearest
    neighbour, from half the gap to four times it (the spacing's study: closer, a punch
    may lift off, which under creep costs seconds to a minute a point); one
    between two moves by half the smaller gap each way. A punch's half-width grows at
    most to touching 90 % of the free room beside it."""
    v = choice.value
    punch = {} if scene is None else (scene["punches"][0] if "punches" in scene
                                      else scene.get("punch", {}))
    half_width = float(punch.get("half_width", 1.0))
    match = re.fullmatch(r"punches\[(\d+)\]\.(center|half_width)", choice.key)
    if match is not None and scene is not None and "punches" in scene:
        left, right = _room(scene, int(match[1]))
        if match[2] == "half_width":
            stop = v + 0.9 * min(left, right)  # both edges move by the growth
            return Axis(choice.key, round(0.5 * v, 6), round(min(1.5 * v, stop), 6), 9)
        if math.isfinite(left) and math.isfinite(right):
            d = 0.5 * min(left, right)
            return Axis(choice.key, round(v - d, 6), round(v + d, 6), 9)
        if math.isfinite(left):  # the rightmost: further right
            return Axis(choice.key, round(v - 0.5 * left, 6), round(v + 3 * left, 6), 9)
        if math.isfinite(right):  # the leftmost: further left
            return Axis(choice.key, round(v - 3 * right, 6), round(v + 0.5 * right, 6), 9)
    if choice.key.endswith(".modulus") or choice.key.endswith("modulus_final"):
        return Axis(choice.key, v / 10, v * 10, 9, "log")
    if choice.key == "base.age_at_loading":
        return Axis(choice.key, max(v / 4, 1.0), v * 4, 9, "log")
    if choice.key.endswith(".poisson"):
        return Axis(choice.key, round(max(0.0, v - 0.1), 3), round(min(0.49, v + 0.1), 3), 9)
    if choice.key == ECCENTRICITY:
        return Axis(choice.key, 0.0, round(half_width / 3 if v == 0 else 2 * abs(v), 6), 9)
    if v == 0:
        return Axis(choice.key, 0.0, 1.0, 9)
    low, high = _BOUNDED.get(choice.key, (-math.inf, math.inf))
    return Axis(choice.key, max(0.5 * v, low), min(1.5 * v, high), 9)


#: Fields whose values the scene bounds [screen units]: their first range stays inside
#: (a relative humidity of 60 % gave 30 to 90 %, below the codes' 40 %; SCENES.md).
_BOUNDED = {"base.creep.relative_humidity": (40.0, 100.0),
            "base.creep.notional_size": (50.0, 1500.0),
            "base.creep.beta": (0.0, 0.95)}


def _axis_values(axis: Axis, field: str) -> np.ndarray:
    """The values of ``axis`` [screen units]; ValueError naming ``field``."""
    if isinstance(axis.count, bool) or not isinstance(axis.count, (int, np.integer)) \
            or not 2 <= axis.count <= MAX_AXIS_POINTS:
        raise ValueError(f"{field}, points: must be a whole number from 2 to "
                         f"{MAX_AXIS_POINTS}, got {axis.count!r}")
    for name, value in (("from", axis.start), ("to", axis.stop)):
        if value is None or (isinstance(value, float) and math.isnan(value)):
            # (an emptied box sends NaN: "must be a number, got nan" was read)
            raise ValueError(f"{field}, {name}: is empty; give a number")
        if not isinstance(value, (int, float)) or not math.isfinite(value):
            raise ValueError(f"{field}, {name}: must be a number, got {value!r}")
    if axis.start == axis.stop:
        raise ValueError(f"{field}, to: equals 'from' ({axis.start:g}); give a range")
    if axis.spacing not in SPACINGS:
        raise ValueError(f"{field}, spacing: must be 'linear' or 'log', got {axis.spacing!r}")
    if axis.spacing == "log":
        if axis.start <= 0 or axis.stop <= 0:
            raise ValueError(f"{field}, from: a log spacing needs both ends > 0, got "
                             f"{axis.start:g} to {axis.stop:g}")
        return np.geomspace(axis.start, axis.stop, int(axis.count))
    return np.linspace(axis.start, axis.stop, int(axis.count))


def plan_study(scene: Mapping[str, Any], axes: Sequence[Axis],
               max_points: int = MAX_POINTS) -> PlannedStudy:
    """The study of ``axes`` (one or two) around ``scene`` (the scene dict on screen).

    Every output of :data:`OUTPUTS` at every output time of the scene. Refused with a
    ``ValueError`` naming the field of the tab (``parameter 1, from: ...``) when a range
    is bad, the grid has more than ``max_points`` points, or the scene is invalid at an
    end of a range (the core's message, with the parameter's name).
    """
    if not 1 <= len(axes) <= 2:
        raise ValueError(f"parameters: choose one or two, got {len(axes)}")
    offered = {c.key: c for c in study_choices(scene)}
    choices: list[Choice] = []
    for i, axis in enumerate(axes):
        field = f"parameter {i + 1}"
        if axis.key not in offered:
            raise ValueError(f"{field}: {axis.key!r} is not a field of this scene the tab "
                             "can vary")
        if any(c.key == axis.key for c in choices):
            raise ValueError(f"{field}: the same field as parameter 1; choose another")
        choices.append(offered[axis.key])
    keys = {c.key for c in choices}
    if ECCENTRICITY in keys and keys & {"loading.force", "loading.moment"}:
        i = 1 + [c.key for c in choices].index(ECCENTRICITY)
        raise ValueError(f"parameter {i}: the eccentricity sets the moment from the force; "
                         "vary it alone or with a field other than the force and moment")
    values = tuple(_axis_values(a, f"parameter {i + 1}") for i, a in enumerate(axes))
    n = math.prod(len(v) for v in values)
    if n > max_points:
        raise ValueError(f"parameter {len(axes)}, points: the study has {n:,} points ("
                         + " x ".join(str(len(v)) for v in values) + f"), more than the "
                         f"limit of {max_points:,} of this page; use fewer points, or run "
                         "it from a study file (coated-punch sweep)")
    vary = []
    for c, v in zip(choices, values, strict=True):
        if c.key == ECCENTRICITY:
            force = float(scene["loading"]["force"])
            vary.append({"field": "loading.moment", "values": [float(e * force) for e in v]})
        else:
            vary.append({"field": c.key, "values": [float(x * c.scale) for x in v]})
    outputs = study_outputs(scene)
    spec = {"study_version": 1, "name": f"{scene.get('name') or 'scene'}: study"[:200],
            "scene": dict(scene), "vary": vary, "outputs": list(outputs)}
    try:
        study = study_from_dict(spec, max_points=max_points)
    except ValueError as exc:
        force = float(scene["loading"]["force"]) if ECCENTRICITY in keys else None
        raise ValueError(_tab_message(str(exc), choices, force)) from None
    return PlannedStudy(study, tuple(choices), values, tuple(a.spacing for a in axes),
                        outputs)


def _tab_message(message: str, choices: Sequence[Choice], force: float | None = None) -> str:
    """A core message about ``vary[i]`` said with the tab's names (``force`` [N/m]: the
    scene's, where the eccentricity sets the moment)."""
    match = re.match(r"vary\[(\d+)\](?:\.[a-z]+)?: ", message)
    if match is None:
        return message
    i = int(match.group(1))
    rest = message[match.end():]
    choice = choices[i]
    # the grid's value as typed in the tab (it read "loading.force = -100000" for -100
    # kN/m)
    invalid = re.match(r"the scene is invalid at (\S+) = (\S+) \(", rest)
    # the eccentricity is varied as the moment: its value is e = M / P (it read
    # "loading.moment = 1.2e+06" for e = 1.5 m)
    varied = ("loading.moment" if choice.key == ECCENTRICITY and force else choice.key)
    if invalid is not None and invalid.group(1) == varied:
        try:
            typed = float(invalid.group(2)) / (force if varied != choice.key else choice.scale)
        except (ValueError, ZeroDivisionError):
            typed = None
        if typed is not None:
            rest = (f"the scene is invalid at {typed:.6g} {choice.unit}".rstrip() + " ("
                    + rest[invalid.end():])
    return f"parameter {i + 1} ({choice.label}): {rest}"


@dataclass
class StudyResult:
    """The answers of a study on its grid (SI units, see ``core.study.definition.OUTPUT_UNITS``):
    ``outputs[name]`` of shape ``grid + (len(times),)``, ``flags`` (comma-joined, or
    ``failed``), ``errors`` (a failed point's message) and ``estimates`` (the solver's
    relative error estimate of each point, NaN where failed) of the grid's shape."""

    planned: PlannedStudy
    times: np.ndarray
    outputs: dict[str, np.ndarray]
    flags: np.ndarray
    errors: np.ndarray
    seconds: float
    estimates: np.ndarray | None = None

    @classmethod
    def from_arrays(cls, planned: PlannedStudy, arrays: Mapping[str, Any]) -> StudyResult:
        """Put the per-point arrays of a run (point order of ``core.study.definition.point_table``:
        the last parameter fastest) on the grid."""
        shape = planned.shape
        outputs = {name: np.asarray(arrays[name], dtype=float).reshape(shape + (-1,))
                   for name in planned.outputs}
        estimates = arrays.get("error_estimate")
        return cls(planned, np.asarray(arrays["time"], dtype=float), outputs,
                   np.asarray(arrays["flags"], dtype=str).reshape(shape),
                   np.asarray(arrays["error"], dtype=str).reshape(shape),
                   float(arrays.get("seconds", 0.0)),
                   None if estimates is None
                   else np.asarray(estimates, dtype=float).reshape(shape))

    @property
    def failed(self) -> np.ndarray:
        """Points without a result."""
        return self.flags == "failed"

    @property
    def flagged(self) -> np.ndarray:
        """Points with a result the solver flagged (contact lost, tolerance not met, ...)."""
        return (self.flags != "") & ~self.failed

    def shown(self, output: str, time_index: int) -> np.ndarray:
        """``output`` at output time ``time_index`` on the grid [screen units]."""
        return self.outputs[output][..., time_index] * self.planned.outputs[output][2]
