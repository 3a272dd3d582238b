"""Lift-off answers of many eccentricities of one flat punch, located along the zone end.

On a flat punch over an elastic base (uniform coating, no gap) the unilateral problem is
homogeneous in the loads: its answer per unit force depends on the eccentricity
``e = M / (P a)`` alone, and with lift-off the contact zone is one interval ``[c, 1]``
(``e > 0``; ``[-1, c]`` for ``e < 0``). Parametrized by the zone end ``c`` instead of
``e``, the answer is a smooth function of ``c``: on the zone the two unit responses
(settlement 1 and tilt 1) of the thin-layer model are solved on the Nystrom rule of
:mod:`core.contact.zones` (:func:`core.contact.zone_panels`, the unilateral
solver's own), and the free-end condition ``Q(c) = 0`` fixes the ratio of tilt to
settlement; the force and the moment of that combination give ``e(c)``.

:func:`liftoff_family` builds ``e(c)`` on Chebyshev-Lobatto points in ``c`` between the
zone ends of the batch's smallest and largest eccentricity (both solved by
:func:`core.scene.solve`, which also fixes the topology), inverts it for every other
eccentricity (its error estimated per point against the interpolant of half the degree,
on the nested points) and solves each point once on its zone ``[c*, 1]``: settlement,
tilt and the pressure on the plotting grid come from that solve, so ``q_max`` and ``q_min``
are the point's own grid extremes (nothing is interpolated through the kinks of a max over
a grid), and the contact width is its zone's length. The discretization error is that of
each family point against the next coarser panel rule, as
:func:`core.contact.refine_zone_ends` estimates it. A point is answered only when its
zone end is within a third of :data:`core.contact.ZONE_END_TOL` (the interpolant's
estimate, the discretization's and the zone's own miss of ``e`` through ``de/dc``), its
outputs within a third of ``tol``, and its pressure passes the contact set's check; the
others are left to :func:`core.scene.solve`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from types import SimpleNamespace
from typing import Any

import numpy as np

from core.contact import (
    ZONE_EDGE_WIDTH,
    ZONE_END_TOL,
    ZONE_PANEL_WIDTH,
    Resolution,
    Space,
    zone_panels,
)
from core.discretize import kernel_operator, operator_rows
from core.scene import (
    LARGE_TILT,
    Scene,
    contact_width,
    narrowest_zone,
    plotting_grid,
    scene_model_error,
    strain_share,
    thick_coating,
)
from core.study.outputs import point_outputs

__all__ = ["FAMILY_MIN_ECCENTRICITIES", "LiftoffAnswer", "liftoff_family"]

#: Eccentricities between a family's two ends below which it is not built: its 9 to 33
#: family points (each with its coarser check) cost about as much as this many
#: one-by-one lift-off solves.
FAMILY_MIN_ECCENTRICITIES = 8
#: Chebyshev-Lobatto degrees tried in turn (nested: each reuses the solves of the one
#: before; the estimate of degree N is the difference to degree N / 2).
_DEGREES = (8, 16, 32)
#: Panel-rule refinements of the whole family before it gives up (as the one-point
#: solver's :data:`core.contact.zones.MAX_LEVELS`).
_MAX_LEVELS = 4
#: Pressure on the zone below this share of its largest value counts as negative, and
#: above it off the zone as an overlap (the one-point solver's check of the contact set).
_CONTACT_CHECK = 1e-8
#: Absolute accuracy of the kernel values where the pressure is only checked for its sign
#: (off the zone): it moves Q by ~1e-12 / m per unit force, below :data:`_CONTACT_CHECK`
#: for any coating compliance m above 1e-4 (m = 0.36 on the preset's coating).
_CHECK_ACCURACY = 1e-12
_CHECK_ACCURACY_MIN_M = 1e-4
#: Absolute accuracy of the kernel values of the zone solves: they move the pressure per
#: unit force by ~1e-12 / m, far below tol (measured: the outputs' largest difference to
#: core.solve on four lift-off batches of the loads study unchanged at 2.3e-9; ~8 % less
#: CPU than the full accuracy).
_SOLVE_ACCURACY = 1e-12


@dataclass(frozen=True)
class LiftoffAnswer:
    """One eccentricity's answer at the force ``force`` [N/m]: ``values`` (outputs x
    times, units of :data:`core.study.definition.OUTPUT_UNITS`), ``estimate`` (relative, -),
    ``flags``, the largest |tilt| [rad] and :func:`core.scene.strain_share`, as
    :func:`core.study.run_batch` keeps a solved point to scale it."""

    force: float
    values: np.ndarray
    estimate: float
    flags: list[str]
    tilt: float
    strain_share: float


def _callable(value: Any) -> Callable[[np.ndarray], np.ndarray]:
    if callable(value):
        return lambda x, _f=value: np.broadcast_to(
            np.asarray(_f(np.asarray(x, dtype=float)), dtype=float), np.shape(x)).astype(float)
    return lambda x, _v=float(value): np.full(np.shape(x), _v)


@dataclass
class _Node:
    """The zone ``c``'s answer per unit force (dimensionless): eccentricity, settlement,
    tilt and the Nystrom pressure on the plotting grid; and the same on the coarser rule's
    differences (the discretization estimate)."""

    e: float
    settlement: float
    tilt: float
    grid: np.ndarray
    error: float
    e_error: float


def _unit_zone(space: Space, c_rel: float, ends: list[float], res: Resolution,
               end_index: int, x_grid: np.ndarray) -> tuple[float, float, float, np.ndarray]:
    """Per unit force on the zone ``ends`` with the free end ``ends[end_index]``: (e,
    settlement, tilt, Q on ``x_grid``), the tilt-to-settlement ratio set by Q(end) = 0."""
    panels = zone_panels(space, ends, res)
    x, w = panels.nodes, panels.weights
    matrix = kernel_operator(space.lam, panels, accuracy=_SOLVE_ACCURACY).matrix.copy()
    matrix[np.arange(x.size), np.arange(x.size)] += c_rel * space.m(x)
    q = np.linalg.solve(matrix, np.column_stack([np.ones(x.size), x]))
    end = ends[end_index]
    inward = 1.0 if end_index % 2 == 0 else -1.0
    targets = np.concatenate([[end], x_grid])
    # off the zone Q only has to be <= 0 (the gap open): its kernel values to a looser
    # accuracy, far below the check's threshold
    inside = (targets >= end) if inward > 0 else (targets <= end)
    inside[0] = True
    fq = np.empty((targets.size, 2))
    fq[inside] = operator_rows(space.lam, panels, targets[inside],
                               accuracy=_SOLVE_ACCURACY) @ q
    if not inside.all():
        loose = float(np.min(space.m(targets[~inside]))) >= _CHECK_ACCURACY_MIN_M
        fq[~inside] = operator_rows(space.lam, panels, targets[~inside], **(
            {"accuracy": _CHECK_ACCURACY} if loose else {})) @ q
    side = targets.copy()
    side[0] = np.clip(end + 1e-13 * inward, -1.0, 1.0)  # m sampled from inside the zone
    scale = c_rel * space.m(side)
    unit = np.column_stack([1.0 - fq[:, 0], targets - fq[:, 1]]) / scale[:, None]
    # settlement and tilt in the ratio that makes Q vanish at the free end
    delta, alpha = unit[0, 1], -unit[0, 0]
    combined = q @ np.array([delta, alpha])
    force = float(w @ combined)
    moment = float((w * x) @ combined)
    grid = (unit[1:] @ np.array([delta, alpha])) / force
    return moment / force, delta / force, alpha / force, grid


def _node(space: Space, c_rel: float, end: float, side: int, res: Resolution,
          x_grid: np.ndarray) -> _Node:
    ends = [end, 1.0] if side > 0 else [-1.0, end]
    index = 0 if side > 0 else 1
    e, d, a, grid = _unit_zone(space, c_rel, ends, res, index, x_grid)
    e0, d0, a0, grid0 = _unit_zone(space, c_rel, ends, res.coarser(), index, x_grid)
    kin = max(abs(d), abs(a), 1e-300)
    q_scale = max(float(np.max(np.abs(grid))), 1e-300)
    error = max(abs(d - d0) / kin, abs(a - a0) / kin,
                float(np.max(np.abs(grid - grid0))) / q_scale)
    return _Node(e, d, a, grid, error, abs(e - e0))


def _lobatto(lo: float, hi: float, degree: int) -> np.ndarray:
    return 0.5 * (lo + hi) + 0.5 * (hi - lo) * np.cos(np.pi * np.arange(degree + 1) / degree)


def _barycentric(nodes: np.ndarray, values: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The polynomial through ``(nodes, values)`` (Chebyshev-Lobatto points) at ``t``;
    ``values`` may have trailing axes. Returns shape ``t.shape + values.shape[1:]``."""
    n = nodes.size - 1
    weights = (-1.0) ** np.arange(n + 1)
    weights[0] *= 0.5
    weights[-1] *= 0.5
    d = t[:, None] - nodes[None, :]
    exact = d == 0.0
    d[exact] = 1.0
    ratio = weights[None, :] / d
    out = np.tensordot(ratio, values, axes=(1, 0)) / ratio.sum(axis=1).reshape(
        (-1,) + (1,) * (values.ndim - 1))
    hit_t, hit_node = np.nonzero(exact)
    out[hit_t] = values[hit_node]
    return out


def _invert(nodes: np.ndarray, e_nodes: np.ndarray, targets: np.ndarray) -> np.ndarray:
    """The zone ends where the interpolant of ``e`` equals ``targets`` (bisection, e
    monotone along the family), clipped to the nodes' range."""
    lo = np.full(targets.size, float(nodes.min()))
    hi = np.full(targets.size, float(nodes.max()))
    rising = e_nodes[np.argmax(nodes)] > e_nodes[np.argmin(nodes)]
    for _ in range(64):  # 2^-64 of the range: below rounding
        mid = 0.5 * (lo + hi)
        above = _barycentric(nodes, e_nodes, mid) > targets
        if not rising:
            above = ~above
        hi = np.where(above, mid, hi)
        lo = np.where(above, lo, mid)
    return 0.5 * (lo + hi)


def liftoff_family(scene: Scene, eccentricities: np.ndarray, forces: np.ndarray,
                   ends: tuple[float, float], outputs: Sequence[str],
                   flags: Sequence[str]) -> tuple[list[LiftoffAnswer | None], dict[str, Any]]:
    """Answers of ``scene`` at the dimensionless eccentricities ``eccentricities``
    (``M / (P a)``, all of one sign, strictly between those of two points
    :func:`core.scene.solve` answered with lift-off, whose zone ends ``ends`` [-] are
    the free ends at the smallest and the largest ``|e|``) under the forces ``forces``
    [N/m] (one point per eccentricity), for ``outputs`` of
    :data:`core.study.definition.OUTPUT_UNITS`. ``flags`` are the geometry's flags of those
    two answers (the contact-model ones and ``large_settlement``, ``large_tilt``,
    ``model_error`` and ``thick_coating`` excluded: they are decided per point here, the
    last two on its zone). Requires :func:`core.study.answers_scale_with_loads`
    and a modulus constant over the scene's times.

    Returns one :class:`LiftoffAnswer` per eccentricity, None where the estimate misses
    the tolerance (to be solved one by one), and what the family cost (``zone_solves``,
    ``degree``, ``levels``).
    """
    problem = scene.dimensionless
    a = scene.half_width
    times = np.asarray(scene.times, dtype=float)
    side = 1 if eccentricities[0] > 0 else -1
    m_fn = _callable(problem.m)
    space = Space(problem.lam, m_fn, _callable(problem.g), tuple(problem.breakpoints))
    c_rel = float(np.asarray(_callable(problem.c)(np.asarray(problem.times)))[0])
    pressure_scale = problem.modulus_after_loading(times) / problem.plane_factor
    m_probe = m_fn(np.linspace(-1.0, 1.0, 257))
    res = Resolution(min(ZONE_PANEL_WIDTH, 3.0 / problem.lam),
                     min(ZONE_EDGE_WIDTH, 0.25 * float(np.min(m_probe))))
    x = plotting_grid(a)
    x_rel = np.clip(x / a, -1.0, 1.0)
    tol = problem.tol
    answers: list[LiftoffAnswer | None] = [None] * len(eccentricities)
    cost = {"zone_solves": 0, "degree": 0, "levels": 0}
    lo, hi = float(min(ends)), float(max(ends))
    for level in range(_MAX_LEVELS):
        cost["levels"] = level + 1
        built: dict[float, _Node] = {}
        disc_ok = True
        for degree in _DEGREES:
            nodes = _lobatto(lo, hi, degree)
            for c in nodes:
                if float(c) not in built:
                    built[float(c)] = _node(space, c_rel, float(c), side, res, x_rel)
                    cost["zone_solves"] += 2
            family = [built[float(c)] for c in nodes]
            cost["degree"] = degree
            disc = max(n.error for n in family)
            e_slope = np.abs(np.diff([n.e for n in family]) / np.diff(nodes))
            end_disc = max(n.e_error for n in family) / max(float(np.min(e_slope)), 1e-300)
            if disc > tol / 3 or end_disc > ZONE_END_TOL / 3:
                disc_ok = False
                break
            e_nodes = np.array([n.e for n in family])
            c_fine = _invert(nodes, e_nodes, eccentricities)
            c_err = np.abs(c_fine - _invert(nodes[::2], e_nodes[::2], eccentricities))
            step = 1e-6 * (hi - lo)
            slope = np.abs(_barycentric(nodes, e_nodes, c_fine + step)
                           - _barycentric(nodes, e_nodes, c_fine - step)) / (2 * step)
            for i in np.flatnonzero(c_err + end_disc <= ZONE_END_TOL / 3):
                if answers[i] is not None:
                    continue
                cost["zone_solves"] += 1
                answers[i] = _solved_point(space, c_rel, float(c_fine[i]), side, res, x, x_rel,
                                           problem, scene, float(forces[i]),
                                           float(eccentricities[i]), float(slope[i]),
                                           end_disc, disc, pressure_scale, outputs, flags)
            if all(answer is not None for answer in answers):
                return answers, cost
        if disc_ok:
            break
        res = res.finer()
    return answers, cost


def _solved_point(space: Space, c_rel: float, end: float, side: int, res: Resolution,
                  x: np.ndarray, x_rel: np.ndarray, problem: Any, scene: Scene, force: float,
                  e: float, slope: float, end_disc: float, disc: float,
                  pressure_scale: np.ndarray, outputs: Sequence[str],
                  flags: Sequence[str]) -> LiftoffAnswer | None:
    """The point of eccentricity ``e`` solved on its zone, whose free end ``end`` the
    family located; None when the zone's own eccentricity misses ``e`` by more than the
    zone-end tolerance (through ``slope`` = de/dc) or the pressure fails the contact
    set's check."""
    ends = [end, 1.0] if side > 0 else [-1.0, end]
    e_zone, settlement, tilt, grid = _unit_zone(space, c_rel, ends, res, 0 if side > 0 else 1,
                                                x_rel)
    miss = abs(e_zone - e) / max(slope, 1e-300)
    if miss + end_disc > ZONE_END_TOL / 3:
        return None
    # the contact set's check, as the one-point solver makes it: q >= 0 on the zone and
    # the gap open off it
    inside = x_rel >= end if side > 0 else x_rel <= end
    scale = _CONTACT_CHECK * max(float(np.max(np.abs(grid[inside]), initial=0.0)), 1e-300)
    if np.any(grid[inside] < -scale) or np.any(grid[~inside] > scale):
        return None
    q = np.where(inside, np.maximum(grid, 0.0), 0.0)
    a = scene.half_width
    zone = (a * end, a) if side > 0 else (-a, a * end)  # as SceneSolution scales its zones
    point = _point_values(problem, a, force, e, settlement, tilt, q, x, zone,
                          pressure_scale, outputs)
    # the discretization's estimate and the change of the outputs over the eccentricity
    # the zone misses (per unit force they move by about their own size over e)
    estimate = disc + abs(e_zone - e) / max(abs(e), 1e-300)
    return _answer(scene, point, force, flags, estimate)


def _dimensionless_force(problem: Any, force: float, a: float) -> float:
    # as core.scene.pipeline.to_dimensionless converts a constant force (the same operations)
    return problem.plane_factor * force / (problem.modulus_at_loading * a)


def _point_values(problem: Any, a: float, force: float, e: float, settlement: float,
                  tilt: float, q: np.ndarray, x: np.ndarray, zone: tuple[float, float],
                  pressure_scale: np.ndarray,
                  outputs: Sequence[str]) -> tuple[np.ndarray, SimpleNamespace]:
    """The outputs of one point (``q`` the pressure per unit force on the grid ``x``,
    ``zone`` its contact zone [m] at every time) as :func:`core.study.point_outputs` takes
    them from a :class:`core.scene.SceneSolution`, and that point's histories."""
    p_star = _dimensionless_force(problem, force, a)
    n = pressure_scale.size
    result = SimpleNamespace(
        contact_width=contact_width([[zone]] * n, a),
        settlement=np.full(n, a * settlement * p_star), tilt=np.full(n, tilt * p_star),
        force=p_star * pressure_scale * a, moment=e * p_star * pressure_scale * a * a,
        x=x, pressure_on_grid=(p_star * q)[:, None] * pressure_scale[None, :])
    return point_outputs(result, outputs), result


def _answer(scene: Scene, point: tuple[np.ndarray, SimpleNamespace], force: float,
            flags: Sequence[str], estimate: float) -> LiftoffAnswer:
    """The point's answer with its flags, as :class:`core.scene.SceneSolution` sets them."""
    from core.coating import tilt_share

    values, result = point
    a = scene.half_width
    point_flags = list(flags)
    share = tilt_share(a, result.settlement, result.tilt)
    # the coating's model is read against this point's zone, as core.scene.SceneSolution
    # reads it
    zone = narrowest_zone([[(-a, -a + float(w))] for w in result.contact_width], a)
    if thick_coating(scene, zone):
        point_flags.append("thick_coating")
    if scene_model_error(scene, share, zone)["estimate"] > scene.model_tol:
        point_flags.append("model_error")
    largest = float(np.max(np.abs(result.tilt)))
    share = strain_share(scene, result.settlement, largest,
                         float(np.nanmax(result.pressure_on_grid, initial=0.0)))
    if share > 1.0:
        point_flags.append("large_settlement")
    if largest > LARGE_TILT:
        point_flags.append("large_tilt")
    order = ("thick_coating", "model_error", "stiff_coating", "large_settlement", "large_tilt")
    point_flags.sort(key=lambda f: order.index(f) if f in order else -1)
    return LiftoffAnswer(force, values, estimate, point_flags, largest, share)


def family_flags(result_flags: Sequence[str]) -> list[str] | None:
    """The geometry's flags of a lift-off answer of :func:`core.scene.solve` that hold for
    every eccentricity of the family, or None when its flags say the one-point solver
    missed its tolerance or its check (the family is then not built)."""
    if {"tol_not_met", "contact_set_unverified", "contact_lost"} & set(result_flags):
        return None
    return [f for f in result_flags
            if f not in ("model_error", "large_settlement", "large_tilt", "thick_coating")]


def family_applies(scene: Scene) -> bool:
    """Whether the modulus is one over the scene's times (the answer per unit force is
    then one at every time)."""
    problem = scene.dimensionless
    times = np.asarray(scene.times, dtype=float)
    modulus = problem.modulus_after_loading(times)
    if not np.all(modulus == problem.modulus_at_loading):
        return False
    c = np.asarray(_callable(problem.c)(np.asarray(problem.times, dtype=float)), dtype=float)
    return bool(np.all(c == c[0]))
