"""A batch of load changes on one scene answered with array operations.

On an elastic base under a uniform coating the exact layered kernel answers
(:mod:`core.engines.layered.answer`), and the problem is linear: the pressure is the gap's response
plus a settlement times the unit-settlement response plus a tilt times the unit-tilt
response (:class:`core.engines.layered.LayeredResponse`). A batch of constant loads is then
a batch of 2 x 2 solves and matrix products: the unknowns, the error estimate of
:func:`core.engines.layered.solve_layered`, the lift-off test of
:func:`core.engines.layered.solve_scene_layered`, the flags of
:class:`core.scene.SceneSolution` and the pressure on its plotting grid, for every point
at once, as :func:`core.scene.solve` computes them for one point.

A point this path does not answer the same way is left to :func:`core.scene.solve`
(``answered`` false): a load that the scene's checks would refuse (non-finite, a pulled
punch, a resultant outside the base, beyond double precision), an estimate that would
need more modes than the default, a pressure that comes out negative when the contact
model is ``auto`` (lift-off: the unilateral solver answers), a non-finite answer.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from core.engines.layered import (
    COARSE_ERROR_FLOOR,
    COARSE_TOL,
    ERROR_FLOOR,
    LIFT_OFF_SHARE,
    MAX_MODES,
    PRESSURE_REACH,
    LayeredResponse,
    cached_response,
    corner_reach,
    default_modes,
    gap_key,
    geometric_tail,
    layered_declines,
    stack_key,
    uniform_layers,
)
from core.profiles import profile_values
from core.scene import LARGE_TILT, Scene, contact_width, plotting_grid, strain_share
from core.study.definition import OUTPUT_UNITS
from core.validation import MAX_MAGNITUDE

__all__ = ["LoadBatch", "load_batch_applies", "solve_load_batch"]

_KINEMATIC = ("settlement", "tilt")
_NAMES = ("settlement", "tilt", "force", "moment")


@dataclass
class LoadBatch:
    """The answers of :func:`solve_load_batch` for ``n`` points: ``answered`` (bool, n);
    where answered, ``values`` ``(n, len(outputs), n_times)`` in the units of
    :data:`core.study.definition.OUTPUT_UNITS`, ``error_estimate`` (relative, -) and ``flags``
    (comma-joined) as :func:`core.study.run_batch` records a solved point."""

    answered: np.ndarray
    values: np.ndarray
    error_estimate: np.ndarray
    flags: list[str]


def load_batch_applies(scene: Scene) -> bool:
    """Whether :func:`solve_load_batch` can answer load changes of ``scene``: the exact
    layered kernel answers it (elastic base, uniform coating, smooth punch) and every
    given load is a constant."""
    if not all(getattr(p, "kind", None) == "constant" for p in scene.loading.values()):
        return False
    return layered_declines(scene, scene.dimensionless) is None


def _dimensionless_loads(scene: Scene, loads: Mapping[str, np.ndarray],
                         n: int) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """The given loads of every point, dimensionless as :func:`core.scene.pipeline.to_dimensionless`
    converts a constant load (the same operations, so the same numbers), and the points
    whose loads the scene's checks pass without a doubt."""
    problem = scene.dimensionless
    a = scene.half_width
    plane, e0 = problem.plane_factor, problem.modulus_at_loading
    given: dict[str, np.ndarray] = {}
    dimensional: dict[str, np.ndarray] = {}
    plain = np.ones(n, dtype=bool)
    with np.errstate(all="ignore"):
        for name, profile in scene.loading.items():
            if name in loads:
                value = np.asarray(loads[name], dtype=float).reshape(n)
            else:
                value = np.full(n, profile_values(profile, np.zeros(1))[0])
            dimensional[name] = value
            if name in _KINEMATIC:
                scale = 1.0 / a if name == "settlement" else 1.0
                given[name] = scale * value
            else:
                a_power = a if name == "force" else a * a
                given[name] = plane * value / (e0 * a_power)
            plain &= np.isfinite(value) & np.isfinite(given[name]) \
                & (np.abs(given[name]) <= MAX_MAGNITUDE)
        # core.scene.load_limits.check_loads_touch refuses these (with its message)
        if "force" in dimensional:
            force = dimensional["force"]
            plain &= force > 0.0
            if "moment" in dimensional:
                e = dimensional["moment"] / np.where(force > 0.0, force, 1.0)
                plain &= np.abs(e) < a
    return given, plain


def _differences(response: LayeredResponse, given: Mapping[str, np.ndarray],
                 fine: Mapping[str, np.ndarray], level: int) -> dict[str, np.ndarray]:
    """Per point (column), the relative differences of levels ``level`` and ``level - 1``
    as :func:`core.engines.layered.solve_layered` measures them over one point's times."""
    other = response.complete(dict(given), level=level)
    better = response.complete(dict(given), level=level - 1)
    kin = np.maximum(np.abs(fine["settlement"]), np.abs(fine["tilt"]))
    stat = np.maximum(np.abs(fine["force"]), np.abs(fine["moment"]))
    out = {}
    for name in _NAMES:
        scale = kin if name in _KINEMATIC else stat
        diff = np.abs(other[name] - better[name])
        out[name] = np.where(scale > 0, diff / np.where(scale > 0, scale, 1.0), diff)
    t = PRESSURE_REACH * np.cos(np.linspace(0.0, np.pi, 91))
    root = np.sqrt(1 - t * t)[:, None]
    q = response.regular_part(t, fine["settlement"], fine["tilt"])
    q_scale = np.max(np.abs(q / root), axis=0)
    q_diff = response.regular_part(t, better["settlement"], better["tilt"], level=level - 1) \
        - response.regular_part(t, other["settlement"], other["tilt"], level=level)
    q_diff = np.max(np.abs(q_diff / root), axis=0)
    out["pressure"] = np.where(q_scale > 0, q_diff / np.where(q_scale > 0, q_scale, 1.0),
                               q_diff)
    return out


def _response(scene: Scene, layers: list, modes: int, room: int) -> LayeredResponse:
    """The scene's unit responses on ``modes`` modes, from the caches
    :func:`core.engines.layered.solve_layered` fills (built once per geometry), with the
    same rules (chosen by the scene's tol) and the same ``room`` for doubling, so a batch
    reads the very table and Galerkin matrix one point's solve reads."""
    problem = scene.dimensionless
    a, h, e0, nu = (scene.half_width, scene.base_thickness, problem.modulus_at_loading,
                    scene.base_poisson)
    keys = (stack_key(a, layers, h, e0, nu), gap_key(problem.g, problem.breakpoints))
    return cached_response(a, layers, h, e0, nu, problem.g, problem.breakpoints, modes,
                            keys, {}, tol=problem.tol, room=room)


@dataclass
class _Level:
    """The answers of some points on one mode count (arrays over those points)."""

    settled: np.ndarray
    keep: np.ndarray
    rows: np.ndarray
    error: np.ndarray
    numerical: np.ndarray
    lost: np.ndarray
    tilt: np.ndarray
    settlement: np.ndarray
    pressure_max: np.ndarray  # [Pa] the largest on the plotting grid over the times


def _answer_level(scene: Scene, response: LayeredResponse, given: Mapping[str, np.ndarray],
                  outputs: Sequence[str], last: bool) -> _Level:
    """The points of ``given`` on ``response``: which settle on its modes (estimate below
    tol / 2, or ``last``) and, for those kept, their outputs as one point's solve gives."""
    problem = scene.dimensionless
    a = scene.half_width
    fine = response.complete(dict(given))
    d1 = _differences(response, given, fine, level=1)
    d0 = _differences(response, given, fine, level=2)
    unknowns = [name for name in _NAMES if name not in given]
    floor = COARSE_ERROR_FLOOR if problem.tol >= COARSE_TOL else ERROR_FLOOR
    errors = {}
    for name in unknowns + ["pressure"]:
        errors[name] = np.maximum(geometric_tail(d1[name], d0[name]), floor)
    error = np.max(np.stack(list(errors.values())), axis=0)
    numerical = np.max(np.stack([errors[name] for name in unknowns]), axis=0)
    met = error <= 0.5 * problem.tol
    settled = met | last
    # a point past tol / 2 on the most modes is flagged tol_not_met: one by one
    keep = met.copy()
    # lift-off, as solve_scene_layered tests it
    theta = np.linspace(0.0, np.pi, 8 * response.modes + 1)
    regular = response.regular_part(np.cos(theta), fine["settlement"], fine["tilt"])
    q_scale = np.maximum(np.max(np.abs(regular), axis=0), 1e-300)
    lost = np.min(regular, axis=0) < -np.maximum(error, LIFT_OFF_SHARE) * q_scale
    if scene.contact in ("auto", "unilateral"):
        # solved one by one (without coating the lift-off is the layered path's too)
        keep &= ~lost
    # the pressure on the plotting grid, as the solution's evaluate gives it
    x = plotting_grid(a)
    edge = corner_reach(uniform_layers(scene), a)
    t = np.clip(np.clip(x / a, -1.0, 1.0), -edge, edge)
    q_star = response.regular_part(t, fine["settlement"], fine["tilt"]) \
        / np.sqrt(1.0 - t * t)[:, None]
    times = np.array(scene.times, dtype=float)
    pressure_scale = problem.modulus_after_loading(times) / problem.plane_factor
    dimensional = {"settlement": a * fine["settlement"], "tilt": fine["tilt"],
                   "force": fine["force"][:, None] * pressure_scale * a,
                   "moment": fine["moment"][:, None] * pressure_scale * a * a}
    n = len(error)
    # every point here is a full-contact answer: its contact set is the whole base
    width = contact_width([[(-a, a)]], a)[0]
    rows = np.empty((n, len(outputs), times.size))
    pressure_max = np.zeros(n)
    for k in range(times.size):
        q = q_star * pressure_scale[k]
        pressure_max = np.fmax(pressure_max, np.max(q, axis=0))
        for j, name in enumerate(outputs):
            if name in ("settlement", "tilt"):
                rows[:, j, k] = dimensional[name]
            elif name in ("force", "moment"):
                rows[:, j, k] = dimensional[name][:, k]
            elif name == "q_max":
                rows[:, j, k] = np.max(q, axis=0)
            elif name == "q_min":
                rows[:, j, k] = np.min(q, axis=0)
            else:
                rows[:, j, k] = width
        keep &= np.all(np.isfinite(q), axis=0)
    # core.scene.pipeline._check_finite refuses a non-finite answer with its message
    keep &= np.all(np.isfinite(rows), axis=(1, 2))
    for name in _NAMES:
        keep &= np.isfinite(dimensional[name]).reshape(n, -1).all(axis=1)
    return _Level(settled, keep & settled, rows, error, numerical, lost, fine["tilt"],
                  a * fine["settlement"], pressure_max)


def solve_load_batch(scene: Scene, loads: Mapping[str, np.ndarray],
                     outputs: Sequence[str]) -> LoadBatch:
    """Answer ``scene`` with the given loads of each point replaced by ``loads[name][i]``
    (N/m, N, m or rad as in the scene file; loads not named keep the scene's value), for
    the ``outputs`` of :data:`core.study.definition.OUTPUT_UNITS` at the scene's times. Requires
    :func:`load_batch_applies`. Points not ``answered`` must be solved one by one.

    The modes grow as :func:`core.engines.layered.solve_layered` grows them for one point:
    from :func:`core.engines.layered.solve.default_modes`, doubled for the points whose estimate
    is still above ``tol / 2``, up to :data:`core.engines.layered.solve.MAX_MODES`."""
    unknown = [name for name in outputs if name not in OUTPUT_UNITS]
    if unknown:
        raise ValueError(f"outputs: unknown {unknown}")
    n = len(next(iter(loads.values()))) if loads else 1
    given, answered = _dimensionless_loads(scene, loads, n)
    values = np.full((n, len(outputs), len(scene.times)), np.nan)
    estimate = np.full(n, np.nan)
    flags = [""] * n
    layers = uniform_layers(scene)
    pending = np.flatnonzero(answered)
    answered[:] = False
    modes = min(default_modes(scene.half_width, layers), MAX_MODES)
    room = min(2 * modes, MAX_MODES)  # as solve_layered reserves it
    with np.errstate(all="ignore"):
        while pending.size:
            last = 2 * modes > MAX_MODES
            level = _answer_level(scene, _response(scene, layers, modes, room),
                                  {name: v[pending] for name, v in given.items()}, outputs,
                                  last)
            for i in np.flatnonzero(level.keep):
                point = pending[i]
                point_flags = ["contact_lost"] if level.lost[i] else []
                # the numerical estimate stands for the coating model's (0 without one)
                if scene.coating and level.numerical[i] > scene.model_tol:
                    point_flags.append("model_error")
                if strain_share(scene, level.settlement[i], level.tilt[i],
                                level.pressure_max[i]) > 1.0:
                    point_flags.append("large_settlement")
                if abs(level.tilt[i]) > LARGE_TILT:
                    point_flags.append("large_tilt")
                flags[point] = ",".join(point_flags)
                values[point] = level.rows[i]
                estimate[point] = float(level.error[i])
                answered[point] = True
            pending = pending[~level.settled]
            modes *= 2
    return LoadBatch(answered, values, estimate, flags)
