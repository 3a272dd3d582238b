"""Unilateral contact on Gauss-Legendre panels: the nodal active set and exact zone ends.

At one time the unilateral problem (model notes, dimensionless) reads: find ``q >= 0`` and
the contact set ``S`` with

    c m q + s F q = delta + alpha x - g + e(x)   on S   (q > 0: the surfaces touch)
    h(x) = s F q - (delta + alpha x - g + e(x)) >= 0   off S   (q = 0: the gap is open)

and the two given ones of ``delta, alpha, P = int q, M = int x q``. ``s`` weighs the current
pressure (1 elastic; ``1 - K(t, t) dt/2`` in an implicit creep step) and ``e(x)`` is the
displacement of the creep memory (0 elastic). Both conditions are one continuous function,
the *Nystrom pressure*

    Q(x) = [delta + alpha x - g(x) + e(x) - s F q (x)] / (c m(x)),

which equals ``q`` on S and ``-h / (c m)`` off it: S is where ``Q > 0``, and at a free end
of a zone ``Q`` passes through zero (``q`` is continuous and vanishes there: ``h >= 0`` just
outside forces ``q(end) <= 0``, ``q >= 0`` just inside forces ``>= 0``).

Two stages: (1) a primal-dual active set on the nodes of a fixed panel rule (each sweep
makes the contact nodes those with ``Q > 0``; it stops when the set repeats) gives the
topology and ends to within a node; (2) each free end is then located as the root of
``Q(end) = 0`` of the problem solved on the contact set alone, with panels broken at and
graded toward the current end estimates (quasi-Newton on the ends), and checked against
a finer rule.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.polynomial import legendre as npleg

from core.contact_systems import StepSolver, bordered_solve
from core.kernel_values import FULL_ACCURACY
from core.quadrature import NODES_PER_PANEL, Panels, base_panels, kernel_operator, operator_rows

#: Accuracy aimed at for every free zone end [half-widths] (issue 13).
ZONE_END_TOL = 1e-6
#: Sweeps of the nodal active set before it is declared cycling.
MAX_SWEEPS = 60
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
MAX_LEVELS = 4

_T, _W = npleg.leggauss(NODES_PER_PANEL)
# Barycentric weights of the Gauss-Legendre nodes: (-1)^j sqrt((1 - t_j^2) w_j).
_BARYCENTRIC = (-1.0) ** np.arange(NODES_PER_PANEL) * np.sqrt((1.0 - _T**2) * _W)


@dataclass(frozen=True)
class Space:
    """The scene's functions of x: ``lam`` = a/H, coating compliance ``m`` and gap ``g``
    (vectorized callables on [-1, 1]), and ``breakpoints`` where m or g may jump."""

    lam: float
    m: Callable[[np.ndarray], np.ndarray]
    g: Callable[[np.ndarray], np.ndarray]
    breakpoints: tuple[float, ...]


@dataclass(frozen=True)
class Step:
    """One time's data: relative modulus ``c``, weight ``scale`` of F on the current
    pressure, and the two given ones of settlement, tilt, force, moment (dimensionless)."""

    c: float
    scale: float
    given: dict[str, float]


class _Resultants:
    """Force and moment (dimensionless) of a nodal pressure ``q`` on ``panels``."""

    panels: Panels
    q: np.ndarray

    @property
    def force(self) -> float:
        return float(self.panels.weights @ self.q)

    @property
    def moment(self) -> float:
        return float((self.panels.weights * self.panels.nodes) @ self.q)


@dataclass
class NodalState(_Resultants):
    """A solution on the nodes of ``panels``: pressure ``q`` (0 off contact), the four
    scalars, the contact nodes ``active`` and the Nystrom pressure ``nystrom`` (Q)."""

    panels: Panels
    q: np.ndarray
    settlement: float
    tilt: float
    active: np.ndarray
    nystrom: np.ndarray


class NoContact(ValueError):
    """The loads leave no contact (the punch is pulled away)."""


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


def _bordered_solve(op: np.ndarray, m: np.ndarray, x: np.ndarray, w: np.ndarray, step: Step,
                    rhs: np.ndarray, idx: np.ndarray,
                    solver: StepSolver | None = None) -> tuple[np.ndarray, float, float]:
    """:func:`core.contact_systems.bordered_solve` for one :class:`Step`."""
    return bordered_solve(op, m, x, w, step.c, step.scale, step.given, rhs, idx, solver)


def _given_rhs(step: Step, x: np.ndarray, g: np.ndarray, memory: np.ndarray | None) -> np.ndarray:
    rhs = step.given.get("settlement", 0.0) + step.given.get("tilt", 0.0) * x - g
    return rhs if memory is None else rhs + memory


def nodal_active_set(panels: Panels, op: np.ndarray, m: np.ndarray, g: np.ndarray, step: Step,
                     memory: np.ndarray | None = None, start: np.ndarray | None = None,
                     solver: StepSolver | None = None) -> tuple[NodalState, int, bool]:
    """Primal-dual active set on the nodes of ``panels``.

    ``op`` is the Nystrom matrix of F there, ``m``, ``g`` and ``memory`` (e(x)) the node
    values; ``start`` the first guess of the contact nodes (default: all). Returns the
    state, the number of sweeps and whether the set settled (it may cycle between two
    sets on a degenerate node; the last one is kept). Raises :class:`NoContact` when
    no node stays in contact under a given force or moment.
    """
    x, w = panels.nodes, panels.weights
    rhs = _given_rhs(step, x, g, memory)
    active = np.ones(x.size, dtype=bool) if start is None else start.copy()
    seen: set[bytes] = set()
    settled = False
    sweeps = 0
    q = np.zeros(x.size)
    delta = step.given.get("settlement", 0.0)
    alpha = step.given.get("tilt", 0.0)
    for _ in range(MAX_SWEEPS):
        sweeps += 1
        idx = np.nonzero(active)[0]
        q = np.zeros(x.size)
        if idx.size == 0:
            if {"force", "moment"} & set(step.given) and any(
                    step.given.get(k, 0.0) != 0.0 for k in ("force", "moment")):
                raise NoContact("no node stays in contact")
        elif idx.size < 3 and not {"settlement", "tilt"} <= set(step.given):
            raise NoContact("the contact shrinks to a point")
        else:
            q[idx], delta, alpha = _bordered_solve(op, m, x, w, step, rhs, idx, solver)
        nystrom = (delta + alpha * x - g + (0.0 if memory is None else memory)
                   - step.scale * (op @ q)) / (step.c * m)
        # Keep the contact nodes the equation solved exactly (rounding must not flip them).
        nystrom[idx] = q[idx]
        new = nystrom > 0.0
        key = new.tobytes()
        if np.array_equal(new, active):
            settled = True
            break
        if key in seen:
            break
        seen.add(active.tobytes())
        active = new
    return NodalState(panels, q, delta, alpha, active, nystrom), sweeps, settled


def _crossing(panels: Panels, values: np.ndarray, i: int) -> float:
    """Where the nodal function ``values`` changes sign between nodes i and i + 1."""
    x = panels.nodes
    p, p1 = i // NODES_PER_PANEL, (i + 1) // NODES_PER_PANEL
    fa, fb = float(values[i]), float(values[i + 1])
    linear = float(x[i] - fa * (x[i + 1] - x[i]) / (fb - fa)) if fb != fa else float(x[i])
    if p != p1:
        return linear
    c, h = panels.centers[p], panels.half_widths[p]
    local = values[p * NODES_PER_PANEL:(p + 1) * NODES_PER_PANEL]

    def f(xx: float) -> float:
        # barycentric form of the panel's interpolant: O(16), stable (Gauss nodes)
        d = (xx - c) / h - _T
        hit = np.nonzero(d == 0.0)[0]
        if hit.size:
            return float(local[hit[0]])
        ratio = _BARYCENTRIC / d
        return float(ratio @ local / ratio.sum())

    # the interpolant takes the nodal values at the nodes
    if fa == 0.0:
        return float(x[i])
    if fa * fb > 0.0:
        return linear
    return _root_between(f, float(x[i]), float(x[i + 1]), fa, fb)


#: Step of the zone-end root below which the secant has converged (half-widths).
_ROOT_XTOL = 1e-14


def _root_between(f: Callable[[float], float], a: float, b: float, fa: float, fb: float
                  ) -> float:
    """The root of ``f`` in ``[a, b]`` (``fa``, ``fb`` of opposite signs): secant steps
    from the ends, kept inside the bracket (a bisection where one leaves it), until the
    next step would be below ``_ROOT_XTOL``. Between two nodes the interpolant is smooth
    and its root simple: 3-4 evaluations on the lift-off preset, where brentq (closing its
    bracket to the same tolerance) took ~6 and its wrapper's checks."""
    x0, f0, x1, f1 = a, fa, b, fb
    for _ in range(100):
        x = x1 - f1 * (x1 - x0) / (f1 - f0) if f1 != f0 else 0.5 * (a + b)
        if not a < x < b:
            x = 0.5 * (a + b)
        fx = f(x)
        if fx == 0.0:
            return x
        if (fx > 0.0) == (fa > 0.0):
            a, fa = x, fx
        else:
            b, fb = x, fx
        # converged when the next secant step would be below the tolerance
        if b - a <= _ROOT_XTOL or (fx != f1 and abs(fx * (x - x1) / (fx - f1)) <= _ROOT_XTOL):
            return x
        x0, f0, x1, f1 = x1, f1, x, fx
    return 0.5 * (a + b)


def zones_from_nodes(state: NodalState, breakpoints: Sequence[float] = ()
                     ) -> tuple[list[float], list[bool], list[float]]:
    """Zone ends from the nodal contact set: (ends, pinned flags, slopes of Q at the ends).

    ``ends`` is sorted, two per zone; an end at a node next to x = -1 or 1 is pinned there,
    and one whose sign change of Q straddles a breakpoint is pinned at the breakpoint (a
    step of the punch: the zone ends at its corner, where Q jumps and has no root).
    """
    cuts = [float(b) for b in sorted(breakpoints)]
    active = state.active
    x = state.panels.nodes
    n = x.size
    ends: list[float] = []
    pinned: list[bool] = []
    slopes: list[float] = []
    # the runs of contact nodes, found at once (a loop over the nodes cost ~0.1 ms per
    # call, paid at every output time of a creep march)
    flips = np.flatnonzero(np.diff(np.concatenate([[0], active.astype(np.int8), [0]])))
    for i, j in zip(flips[0::2], flips[1::2] - 1, strict=True):
        i, j = int(i), int(j)
        for k, side in ((i, -1), (j, 1)):
            if (k == 0 and side < 0) or (k == n - 1 and side > 0):
                ends.append(float(side))
                pinned.append(True)
                slopes.append(0.0)
                continue
            lo = k - 1 if side < 0 else k
            x_lo, x_hi = float(x[lo]), float(x[lo + 1])
            inside = [cut for cut in cuts if x_lo < cut < x_hi]
            if inside:
                ends.append(inside[0])
                pinned.append(True)
                slopes.append(0.0)
                continue
            end = _crossing(state.panels, state.nystrom, lo)
            ends.append(end)
            pinned.append(False)
            slopes.append(float(state.nystrom[lo + 1] - state.nystrom[lo]) / (x_hi - x_lo))
    return ends, pinned, slopes


@dataclass(frozen=True)
class Resolution:
    """A panel rule for the refined problem: panels at most ``width`` wide, graded to
    ``edge`` at +-1, at the breakpoints and at every zone end."""

    width: float
    edge: float

    def finer(self) -> Resolution:
        return Resolution(self.width / 2.0, self.edge / 4.0)

    def coarser(self) -> Resolution:
        return Resolution(min(2.0 * self.width, 1.0), 4.0 * self.edge)


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
    panels = base_panels(space.lam, merged, edge_width=res.edge, max_width=res.width)
    lo, hi = np.array(ends[0::2]), np.array(ends[1::2])
    c = panels.centers
    keep = np.any((c[:, None] > lo[None, :]) & (c[:, None] < hi[None, :]), axis=1)
    return subset(panels, keep)


def nystrom_pressure(space: Space, step: Step, panels: Panels, q: np.ndarray, delta: float,
                     alpha: float, targets: np.ndarray, inward: np.ndarray | None = None,
                     memory_at: Callable[[np.ndarray], np.ndarray] | None = None,
                     accuracy: float = FULL_ACCURACY) -> np.ndarray:
    """Q at ``targets`` for the nodal pressure ``q`` on ``panels`` (see the module notes).

    ``inward`` (+-1 per target) says from which side m and g are sampled at a jump;
    ``accuracy`` is the absolute accuracy of the kernel values (default: rounding).
    """
    targets = np.asarray(targets, dtype=float)
    side = targets if inward is None else np.clip(targets + 1e-13 * inward, -1.0, 1.0)
    fq = operator_rows(space.lam, panels, targets, accuracy=accuracy) @ q
    memory = 0.0 if memory_at is None else memory_at(targets)
    return (delta + alpha * targets - space.g(side) + memory - step.scale * fq) / (
        step.c * space.m(side))


def solve_on_zones(space: Space, step: Step, ends: Sequence[float],
                   res: Resolution, probes: np.ndarray | None = None,
                   accuracy: float = FULL_ACCURACY
                   ) -> tuple[ZoneSolution, np.ndarray] | ZoneSolution:
    """Solve the equation on the zones given by ``ends`` (full contact there).

    With ``probes`` (points of the zones, x) returns the solution and Q there too: one
    evaluation of the operator's rows serves the ends and the probes. ``accuracy``:
    absolute accuracy of the kernel values in the operator (default: rounding).
    """
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


def refine_zone_ends(space: Space, step: Step, ends: list[float], pinned: list[bool],
                     slopes: list[float], res: Resolution, *, tol: float,
                     max_levels: int = MAX_LEVELS) -> Refined:
    """Locate every free end as the root of ``Q(end) = 0`` and estimate the error.

    Quasi-Newton (Broyden) on the free ends, starting from the Jacobian ``diag(dQ/dx)``
    of the nodal estimate. At each resolution the converged ends are compared with the
    next coarser rule (the shift ``-J^-1 dQ`` it would give them, and the change of the
    outputs): that difference is the error estimate, an overestimate by the convergence
    ratio of a level (measured ~16 for the ends), and a coarser check costs a quarter of
    a finer one. The resolution is refined until both meet ``ZONE_END_TOL`` and ``tol``
    (a third of each), at most ``max_levels`` times.
    """
    ends = list(ends)
    pinned = list(pinned)
    free = [k for k, p in enumerate(pinned) if not p]
    # Kernel values to 1e-4 of the tighter of tol and the zone-end tolerance: F q then
    # errs by that times int |q|, far below both; the truncated series and the zeros of
    # the decayed kernel save ~6 % of an elastic lift-off solve (12.9 -> 12.1 ms CPU,
    # measured; the ends moved by 6e-14 at tol 1e-6).
    accuracy = zone_kernel_accuracy(tol)
    builds = 0
    # The nodal Q is in units of q; the residual is Q / max q.
    inward = np.array([1.0 if k % 2 == 0 else -1.0 for k in free])
    ends_free = np.array([ends[k] for k in free])
    probe = ends_free + inward * 1e-3 * res.edge
    sol, q_in = solve_on_zones(space, step, ends, res, probes=probe, accuracy=accuracy)
    builds += 1
    jac = np.diag([s / sol.q_scale if s != 0.0 else 1.0 for s in
                   (slopes[k] for k in free)]) if free else np.zeros((0, 0))
    if free:
        # Near the root, moving an end changes the answer little (q vanishes there), so
        # dQ(end)/d(end) is about the slope of Q in x at the end: taken from this solution
        # (a step into the zone) it beats the nodal difference, and the first quasi-Newton
        # step lands far closer (one solve fewer, measured).
        slope = (q_in - sol.end_values[free]) / (probe - ends_free) / sol.q_scale
        if np.all(np.isfinite(slope)) and np.all(slope * inward > 0.0):
            jac = np.diag(slope)
    converged = not free
    unmade = 0.0  # the step the root-find judged too small to make (added to the estimate)
    end_error = output_error = np.inf
    level = 0
    for _ in range(max_levels):
        level += 1
        if free:
            r = sol.end_values[free] / sol.q_scale
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
                    lo, hi = _walls(ends, pinned, k)
                    trial[k] = float(np.clip(ends[k] + move[j], ends[k] - 0.9 * (ends[k] - lo),
                                             ends[k] + 0.9 * (hi - ends[k])))
                new = solve_on_zones(space, step, trial, res, accuracy=accuracy)
                builds += 1
                r_new = new.end_values[free] / new.q_scale
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
        fine = solve_on_zones(space, step, ends, res.coarser(), accuracy=accuracy)
        builds += 1
        if free:
            r_fine = fine.end_values[free] / fine.q_scale
            try:
                shift = -np.linalg.solve(jac, r_fine)
            except np.linalg.LinAlgError:
                shift = np.full(len(free), np.inf)
            end_error = float(np.max(np.abs(shift))) + unmade
        else:
            end_error = 0.0
        kin = max(abs(sol.settlement), abs(sol.tilt), 1e-300)
        dyn = max(abs(sol.force), abs(sol.moment), 1e-300)
        output_error = max(abs(sol.settlement - fine.settlement) / kin,
                           abs(sol.tilt - fine.tilt) / kin,
                           abs(sol.force - fine.force) / dyn,
                           abs(sol.moment - fine.moment) / dyn)
        if end_error <= ZONE_END_TOL / 3 and output_error <= tol / 3:
            break
        if level == max_levels:
            break
        res = res.finer()
        sol = solve_on_zones(space, step, ends, res, accuracy=accuracy)
        builds += 1
    return Refined(sol, end_error, output_error, builds, level, converged)
