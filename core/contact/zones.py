"""Unilateral contact on Gauss-Legendre panels: the exact zone ends at one time.

The problem at one time and its Nystrom pressure Q are those of :mod:`core.contact.step`.
Two stages: (1) the nodal active set (:mod:`core.contact.active_set`) gives the topology
and ends to within a node; (2) each free end is then located as the root of
``Q(end) = 0`` of the problem solved on the contact set alone, with panels broken at and
graded toward the current end estimates (quasi-Newton on the ends), and checked against
a finer rule (this module).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from core.contact.step import (
    Space,
    Step,
    _bordered_solve,
    _given_rhs,
    _Resultants,
    nystrom_pressure,
)
from core.discretize import (
    NODES_PER_PANEL,
    SHORT_SHARE,
    Panels,
    base_panels,
    kernel_operator,
)
from core.kernel import FULL_ACCURACY
from core.work import check_work

#: Accuracy aimed at for every free zone end [half-widths] (issue 13).
ZONE_END_TOL = 1e-6
#: What a zone solve says it was doing when the solve's work bound stops it (the scene
#: level then names the punch's shape: ``core.scene.pipeline``).
LOCATING_ZONE_ENDS = "locating the ends of"
#: The same, for the ends corrected at each time step of a march under creep.
CORRECTING_ZONE_ENDS = "correcting the ends of"
#: Quasi-Newton iterations on the zone ends per resolution level.
MAX_END_ITERATIONS = 25
#: The last quasi-Newton step on the ends is not made when it would move them by less
#: than this share of the tighter of ``ZONE_END_TOL`` and tol: its length is added to the
#: end-error estimate instead. The outputs move by ~q(end) times that step, second order
#: in it (q vanishes at a free end). After the first step from the nodal estimate the
#: next one is 3e-8 to 4e-7 half-widths on the eccentric footing (measured): at the
#: scenes' tol (>= 1e-6) a solve saved on most load changes, the estimate still within
#: a third of the tolerance; a tighter tol (the references of the work-precision
#: benchmarks) still converges the ends to it.
SKIP_END_STEP = 0.1
#: Resolution levels of the zone-end refinement (panel width and end grading shrink).
#: Since the estimate compares q too, whose largest change between rules sits at the
#: finer rule's node nearest the punch's edge and falls ~14x a level, 4 levels stopped
#: it at 8.4e-10 (e = 0.45 a, m = 0.05: every tol <= 1e-9 refused, 720 nodes); with 6,
#: tol 1e-9 is met on 1216 nodes (0.2 s) and 1e-10 on 2176 (0.7 s). A looser tol stops
#: at its first levels as before.
MAX_LEVELS = 6
#: Panels of the nodal active set (at most ``NODAL_PANEL_WIDTH`` wide: it must see every
#: zone) and of the first refinement level (at most ``ZONE_PANEL_WIDTH``), graded to at
#: most ``ZONE_EDGE_WIDTH`` at +-1, breakpoints and zone ends (finer when the coating is
#: thinner: its boundary layer is ~m wide). Measured on four lift-off cases: the first
#: level already meets 1e-6 for the ends (estimates 1e-10 to 6e-9); tighter tol refines
#: further. The study's family of lift-off points (core/study/liftoff.py) starts from the
#: same rule.
NODAL_PANEL_WIDTH = 0.25
ZONE_PANEL_WIDTH = 0.5
ZONE_EDGE_WIDTH = 1e-2
#: Floor of the outputs' error estimate [-, relative]: the rounding of a zone's solves.
#: Settled answers (tol 1e-10 against 1e-12, a centred force with e = 0.4-0.999 a,
#: m = 0.01-0.2) differ by ~1e-14, but by up to 2.3e-12 where the zone is narrower than
#: its panels (e = 0.99 a: 0.03 half-widths), where the rules' difference and the moved
#: ends read 2.6e-13-3.9e-12 depending on the BLAS and numpy at hand; the floor keeps the
#: estimate at that rounding (tests/contact/test_tiny_zone_estimate.py).
ZONE_ROUNDING = 3e-12


@dataclass(frozen=True)
class Resolution:
    """A panel rule for the refined problem: panels at most ``width`` wide, graded to
    ``edge`` at +-1, at the breakpoints and at every zone end; on a stretch between two
    of these narrower than ``edge / short``, to ``short`` times its length
    (:func:`~core.discretize.base_panels`).

    ``short`` moves with ``edge`` from rule to rule: a zone narrower than 8 edges (at
    e = 0.99 a, or a crest of a wavy punch) is graded to its own eighth on the first rule,
    and each finer rule is finer on it too. With a fixed share the rules whose difference
    is the estimate held the same panels there: a zone 0.019 half-widths wide pinned at a
    coating step read 3e-12 while q was 9.5e-9 off (tol 1e-10).
    """

    width: float
    edge: float
    short: float = SHORT_SHARE

    def finer(self) -> Resolution:
        return Resolution(self.width / 2.0, self.edge / 4.0, self.short / 4.0)

    def coarser(self) -> Resolution:
        return Resolution(min(2.0 * self.width, 1.0), 4.0 * self.edge,
                          min(4.0 * self.short, 1.0))


def subset(panels: Panels, keep: np.ndarray) -> Panels:
    """The panels flagged in ``keep`` (one flag per panel) as a rule of their own.

    The kept panels need not touch; only nodes, weights, centres and half-widths are used
    by the operator, and ``edges`` holds the (lower, upper) ends of each kept panel.
    """
    keep = np.asarray(keep, dtype=bool)
    node_keep = np.repeat(keep, NODES_PER_PANEL)
    lo = panels.centers[keep] - panels.half_widths[keep]
    hi = panels.centers[keep] + panels.half_widths[keep]
    return Panels(np.column_stack([lo, hi]).ravel(), panels.nodes[node_keep],
                  panels.weights[node_keep], panels.centers[keep], panels.half_widths[keep])


@dataclass
class ZoneSolution(_Resultants):
    """The problem solved on given zones: the rule on the contact set, nodal q, the
    scalars, and Q (the Nystrom pressure) at every end."""

    ends: list[float]
    panels: Panels
    q: np.ndarray
    settlement: float
    tilt: float
    end_values: np.ndarray
    q_scale: float


def zone_panels(space: Space, ends: Sequence[float], res: Resolution) -> Panels:
    """Panels covering the zones ``(ends[0], ends[1]), (ends[2], ends[3]), ...``."""
    cuts = sorted({round(float(e), 15) for e in ends if -1.0 < e < 1.0}
                  | set(space.breakpoints))
    merged = [c for k, c in enumerate(cuts) if k == 0 or c - cuts[k - 1] > 1e-12]
    panels = base_panels(space.lam, merged, edge_width=res.edge, max_width=res.width,
                         short_share=res.short)
    lo, hi = np.array(ends[0::2]), np.array(ends[1::2])
    c = panels.centers
    keep = np.any((c[:, None] > lo[None, :]) & (c[:, None] < hi[None, :]), axis=1)
    return subset(panels, keep)


def solve_on_zones(space: Space, step: Step, ends: Sequence[float],
                   res: Resolution, probes: np.ndarray | None = None,
                   accuracy: float = FULL_ACCURACY
                   ) -> tuple[ZoneSolution, np.ndarray] | ZoneSolution:
    """Solve the equation on the zones given by ``ends`` (full contact there).

    With ``probes`` (points of the zones, x) returns the solution and Q there too: one
    evaluation of the operator's rows serves the ends and the probes. ``accuracy``:
    absolute accuracy of the kernel values in the operator (default: rounding).
    """
    # each solve is dense in every zone's nodes (a wavy punch touching at 47 crests: 3000
    # to 5800 nodes, 0.4-3 s a solve): the solve's work bound is checked before each
    check_work(f"{LOCATING_ZONE_ENDS} {len(ends) // 2} contact zone(s)")
    panels = zone_panels(space, ends, res)
    x = panels.nodes
    op = kernel_operator(space.lam, panels, accuracy=accuracy).matrix
    m = space.m(x)
    g = space.g(x)
    rhs = _given_rhs(step, x, g, None)
    idx = np.arange(x.size)
    q, delta, alpha = _bordered_solve(op, m, x, panels.weights, step, rhs, idx)
    ends_arr = np.asarray(ends, dtype=float)
    inward = np.tile([1.0, -1.0], len(ends) // 2)
    extra = np.zeros(0) if probes is None else np.asarray(probes, dtype=float)
    # probes lie inside the zones: sampled where they are (no jump to step across)
    values = nystrom_pressure(space, step, panels, q, delta, alpha,
                              np.concatenate([ends_arr, extra]),
                              np.concatenate([inward, np.zeros(extra.size)]))
    sol = ZoneSolution(list(ends), panels, q, delta, alpha, values[:ends_arr.size],
                       max(float(np.max(np.abs(q))), 1e-300))
    return sol if probes is None else (sol, values[ends_arr.size:])


def zone_kernel_accuracy(tol: float) -> float:
    """Absolute accuracy of the kernel values in the zone operators for ``tol``."""
    return max(FULL_ACCURACY, 1e-4 * min(tol, ZONE_END_TOL))


@dataclass
class Refined:
    """Result of :func:`refine_zone_ends`: the final solution, the estimated error of the
    ends [half-widths] and of the outputs (relative), and what the refinement did."""

    solution: ZoneSolution
    end_error: float
    output_error: float
    builds: int
    levels: int
    converged: bool


def _walls(ends: list[float], pinned: list[bool], k: int) -> tuple[float, float]:
    lo = -1.0 if k == 0 else ends[k - 1]
    hi = 1.0 if k == len(ends) - 1 else ends[k + 1]
    return lo, hi


def output_error(sol: ZoneSolution, fine: ZoneSolution) -> float:
    """The change of delta, alpha (relative to the larger of them) and P, M (to the larger
    of them) from the coarser rule's ``fine`` to ``sol``: the estimate of the outputs."""
    kin = max(abs(sol.settlement), abs(sol.tilt), 1e-300)
    dyn = max(abs(sol.force), abs(sol.moment), 1e-300)
    return max(abs(sol.settlement - fine.settlement) / kin,
               abs(sol.tilt - fine.tilt) / kin,
               abs(sol.force - fine.force) / dyn,
               abs(sol.moment - fine.moment) / dyn)


def pressure_error(space: Space, step: Step, sol: ZoneSolution, fine: ZoneSolution,
                   accuracy: float,
                   memory_at: Callable[[np.ndarray], np.ndarray] | None = None) -> float:
    """The change of q from the coarser rule's ``fine`` to ``sol`` at the nodes of ``sol``
    (``fine``'s Nystrom pressure there), relative to the largest q of ``sol``: the four
    outputs are integrals of q and miss a local error of it (a rough punch, 15 waves on
    the base: q off by 4.5e-3 on 288 nodes where they changed by 2e-8). ``memory_at``:
    the displacement the rest of the base adds (:func:`nystrom_pressure`)."""
    if sol.q.size == 0:
        return 0.0
    coarse = nystrom_pressure(space, step, fine.panels, fine.q, fine.settlement, fine.tilt,
                              sol.panels.nodes, memory_at=memory_at, accuracy=accuracy)
    return float(np.max(np.abs(sol.q - coarse))) / sol.q_scale


class OnePunch:
    """The zone ends of one punch at one time, as :func:`refine_ends` asks for them.

    An end problem answers ``solve(ends, res, probes)`` (a solution whose ``end_values``
    hold Q at the ends, and Q at ``probes``), ``scale(sol)`` (the q that makes Q at the
    ends relative: a number, or one per end), ``walls(ends, k)`` (how far end ``k`` may
    move), ``edge(res)`` (the end grading of ``res``: a number, or one per end) and
    ``output_error(sol, fine)``, ``moved_error(moved, sol)`` (the same for a solution
    whose end moved by its error, added to the estimate) and ``needs_moved(error,
    end_error)`` (whether to measure that); ``res`` has ``finer()`` and
    ``coarser()``. Several punches on one base answer the same questions for all their
    ends at once (:mod:`core.contact.coupled`).
    """

    def __init__(self, space: Space, step: Step, accuracy: float) -> None:
        self.space, self.step, self.accuracy = space, step, accuracy

    def solve(self, ends: Sequence[float], res: Resolution, probes: np.ndarray | None = None
              ) -> tuple[ZoneSolution, np.ndarray] | ZoneSolution:
        return solve_on_zones(self.space, self.step, ends, res, probes=probes,
                              accuracy=self.accuracy)

    @staticmethod
    def scale(sol: ZoneSolution) -> float:
        return sol.q_scale

    @staticmethod
    def walls(ends: list[float], k: int) -> tuple[float, float]:
        return _walls(ends, [], k)

    @staticmethod
    def edge(res: Resolution) -> float:
        return res.edge

    def output_error(self, sol: ZoneSolution, fine: ZoneSolution) -> float:
        """The outputs' and q's change between the rules (:func:`output_error`,
        :func:`pressure_error`)."""
        return max(output_error(sol, fine),
                   pressure_error(self.space, self.step, sol, fine, self.accuracy))

    @staticmethod
    def moved_error(moved: ZoneSolution, sol: ZoneSolution) -> float:
        """The outputs' change when an end moves by its error (added to the estimate)."""
        return output_error(moved, sol)

    @staticmethod
    def needs_moved(error: float, end_error: float) -> bool:
        """Whether the ends' part of the outputs' error is to be measured by moving them
        (:func:`_moved_ends_error`): where the rules' difference ``error`` reads less than
        the ends' own error (a heuristic across units: the rules may then not differ on
        the zone at all; it measured below it only where the zone was narrower than its
        panels, e = 0.99 a, among e = 0.3-0.99 a and tol 1e-4-1e-8)."""
        return error < end_error < np.inf


def refine_zone_ends(space: Space, step: Step, ends: list[float], pinned: list[bool],
                     slopes: list[float], res: Resolution, *, tol: float,
                     max_levels: int = MAX_LEVELS) -> Refined:
    """Locate every free end as the root of ``Q(end) = 0`` and estimate the error
    (:func:`refine_ends` for one punch)."""
    # Kernel values to 1e-4 of the tighter of tol and the zone-end tolerance: F q then
    # errs by that times int |q|, far below both; the truncated series and the zeros of
    # the decayed kernel save ~6 % of an elastic lift-off solve (12.9 -> 12.1 ms CPU,
    # measured; the ends moved by 6e-14 at tol 1e-6).
    problem = OnePunch(space, step, zone_kernel_accuracy(tol))
    return refine_ends(problem, ends, pinned, slopes, res, tol=tol, max_levels=max_levels)


def refine_ends(problem: Any, ends: list[float], pinned: list[bool], slopes: list[float],
                res: Any, *, tol: float, max_levels: int = MAX_LEVELS) -> Refined:
    """Locate every free end as the root of ``Q(end) = 0`` and estimate the error.

    ``problem``: the end problem (:class:`OnePunch` says what it answers), ``res`` its
    resolution. Quasi-Newton (Broyden) on the free ends, starting from the Jacobian
    ``diag(dQ/dx)`` of the nodal estimate. At each resolution the converged ends are
    compared with the next coarser rule (the shift ``-J^-1 dQ`` it would give them, and
    the change of the outputs): that difference is the error estimate, an overestimate by
    the convergence ratio of a level (measured ~16 for the ends), and a coarser check
    costs a quarter of a finer one. The resolution is refined until both meet
    ``ZONE_END_TOL`` and ``tol`` (a third of each), at most ``max_levels`` times.
    """
    ends = list(ends)
    pinned = list(pinned)
    free = [k for k, p in enumerate(pinned) if not p]
    builds = 0
    # The nodal Q is in units of q; the residual is Q / max q.
    inward = np.array([1.0 if k % 2 == 0 else -1.0 for k in free])
    ends_free = np.array([ends[k] for k in free])
    probe = ends_free + inward * 1e-3 * _at(problem.edge(res), free)
    sol, q_in = problem.solve(ends, res, probes=probe)
    builds += 1
    scale = _at(problem.scale(sol), free)
    jac = np.diag([s / sc if s != 0.0 else 1.0 for s, sc in
                   zip((slopes[k] for k in free), np.broadcast_to(scale, (len(free),)),
                       strict=True)]) if free else np.zeros((0, 0))
    if free:
        # Near the root, moving an end changes the answer little (q vanishes there), so
        # dQ(end)/d(end) is about the slope of Q in x at the end: taken from this solution
        # (a step into the zone) it beats the nodal difference, and the first quasi-Newton
        # step lands far closer (one solve fewer, measured).
        slope = (q_in - sol.end_values[free]) / (probe - ends_free) / scale
        if np.all(np.isfinite(slope)) and np.all(slope * inward > 0.0):
            jac = np.diag(slope)
    converged = not free
    unmade = 0.0  # the step the root-find judged too small to make (added to the estimate)
    end_error = output_error = np.inf
    level = 0
    for _ in range(max_levels):
        level += 1
        if free:
            r = sol.end_values[free] / _at(problem.scale(sol), free)
            converged = False
            unmade = 0.0
            for _ in range(MAX_END_ITERATIONS):
                if np.max(np.abs(r)) < 1e-15:
                    converged = True  # at the root to rounding: no step can improve it
                    break
                try:
                    move = -np.linalg.solve(jac, r)
                except np.linalg.LinAlgError:
                    move = -r / np.maximum(np.abs(np.diag(jac)), 1e-300)
                # Never jump past a neighbouring end or more than a tenth of a half-width.
                move = np.clip(move, -0.1, 0.1)
                trial = list(ends)
                for j, k in enumerate(free):
                    # At most 90% of the way to a neighbouring end or +-1: an end close to
                    # the punch's edge is approached geometrically (a fixed margin of
                    # 1e-3 of the span held it 2e-3 away, just past the lift-off
                    # threshold).
                    lo, hi = problem.walls(ends, k)
                    trial[k] = float(np.clip(ends[k] + move[j], ends[k] - 0.9 * (ends[k] - lo),
                                             ends[k] + 0.9 * (hi - ends[k])))
                new = problem.solve(trial, res)
                builds += 1
                r_new = new.end_values[free] / _at(problem.scale(new), free)
                ds = np.array([trial[k] - ends[k] for k in free])
                if np.dot(ds, ds) > 0.0:
                    jac = jac + np.outer(r_new - r - jac @ ds, ds) / np.dot(ds, ds)
                ends, sol, r = trial, new, r_new
                if np.max(np.abs(ds)) < 1e-2 * ZONE_END_TOL:
                    converged = True
                    break
                # The step the updated Jacobian would take next: when it is already far
                # below the tolerance the solve it needs is not made (one build saved).
                try:
                    ahead = float(np.max(np.abs(np.linalg.solve(jac, r))))
                except np.linalg.LinAlgError:
                    ahead = np.inf
                if ahead < SKIP_END_STEP * min(ZONE_END_TOL, tol):
                    converged = True
                    unmade = ahead
                    break
        fine = problem.solve(ends, res.coarser())
        builds += 1
        if free:
            r_fine = fine.end_values[free] / _at(problem.scale(fine), free)
            try:
                shift = -np.linalg.solve(jac, r_fine)
            except np.linalg.LinAlgError:
                shift = np.full(len(free), np.inf)
            end_error = float(np.max(np.abs(shift))) + unmade
        else:
            end_error = 0.0
        output_error = problem.output_error(sol, fine)
        if end_error <= ZONE_END_TOL / 3 and output_error <= tol / 3:
            break
        if level == max_levels:
            break
        res = res.finer()
        sol = problem.solve(ends, res)
        builds += 1
    if free and problem.needs_moved(output_error, end_error):
        moved, made = _moved_ends_error(problem, sol, ends, free, inward, end_error, res,
                                         tol)
        output_error += moved
        builds += made
    output_error = max(output_error, ZONE_ROUNDING)
    return Refined(sol, end_error, output_error, builds, level, converged)


def _moved_ends_error(problem: Any, sol: Any, ends: list[float], free: list[int],
                      inward: np.ndarray, end_error: float, res: Any,
                      tol: float) -> tuple[float, int]:
    """The change of the outputs when each free end moves by its estimated error (into
    the zone), summed over the ends: the part of the outputs' error the ends make; and
    the solves it took.

    The rules' difference misses it where a zone is narrower than its panels (both rules
    then hold the same panels there): at e = 0.999 a, a zone 0.003 wide, the estimate read
    0.0 while the settlement was 1.2e-9 off (its end 1.6e-8).

    Each end costs a solve of the whole problem. With more than :data:`MOVED_SAMPLE`
    free ends, the ends of the narrowest zones and the outermost ends are moved first:
    when their largest change times :data:`MOVED_SAFETY` times the number of free ends is
    below :data:`MOVED_NEGLIGIBLE` of ``tol``, that bound stands for the sum; otherwise
    every end is moved. A wavy punch touching at 37 crests (73 free ends) took 31 s for the
    sum, 1.8e-11 at tol 1e-3 (each end 7e-14 to 4.8e-13, the largest at the outermost
    zones); the bound reads 7.0e-11 from 4 solves."""
    def change(j: int) -> float:
        k = free[j]
        lo, hi = problem.walls(ends, k)
        moved = list(ends)
        moved[k] = float(np.clip(ends[k] + inward[j] * end_error,
                                 ends[k] - 0.5 * (ends[k] - lo), ends[k] + 0.5 * (hi - ends[k])))
        return float(problem.moved_error(problem.solve(moved, res), sol))

    if len(free) > MOVED_SAMPLE:
        widths = [ends[k + 1] - ends[k] if k % 2 == 0 else ends[k] - ends[k - 1]
                  for k in free]
        order = [0, len(free) - 1] + [int(j) for j in np.argsort(widths, kind="stable")]
        sample = list(dict.fromkeys(order))[:MOVED_SAMPLE]
        changes = {j: change(j) for j in sample}
        bound = MOVED_SAFETY * len(free) * max(changes.values())
        if bound <= MOVED_NEGLIGIBLE * tol:
            return bound, len(sample)
        rest = sum(change(j) for j in range(len(free)) if j not in changes)
        return sum(changes.values()) + rest, len(free)
    return sum(change(j) for j in range(len(free))), len(free)


#: Free ends up to which :func:`_moved_ends_error` moves every one; beyond, first a
#: sample of this many (the ends of the narrowest zones and the outermost ends).
MOVED_SAMPLE = 4
#: The sample's largest change times this and the number of free ends bounds their sum
#: (measured on the wavy punch's 73 ends: the sample held the largest, and the sum was
#: 50 % of the number of ends times it).
MOVED_SAFETY = 2.0
#: ... where that bound is below this share of tol, else every end is moved.
MOVED_NEGLIGIBLE = 0.01


def _at(values: float | np.ndarray, free: list[int]) -> float | np.ndarray:
    """A number as it stands, or the entries of the free ends of one value per end."""
    return values if np.ndim(values) == 0 else np.asarray(values)[free]
