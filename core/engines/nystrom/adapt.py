"""Adaptive refinement of the Nystrom grid (:mod:`core.engines.nystrom.bordered`) and its
error estimate.

Refinement, in two parts:
- away from ``+-1`` and the jumps q is analytic: a panel whose last three Legendre
  coefficients exceed the target is bisected (a per-panel indicator);
- the panels ending at ``+-1`` or a jump are graded geometrically toward it; the nodal
  error there falls like h^2 (h the finest width; measured 13-21x per 4-5x in h), so
  two solves whose grading differs by one level (the panel at the point cut at a quarter
  of its width: h/4) give the error of the finer one, about their difference / 15, and
  the number of levels still missing. One cut at a quarter, not two halvings, adds 16
  nodes per graded side instead of 32 at the same finest width: the errors and estimates
  of the eight elastic work-precision scenes at tol 1e-4 and 1e-6 came out the same (to
  the digits printed) with 12-25% fewer nodes (smooth 176 -> 144, stepped punch
  384 -> 288).

The answer is the finer grid's, or the coarser one's where its own estimate (the
difference plus the finer grid's error, times ``SAFETY``) leaves the time stepping its
share of the target (``COARSE_SHARE``): so a loose tol buys fewer nodes.

Work of a new scene: the operator of each grid reuses the blocks of the panels it shares
with the previous one (the kernel being even, a square operator evaluates it on and above
the diagonal only, and the new columns of a refined one are its new rows transposed
away from the new panels), the coarse answer is evaluated by the formula only at the new
nodes, the kernel values are computed to ``KERNEL_SHARE * tol`` (not to rounding), and the
responses of the last grid serve the bordered solve of the loads (a 2 x 2 Schur
complement). A refined grid is solved with the factors of the grid it refines (two-grid
steps, :mod:`core.engines.nystrom.twogrid`) and factored only if a later solve asks for it. From
200 nodes the LUs are single-precision factors whose solves are refined against the
double-precision operator (:class:`core.engines.nystrom.NodalLU`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from core.discretize import (
    NODES_PER_PANEL,
    Panels,
    base_panels,
    node_rows,
    panel_legendre_coefficients,
    panel_nodes,
    refine_to_resolve,
    shared_panels,
)
from core.engines.nystrom.bordered import (
    Function,
    NodalLU,
    NystromGrid,
    build_grid,
    factored_responses,
    rhs_columns,
    touches,
)
from core.engines.nystrom.twogrid import DeferredFactor, TwoGridSolver

#: Largest number of panels of an adaptive grid (16 nodes each): the dense operator of
#: 128 panels holds 2048^2 doubles = 32 MiB and its LU costs ~0.3 s, the bound of one
#: solve's memory and work. A scene that needs more is answered with ``tol_not_met``.
MAX_PANELS = 128
#: An interior panel is bisected while its Legendre tail exceeds this share of the target.
INTERIOR_SHARE = 0.25
#: Each level of grading cuts the panel at a singular point at this share of its width.
LEVEL_SPLIT = 0.25
#: Error reduction of the nodal pressure per level of grading (h -> h/4): ~h^2.
LEVEL_RATIO = 16.0
#: The two-grid estimate is multiplied by this (the observed order was 1.9-2.1).
SAFETY = 3.0
#: The coarser grid of the last two-level comparison carries the answer when its own
#: estimate (``SAFETY`` times the difference, plus the finer grid's error) is below this
#: share of the target: under creep the rest is the time stepping's. Measured on the
#: eight scenes of ``benchmarks/engines.py`` at tol 1e-3 and 1e-4 against tol 1e-10 (q
#: on [-1, 1], edges and both sides of jumps included, and the four scalars;
#: benchmarks/results/engines.md): errors 1.5e-6 to 2.1e-4 under estimates 2.9 to 5.9
#: times larger (stepped punch 288 -> 192 nodes, smooth coating 128 -> 96).
COARSE_SHARE = 0.5
#: Relative round-off floor of the pressure (measured: ~1e-13 against the projection).
ROUND_OFF = 2e-13
#: Width ratio of neighbouring panels graded toward +-1 and the jumps on the starting grid,
#: for targets >= COARSE_GRADING_TARGET (above) and below. Measured on the eight elastic
#: work-precision scenes: at tol 1e-6 ratio 4 needs 176-448 nodes where ratio 2 needed
#: 192-496 (no coating 320 instead of 496), at the same error; at tol 1e-8 ratio 2 needs
#: slightly fewer (352-896 against 368-896).
GRADING_RATIO = (4.0, 2.0)
COARSE_GRADING_TARGET = 1e-7
#: The kernel values are evaluated to this share of the target (absolute; they are
#: O(0.1-1)): like the kernel's quadrature (widest_panel), out of sight of the estimate.
KERNEL_SHARE = 1e-4
#: Above this target the starting grid's finest width grows like sqrt(target) (adapt).
COARSEN_FROM = 1e-6
#: m and g are resolved on the starting panels to this share of the target.
RESOLVE_SHARE = 0.1
#: A starting panel may be this much more than GRADING_RATIO times a neighbour's width.
GROWTH_SLACK = 1.05
#: Rounds of each refinement loop.
MAX_ROUNDS = 12
#: From this size on a refined grid is solved with the coarser grid's factors
#: (:mod:`core.engines.nystrom.twogrid`); below it its own dense LU is cheaper (measured, one
#: thread: 144 nodes 0.15 ms LU against 0.30 ms of steps; 224 nodes 0.46 against 0.38;
#: 256-416 nodes 0.66-2.3 against 0.46-0.87).
TWO_GRID_FROM = 200



def interior_tails(grid: NystromGrid, responses: np.ndarray, singular: np.ndarray
                   ) -> np.ndarray:
    """Legendre tail of q on each panel relative to ``max|q|``; 0 on panels at a singular point."""
    scale = np.max(np.abs(responses), axis=0)
    scale[scale == 0] = 1.0
    coef = panel_legendre_coefficients(responses / scale)  # (P, 16, k)
    tail = np.max(np.abs(coef[:, -3:, :]), axis=(1, 2))
    return np.where(touches(grid.panels, singular), 0.0, tail)


def grade(edges: np.ndarray, singular: np.ndarray, levels: int, split: float = 0.5
          ) -> np.ndarray:
    """Cut every panel that ends at a singular point geometrically, ``levels`` times, toward it.

    Each cut is at ``split`` of the remaining width from the point (a panel ending at two
    such points is halved first).
    """
    a, b = edges[:-1], edges[1:]
    at_a = np.min(np.abs(a[:, None] - singular[None, :]), axis=1) < 1e-14
    at_b = np.min(np.abs(b[:, None] - singular[None, :]), axis=1) < 1e-14
    steps = split ** np.arange(1, levels + 1)
    both = at_a & at_b
    mid = 0.5 * (a + b)
    # A panel at two such points is halved, each half cut toward its own end.
    near_a = np.where(both, mid, b)
    near_b = np.where(both, mid, a)
    new = [mid[both],
           (a[at_a, None] + (near_a[at_a] - a[at_a])[:, None] * steps[None, :]).ravel(),
           (b[at_b, None] - (b[at_b] - near_b[at_b])[:, None] * steps[None, :]).ravel()]
    return np.unique(np.concatenate([edges, *new]))


def collapsed(grid: NystromGrid) -> bool:
    """Whether the grading went past what double precision resolves: nodes at a
    singular point itself, a non-finite operator. A base 91 times softer after creep
    asked tol 1e-10 of ~30 levels toward the edges, panels of 1e-18 whose nodes were 1.0
    itself, and the modal form raised a bare LinAlgError (a researcher's audit)."""
    return not bool(np.all(np.isfinite(grid.operator)))


def _coarse_operator_at(coarse: NystromGrid, fine: NystromGrid, kept_new: np.ndarray,
                        kept_old: np.ndarray, fresh: np.ndarray, nodal: np.ndarray,
                        accuracy: float) -> np.ndarray:
    """``(F q)`` of the coarse operator at the nodes of the fine grid's ``fresh`` panels,
    for coarse nodal values ``nodal`` (N0, k).

    On the panels both grids share, the coarse rows are the fine operator's entries (same
    target, same source panel, same rule): its rows times ``nodal`` placed at the shared
    nodes; only the columns of the coarse panels the fine grid split are computed (the
    rows on all coarse columns cost 0.3-1.1 ms a scene).
    """
    fn = panel_nodes(fresh)
    on_fine = np.zeros((fine.size, nodal.shape[1]))
    on_fine[panel_nodes(kept_new)] = nodal[panel_nodes(kept_old)]
    out = fine.operator[fn] @ on_fine
    split = np.ones(coarse.panels.n_panels, dtype=bool)
    split[kept_old] = False
    split = np.nonzero(split)[0]
    if split.size:
        out += node_rows(coarse.lam, coarse.panels, fine.panels, fresh, split,
                         accuracy) @ nodal[panel_nodes(split)]
    return out


def _fine_responses(coarse: NystromGrid, coarse_factor: NodalLU | DeferredFactor,
                    fine: NystromGrid, c: float, with_gap: bool,
                    shared: tuple[np.ndarray, np.ndarray, np.ndarray], guess: np.ndarray
                    ) -> tuple[np.ndarray, NodalLU | DeferredFactor]:
    """The statement-1 responses on ``fine`` and its (deferred) factors.

    Solved with the coarse grid's factors (:class:`core.engines.nystrom.twogrid.TwoGridSolver`,
    from ``guess``, the coarse answer at the fine nodes); the fine grid is factored only
    if that does not converge, or later if a solve asks for its factors.
    """
    if fine.size < TWO_GRID_FROM:
        return factored_responses(fine, c, with_gap)
    solver = TwoGridSolver(coarse, coarse_factor, fine, c, *shared)
    responses = solver.solve(rhs_columns(fine.nodes, fine.g, with_gap), guess)
    if responses is None:
        return factored_responses(fine, c, with_gap)
    return responses, DeferredFactor(fine, c)


@dataclass(frozen=True)
class AdaptiveGrid:
    """The grid the adaptive loop settled on and what it measured on it."""

    grid: NystromGrid
    spatial_error: float  # estimated error of q relative to max|q| on [-1, 1]
    resolved: bool  # the target was met within the panel budget
    rounds: int
    c_ref: float = 1.0  # the relative modulus of ``factor``
    # factors of c_ref m + A on ``grid`` (taken at the first solve that needs them)
    factor: NodalLU | DeferredFactor | None = None
    # (c_ref m + A)^-1 [1, x(, -g)] on ``grid``: the statement-1 responses the loop solved
    responses: np.ndarray | None = None
    # the grading stopped where a finer one would collapse (:func:`collapsed`)
    narrowest: bool = False


def _remembering(f: Function) -> Function:
    """``f`` with its values at the last points asked for kept: the resolution check of the
    starting panels and the operator of the grid on them ask for the same nodes (one
    evaluation of a ten-layer m costs ~0.09 ms at 192 nodes, mostly per call)."""
    last: list = [None, None]

    def remembered(x: np.ndarray) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        key = x.tobytes()
        if last[0] != key:
            last[:] = [key, np.asarray(f(x), dtype=float)]
        return last[1].copy()

    return remembered


def widest_panel(lam: float, target: float) -> float:
    """Widest panel whose Gauss rule integrates the kernel's smooth part to ~target/10.

    ``k_reg(lam d)`` is analytic up to ``d = +-2i/lam``: on a panel of half-width h the
    16-point rule errs like rho^-32 with rho = a + sqrt(a^2 + 1), a = 2/(lam h). At
    target 1e-14 this gives the 3/lam of core.discretize.quadrature; at 1e-6 about 9/lam.
    """
    rho = (0.1 * max(target, 1e-15)) ** (-1.0 / (2 * NODES_PER_PANEL))
    a = 0.5 * (rho - 1.0 / rho)
    return min(0.5, 4.0 / (lam * a))


def start_edges(lam: float, breakpoints: Sequence[float], m_min: float,
                target: float = 1e-14, ratio: float = 2.0, coarsen: float = 1.0
                ) -> np.ndarray:
    """Initial panel ends: graded toward +-1 and every jump down to ~m (dimensionless).

    ``target``: the kernel quadrature's accuracy; ``ratio``: the grading's width ratio;
    ``coarsen``: the finest width is ``coarsen`` times m (at most 0.1).
    """
    edge = float(np.clip(coarsen * m_min, 1e-9, 0.1))
    widest = widest_panel(lam, target)
    # base_panels caps widths at 3/lam' as well: pass the lam' for which that is `widest`.
    panels = base_panels(3.0 / widest, breakpoints, edge_width=edge, max_width=widest,
                         ratio=ratio)
    return _limit_growth(panels.edges, ratio)


def _limit_growth(edges: np.ndarray, ratio: float) -> np.ndarray:
    """``edges`` with every panel wider than ``ratio`` times a neighbour bisected.

    Where a graded run ends early on a short interval (between a jump and +-1) its last
    panel can sit next to one 5-6 times wider, where the end behaviour of q is not yet
    resolved: the interior loop then bisected it after a first solve (measured on the
    modulus jump and the stepped punch at tol 1e-6: a third grid); bisected here instead.
    """
    for _ in range(MAX_ROUNDS):
        widths = np.diff(edges)
        narrower = np.minimum(np.append(widths[1:], np.inf), np.append(np.inf, widths[:-1]))
        wide = widths > ratio * GROWTH_SLACK * narrower
        if not wide.any():
            break
        edges = np.sort(np.concatenate([edges, 0.5 * (edges[:-1] + edges[1:])[wide]]))
    return edges


def adapt(lam: float, m: Function, g: Function, g_is_zero: bool,
          breakpoints: Sequence[float], target: float, *, c_ref: float = 1.0
          ) -> AdaptiveGrid:
    """Refine until the estimated error of q (relative to ``max|q|``) is below ``target``.

    ``c_ref`` is the relative modulus the error is measured at (geometry is prepared
    before the times are known; c(1) = 1 in the scenes' scaling).
    """
    m, g = _remembering(m), _remembering(g)
    probe = np.linspace(-1.0, 1.0, 513)
    m_min = float(np.min(m(probe)))
    with_gap = not g_is_zero
    singular = np.array([-1.0, 1.0, *breakpoints])
    # The kernel's quadrature error is not seen by the two-level estimate: keep it 1e3 below.
    ratio = GRADING_RATIO[0] if target >= COARSE_GRADING_TARGET else GRADING_RATIO[1]
    accuracy = KERNEL_SHARE * target
    # Finest width: ~m at tol 1e-6, where the first two-level comparison then meets the
    # target (measured errors 0.4-3e-7 relative for an end width ~m, falling like h^2);
    # wider in proportion to sqrt(tol) above, so a loose tol starts (and ends) coarser.
    coarsen = max(1.0, np.sqrt(target / COARSEN_FROM))
    start = Panels.from_edges(start_edges(lam, breakpoints, m_min, 1e-3 * target, ratio,
                                          coarsen))
    # m and g need resolving only as far as q does (its own tails are checked below):
    # resolving them to 1e-12 at any tol took the rough punch from ~400 to 1312 nodes.
    panels, resolved = refine_to_resolve(start, [m] if g_is_zero else [m, g],
                                         rel_tol=RESOLVE_SHARE * target,
                                         max_panels=MAX_PANELS)
    edges = panels.edges
    rounds = 0
    # 1. Interior panels: bisect where q is not resolved.
    tails = np.zeros(1)
    grid: NystromGrid | None = None
    for _ in range(MAX_ROUNDS):
        rounds += 1
        grid = build_grid(lam, edges, m, g, grid, accuracy)
        responses, factor = factored_responses(grid, c_ref, with_gap)
        tails = interior_tails(grid, responses, singular)
        flagged = tails > INTERIOR_SHARE * target
        if not flagged.any():
            break
        edges = np.unique(np.concatenate([edges, grid.panels.centers[flagged]]))
        if len(edges) - 1 > MAX_PANELS:
            resolved = False
            break
    interior = float(np.max(tails))
    # 2. Grading toward +-1 and the jumps: two solves one level (h -> h/4) apart.
    estimate = np.inf
    narrowest = False
    for _ in range(MAX_ROUNDS):
        rounds += 1
        fine_edges = grade(grid.panels.edges, singular, 1, LEVEL_SPLIT)
        if len(fine_edges) - 1 > MAX_PANELS:
            resolved = False
            break
        fine = build_grid(lam, fine_edges, m, g, grid, accuracy)
        if collapsed(fine):
            resolved, narrowest = False, True
            break
        # The coarse answer at the fine nodes: its nodal values where the panel is shared
        # (the Nystrom formula returns them there), the formula at the new nodes only.
        kept_new, kept_old, fresh = shared_panels(grid.panels, fine.panels)
        coarse_at_fine = np.empty((fine.size, responses.shape[1]))
        coarse_at_fine[panel_nodes(kept_new)] = responses[panel_nodes(kept_old)]
        fn = panel_nodes(fresh)
        applied = _coarse_operator_at(grid, fine, kept_new, kept_old, fresh, responses,
                                      accuracy)
        coarse_at_fine[fn] = ((rhs_columns(fine.nodes[fn], fine.g[fn], with_gap) - applied)
                              / (c_ref * fine.m[fn, None]))
        fine_responses, fine_factor = _fine_responses(grid, factor, fine, c_ref, with_gap,
                                                      (kept_new, kept_old, fresh),
                                                      coarse_at_fine)
        scale = np.max(np.abs(fine_responses), axis=0)
        scale[scale == 0] = 1.0
        difference = float(np.max(np.abs(coarse_at_fine - fine_responses) / scale))
        estimate = SAFETY * difference / (LEVEL_RATIO - 1.0) + interior
        # The coarser grid errs by the difference plus the finer one's error: where that
        # bound leaves the time stepping its share, the coarser grid is the answer's (a
        # loose tol then buys fewer nodes; the finer grid was only its error's witness).
        coarse_estimate = SAFETY * difference * LEVEL_RATIO / (LEVEL_RATIO - 1.0) + interior
        if coarse_estimate <= COARSE_SHARE * target:
            estimate = coarse_estimate
            break
        grid, responses, factor = fine, fine_responses, fine_factor
        if not np.isfinite(estimate):
            # a reference modulus so small (a base ~1e50 times softer after creep) that
            # the grid's responses overflow and its factor is singular: no refinement
            # resolves it here
            estimate, resolved = np.inf, False
            break
        if estimate <= target:
            break
        # Each further level gains ~16x: add the missing ones (the loop adds the last).
        missing = int(np.ceil(np.log(estimate / target) / np.log(LEVEL_RATIO)))
        if missing > 1:
            edges = grade(grid.panels.edges, singular, missing - 1, LEVEL_SPLIT)
            if len(edges) - 1 > MAX_PANELS:
                resolved = False
                break
            finer = build_grid(lam, edges, m, g, grid, accuracy)
            if collapsed(finer):
                resolved, narrowest = False, True
                break
            grid = finer
            responses, factor = factored_responses(grid, c_ref, with_gap)
    estimate = max(estimate, ROUND_OFF)
    return AdaptiveGrid(grid, estimate, resolved and estimate <= target, rounds, c_ref,
                        factor, responses, narrowest)
