"""The fitted fields and the scene's answer as a function of them.

:class:`Fitted` maps each fitted scene field to the coordinate the fit moves (its
logarithm for a positive field, else the value over a scale); :class:`Model` solves the
working scene at a point of those coordinates and returns the settlements and tilts at
the reading times, with forward-difference derivatives. Every solve goes through
:func:`core.scene.solve`, whose stage caches keep the prepared geometry: a point that
changes only loads or creep parameters re-uses the quadrature, the operator and its
modes, and pays for the time stepping alone.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from core.limits import MAX_FIT_PARAMETERS
from core.scene import (
    Scene,
    SceneSolution,
    at_output_times,
    replace_loads,
    scene_from_dict,
    solve,
)
from core.study import apply_point, field_unit, number_at
from core.validation import finite_number, show_value

#: Step of the forward differences in the fit's coordinates: 1e-3 of the logarithm is a
#: 0.1 % change of a positive field. The settlement then moves by ~1e-4..1e-3 of itself,
#: three orders above the working tolerance :data:`FIT_SOLVER_TOL`, so the solver's
#: error is ~1e-3 of a derivative; a larger step costs accuracy in the curvature term
#: (relative error of the derivative about half the step).
FD_STEP = 1e-3
#: A fit whose normalised Jacobian has a condition number above this does not determine
#: every field: along the weakest direction the readings pin a combination ~1000 times
#: less well than along the strongest (a correlation of 0.999998 between two fields). An
#: exactly degenerate pair (coating thickness and modulus, whose ratio alone matters)
#: measures ~1e4 and more, set by the finite differences' own error (~1e12
#: with central ones).
MAX_CONDITION = 1e3
#: The central differences resolve a combination of the fields whose singular value
#: (of the column-scaled Jacobian) is at least this share of the largest: their own error
#: (h^2 = 1e-6 of :data:`FD_STEP`). Below it the covariance along that combination is the
#: differences' round-off (a coating's thickness and modulus, whose ratio alone counts:
#: 3.6e-13, a covariance of ~1e24), and a forecast is given a band from the resolved
#: combinations alone, where its gradient's share along the others is at most
#: :data:`UNDETERMINED_SHARE`, and none (infinite) otherwise. A merely ill-conditioned fit
#: (condition 5e4, say) keeps its covariance's band.
RESOLVED_SINGULAR_SHARE = 1e-6
#: See :data:`RESOLVED_SINGULAR_SHARE`: the same error again. A settlement forecast of the
#: thickness-and-modulus pair leaves 1.4e-13 to 3.8e-13 of it along the undetermined
#: combination (round-off; tests/back_analysis).
UNDETERMINED_SHARE = 1e-6
#: The solver tolerance of the fit's solves (the scene's own when tighter): at it the
#: shipped young-concrete scene's settlement is 3.9e-9 from the answer at tol 1e-11
#: (1.6e-6 at tol 1e-4; benchmarks/results/creep_honesty.md), so the solves' error is
#: far below any derivative the steps above measure.
FIT_SOLVER_TOL = 1e-6


@dataclass(frozen=True)
class Field:
    """One fitted scene field: its ``path``, ``start`` value, whether the fit moves its
    logarithm (``log``) or its value over ``scale``, and its ``bounds`` (values)."""

    path: str
    start: float
    log: bool
    scale: float
    bounds: tuple[float, float]
    unit: str

    def to_x(self, value: float) -> float:
        """The fit's coordinate of ``value``."""
        return math.log(value) if self.log else value / self.scale

    def to_value(self, x: float) -> float:
        """The field's value at coordinate ``x``."""
        return math.exp(x) if self.log else x * self.scale

    @property
    def x_bounds(self) -> tuple[float, float]:
        """The bounds in the fit's coordinate (a log field's bound 0 is -inf)."""
        lo, hi = self.bounds
        if self.log:
            return (math.log(lo) if lo > 0 else -math.inf,
                    math.log(hi) if math.isfinite(hi) else math.inf)
        return (lo / self.scale, hi / self.scale)


def _bound_pair(spec: Any, field: str) -> tuple[float, float]:
    if isinstance(spec, (str, bytes, Mapping)) or not isinstance(spec, Sequence) \
            or len(spec) != 2:
        raise ValueError(f"{field}: must be a pair (low, high), either may be None, got "
                         f"{show_value(spec)}")
    lo = -math.inf if spec[0] is None else finite_number(spec[0], f"{field}[0]")
    hi = math.inf if spec[1] is None else finite_number(spec[1], f"{field}[1]")
    if not hi > lo:
        raise ValueError(f"{field}: high ({show_value(hi)}) must exceed low "
                         f"({show_value(lo)})")
    return lo, hi


def fitted_fields(base: Mapping[str, Any], fit: Any, bounds: Any) -> tuple[Field, ...]:
    """The fitted fields of the scene dict ``base`` (canonical form): ``fit`` their
    paths, ``bounds`` an optional mapping ``path -> (low, high)``. A field positive at
    the start and not allowed below zero is fitted by its logarithm. ValueError naming
    ``fit[i]`` or ``bounds[path]``."""
    if isinstance(fit, str):
        fit = [fit]
    if not isinstance(fit, (list, tuple)) or not 1 <= len(fit) <= MAX_FIT_PARAMETERS:
        raise ValueError(f"fit: must be a list of 1 to {MAX_FIT_PARAMETERS} scene field "
                         "paths (e.g. ['coating[0].modulus']), got "
                         + (str(len(fit)) if isinstance(fit, (list, tuple))
                            else show_value(fit)))
    bounds = {} if bounds is None else bounds
    if not isinstance(bounds, Mapping):
        raise ValueError(f"bounds: must map a fitted path to (low, high), got "
                         f"{show_value(bounds)}")
    for path in bounds:
        if path not in fit:
            raise ValueError(f"bounds[{path}]: not one of the fitted fields "
                             f"({', '.join(map(str, fit))})")
    fields = []
    for i, path in enumerate(fit):
        start = number_at(base, path, f"fit[{i}]", "fitted",
                          "the output times are the readings' times")
        if path.split(".", 1)[0] == "solver":
            raise ValueError(f"fit[{i}]: {path!r} cannot be fitted (the solver's settings "
                             "are not a property of the foundation: the readings say "
                             "nothing of them)")
        if path in fit[:i]:
            raise ValueError(f"fit[{i}]: {path!r} is fitted twice")
        lo, hi = _bound_pair(bounds[path], f"bounds[{path}]") if path in bounds \
            else (-math.inf, math.inf)
        if not lo <= start <= hi:
            raise ValueError(f"bounds[{path}]: the scene's value {start:.6g} (the start "
                             f"of the fit) is outside [{lo:.6g}, {hi:.6g}]")
        # (a start on a bound is moved strictly inside by the least-squares solver)
        log = start > 0 and (lo >= 0 or path not in bounds)
        if log:
            lo = max(lo, 0.0)
            scale = 1.0
        elif start != 0:
            scale = abs(start)
        elif math.isfinite(hi - lo):
            scale = (hi - lo) / 2
        else:
            raise ValueError(f"bounds[{path}]: the start is 0, which gives the field no "
                             "scale; give finite bounds (low, high)")
        fields.append(Field(path, start, log, scale, (lo, hi), field_unit(path)))
    return tuple(fields)


def central(first: np.ndarray, other: np.ndarray) -> np.ndarray:
    """The central differences of :meth:`Model.two_sided`'s two sides where a column has
    both, the first side's where it has one (``other`` NaN)."""
    both = np.all(np.isfinite(other), axis=0)
    return np.where(both, 0.5 * (first + np.where(both, other, 0.0)), first)


def scaled_svd(J: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray,
                                       np.ndarray]:
    """``(norms, safe, u, sv, vt)``: the singular values of ``J`` with its columns scaled
    to unit length (``safe``: the norms, 1 for a zero column), the measure of which
    combinations of the fields the readings determine."""
    norms = np.linalg.norm(J, axis=0)
    safe = np.where(norms > 0, norms, 1.0)
    u, sv, vt = np.linalg.svd(J / safe, full_matrices=False)
    return norms, safe, u, sv, vt


class Model:
    """The readings the working scene predicts as a function of the fit's coordinates.

    ``work`` is the scene dict the fields' values are set on, ``times`` the output times
    it is solved at (None: its own): the values are set first, then the times, each load
    the same function of time as at the scene's own output times
    (:func:`core.scene.at_output_times`: a ``linear`` history, whose ``end`` may be a
    fitted field, keeps its span). ``fields`` are the fitted fields. :meth:`solve`
    answers one point (a :class:`SceneSolution`);
    :meth:`values` the settlements and tilts (``series``) stacked in one vector;
    :meth:`jacobian` their forward differences. ``solves`` counts the solves.
    """

    def __init__(self, work: Mapping[str, Any], fields: Sequence[Field],
                 series: Sequence[str], times: Any = None) -> None:
        self.work = dict(work)
        self.times = times
        self.fields = tuple(fields)
        self.series = tuple(series)
        self.solves = 0
        self._cache: dict[tuple[float, ...], SceneSolution] = {}
        given = set(work.get("loading", {}))
        loads = [f.path.split(".", 1)[1] for f in fields
                 if f.path.startswith("loading.") and f.path.count(".") == 1]
        # a fit of given loads alone re-uses one validated scene (only the loads are
        # checked again), as a study's load batch does
        self._load_names = loads if len(loads) == len(fields) and set(loads) <= given \
            else None
        self._scene: Scene | None = None

    def __getstate__(self) -> dict[str, Any]:
        # the answers kept and the validated scene are caches (and a Scene holds
        # read-only mappings, which do not pickle): a copy sent to another process
        # (the explorer's report is written in a worker) solves again where it needs to
        state = self.__dict__.copy()
        state.update(_cache={}, _scene=None)
        return state

    def values_at(self, x: Sequence[float]) -> dict[str, float]:
        """The field values at coordinates ``x``."""
        return {f.path: f.to_value(float(v)) for f, v in zip(self.fields, x, strict=True)}

    def scene_dict(self, x: Sequence[float]) -> dict[str, Any]:
        """The scene dict solved at ``x``: the values set, then the output times."""
        scene = apply_point(self.work, self.values_at(x))
        return scene if self.times is None else at_output_times(scene, self.times)

    def solve(self, x: Sequence[float]) -> SceneSolution:
        """The answer at ``x`` (the last few are kept: the fit asks twice for a point)."""
        key = tuple(float(v) for v in x)
        if key in self._cache:
            return self._cache[key]
        if self._load_names is not None:
            if self._scene is None:
                self._scene = scene_from_dict(self.work if self.times is None
                                              else at_output_times(self.work, self.times))
            values = self.values_at(x)
            scene = replace_loads(self._scene, {name: values[f"loading.{name}"]
                                                for name in self._load_names})
        else:
            scene = scene_from_dict(self.scene_dict(x))
        result = solve(scene)
        self.solves += 1
        if len(self._cache) >= 2 * len(self.fields) + 4:
            self._cache.pop(next(iter(self._cache)))
        self._cache[key] = result
        return result

    def values(self, x: Sequence[float]) -> np.ndarray:
        """The settlements [m] then the tilts [rad] at every output time, stacked."""
        result = self.solve(x)
        return np.concatenate([np.asarray(getattr(result, name), dtype=float)
                               for name in self.series])

    def steps(self, x: Sequence[float]) -> np.ndarray:
        """The signed forward-difference step of each coordinate at ``x``: backward where
        a forward step would cross the upper bound."""
        h = np.full(len(self.fields), FD_STEP)
        for j, f in enumerate(self.fields):
            if x[j] + h[j] > f.x_bounds[1]:
                h[j] = -h[j]
        return h

    def jacobian(self, x: Sequence[float], centre: np.ndarray | None = None) -> np.ndarray:
        """The forward differences of :meth:`values` at ``x``, a column per field
        (``centre``: the values at ``x`` when known)."""
        x = np.asarray(x, dtype=float)
        f0 = self.values(x) if centre is None else centre
        h = self.steps(x)
        columns = []
        for j in range(len(x)):
            columns.append(self._difference(x, f0, j, h[j]))
        return np.column_stack(columns)

    def two_sided(self, x: Sequence[float], centre: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`jacobian` at ``x`` (``centre``: the values there) and the differences on
        the other side of its steps, a column per field; a column of the second is NaN
        where only one side is a point within the bounds that the solver accepts. Where
        both are given, their mean is the central difference (error ~h^2 instead of ~h)
        and half their difference measures the error of the one-sided one."""
        x = np.asarray(x, dtype=float)
        first = self.jacobian(x, centre)
        h = self.steps(x)
        other = np.full(first.shape, np.nan)
        for j in range(len(x)):
            sides = []
            for step in (h[j], -h[j]):
                xj = x.copy()
                xj[j] += step
                if not self.fields[j].x_bounds[0] <= xj[j] <= self.fields[j].x_bounds[1]:
                    continue
                try:
                    sides.append((self.values(xj) - centre) / step)
                except ValueError:
                    continue
            if len(sides) == 2:  # (the first side is what jacobian took)
                other[:, j] = sides[1]
        return first, other

    def _difference(self, x: np.ndarray, f0: np.ndarray, j: int, h: float) -> np.ndarray:
        """The one-sided difference of :meth:`values` along coordinate ``j``: the other
        side where the scene refuses the step's point (the answer sits at the edge of
        the values it accepts, a Poisson ratio near 0.5 say)."""
        refusal = None
        for step in (h, -h):
            xj = x.copy()
            xj[j] += step
            if not self.fields[j].x_bounds[0] <= xj[j] <= self.fields[j].x_bounds[1]:
                continue
            try:
                return (self.values(xj) - f0) / step
            except ValueError as exc:
                refusal = exc
        raise ValueError(f"fit: {self.fields[j].path}: no difference step on either side "
                         f"is a scene the solver accepts ({refusal})")
