"""The direct graded-panel Nystrom discretization of the contact equation (the default engine).

The unknowns are the pressures ``q_i`` at the nodes ``x_i`` of a composite 16-point
Gauss-Legendre rule (:mod:`core.quadrature`), and the equation is imposed at the nodes:

    c m_i q_i + sum_j A_ij q_j = delta + alpha x_i - g_i,    sum_j w_j q_j = P,
    sum_j w_j x_j q_j = M,

with ``A`` the discrete layer operator (smooth part of the kernel by the Gauss rule, the
log part by product integration exact for the panel's degree-15 interpolant). Two of
``delta, alpha, P, M`` are given; the other two join ``q`` in one bordered solve.

Panels are graded geometrically toward ``x = +-1`` and toward every declared jump of
``m`` or ``g``, down to a quarter of the smallest compliance (the width of the edge
layer of ``q``), then refined adaptively: a panel whose pressure still has Legendre
coefficients above the target in its last three degrees is bisected (a per-panel error
indicator, so refinement goes where ``q`` is not yet resolved and nowhere else). The same
indicator, times :data:`ESTIMATE_FACTOR`, is the spatial error estimate of ``q``
relative to ``max|q|`` on [-1, 1] (edges and both sides of jumps included, since the
interpolant is exact per panel and panels break at the jumps).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.linalg import lu_factor, lu_solve

from core.quadrature import (
    NODES_PER_PANEL,
    Panels,
    base_panels,
    interpolation_weights,
    kernel_operator,
    panel_legendre_coefficients,
    refine_to_resolve,
)

Function = Callable[[np.ndarray], np.ndarray]

#: Largest number of panels of an adaptive grid (16 nodes each): the dense operator of
#: 256 panels holds 4096^2 doubles = 128 MiB, the bound of one solve's memory.
MAX_PANELS = 256
#: A panel is bisected while its indicator exceeds this share of the target.
REFINE_SHARE = 0.25
#: The estimate is the largest indicator times this factor: the tail coefficients bound
#: the interpolation error of a resolved panel up to a small factor (measured on the
#: work-precision scenes: true error / largest tail between 0.02 and 2.1).
ESTIMATE_FACTOR = 3.0
#: Relative round-off floor of the pressure (measured: ~1e-13 against the projection).
ROUND_OFF = 2e-13
#: Bisection rounds of the adaptive loop (a round halves every flagged panel).
MAX_ROUNDS = 40


@dataclass(frozen=True)
class NystromGrid:
    """Nodes, operator and coefficient samples of one discretization (dimensionless).

    ``operator[i, j]`` maps nodal pressures to ``(F q)(x_i)``; ``m``, ``g`` are the
    coating compliance and the gap at the nodes.
    """

    lam: float
    panels: Panels
    operator: np.ndarray
    m: np.ndarray
    g: np.ndarray

    @property
    def nodes(self) -> np.ndarray:
        """Node abscissae in [-1, 1], shape (N,)."""
        return self.panels.nodes

    @property
    def size(self) -> int:
        """Number of nodes N."""
        return self.panels.size

    def interpolate(self, x: np.ndarray, nodal: np.ndarray) -> np.ndarray:
        """Values at ``x`` of the panel-wise interpolant of ``nodal`` (N, ...)."""
        index, weights = interpolation_weights(self.panels, x)
        per_panel = nodal.reshape((-1, NODES_PER_PANEL) + nodal.shape[1:])
        return np.einsum("ij,ij...->i...", weights, per_panel[index])


def build_grid(lam: float, edges: np.ndarray, m: Function, g: Function) -> NystromGrid:
    """The discretization on panels with the given ``edges`` (dimensionless)."""
    panels = Panels.from_edges(edges)
    operator = kernel_operator(lam, panels).matrix
    return NystromGrid(lam, panels, operator, np.asarray(m(panels.nodes), dtype=float),
                       np.asarray(g(panels.nodes), dtype=float))


def elastic_responses(grid: NystromGrid, c: float, with_gap: bool) -> np.ndarray:
    """Nodal pressures for ``delta = 1``, ``alpha = 1`` (and the gap alone), shape (N, 2|3).

    Solves ``(c m + A) q = [1, x, -g]``: every answer of the elastic problem is a
    combination of these columns (statement 1 form).
    """
    matrix = grid.operator + np.diag(c * grid.m)
    rhs = [np.ones(grid.size), grid.nodes]
    if with_gap:
        rhs.append(-grid.g)
    return np.linalg.solve(matrix, np.column_stack(rhs))


def panel_indicators(grid: NystromGrid, responses: np.ndarray) -> np.ndarray:
    """Per-panel error indicator of the pressure, relative to ``max|q|`` (P,).

    The largest of the last three Legendre coefficients on each panel, over the response
    columns, each column scaled by its own maximum.
    """
    scale = np.max(np.abs(responses), axis=0)
    scale[scale == 0] = 1.0
    coef = panel_legendre_coefficients(responses / scale)  # (P, 16, k)
    return np.max(np.abs(coef[:, -3:, :]), axis=(1, 2))


@dataclass(frozen=True)
class AdaptiveGrid:
    """The grid the adaptive loop settled on and what it measured on it."""

    grid: NystromGrid
    spatial_error: float  # estimated error of q relative to max|q|
    resolved: bool  # every panel met the target within the panel budget
    rounds: int
    indicators: np.ndarray


def start_edges(lam: float, breakpoints: Sequence[float], m_min: float) -> np.ndarray:
    """Initial panel ends: graded toward +-1 and every jump down to ~m/4 (dimensionless)."""
    edge = float(np.clip(0.25 * m_min, 1e-9, 0.05))
    panels = base_panels(lam, breakpoints, edge_width=edge, max_width=min(0.5, 3.0 / lam))
    return panels.edges


def _split(edges: np.ndarray, flagged: np.ndarray, excess: np.ndarray,
           singular: np.ndarray) -> np.ndarray:
    """New panel ends: flagged panels bisected, or graded toward a singular end.

    Next to ``+-1`` or a jump the pressure has ``(x - e) ln|x - e|`` terms, whose tail on a
    panel of width h scales like h: such a panel is cut geometrically (ratio 2) down to
    ``h / excess`` in one go instead of one bisection per round. ``excess`` is the
    indicator over its threshold (> 1 where flagged).
    """
    new: list[float] = []
    for p in np.nonzero(flagged)[0]:
        a, b = edges[p], edges[p + 1]
        at_a = np.any(np.abs(singular - a) < 1e-14)
        at_b = np.any(np.abs(singular - b) < 1e-14)
        if not (at_a or at_b):
            new.append(0.5 * (a + b))
            continue
        levels = int(np.clip(np.ceil(np.log2(excess[p])) + 1, 1, 40))
        if at_a and at_b:
            mid = 0.5 * (a + b)
            new.append(mid)
            new.extend(a + (mid - a) * 0.5 ** np.arange(1, levels + 1))
            new.extend(b - (b - mid) * 0.5 ** np.arange(1, levels + 1))
        elif at_a:
            new.extend(a + (b - a) * 0.5 ** np.arange(1, levels + 1))
        else:
            new.extend(b - (b - a) * 0.5 ** np.arange(1, levels + 1))
    return np.unique(np.concatenate([edges, new]))


def adapt(lam: float, m: Function, g: Function, g_is_zero: bool,
          breakpoints: Sequence[float], target: float, *, c_ref: float = 1.0
          ) -> AdaptiveGrid:
    """Refine panels until every per-panel indicator is below ``REFINE_SHARE * target``.

    ``target`` is the relative accuracy wanted for q; ``c_ref`` the relative modulus the
    indicators are measured at (geometry is prepared before the times are known).
    """
    probe = np.linspace(-1.0, 1.0, 513)
    m_min = float(np.min(m(probe)))
    start = Panels.from_edges(start_edges(lam, breakpoints, m_min))
    functions = [m] if g_is_zero else [m, g]
    panels, resolved = refine_to_resolve(start, functions, max_panels=MAX_PANELS // 2)
    singular = np.array([-1.0, 1.0, *breakpoints])
    edges = panels.edges
    threshold = max(REFINE_SHARE * target, ROUND_OFF)
    grid = build_grid(lam, edges, m, g)
    for rounds in range(1, MAX_ROUNDS + 1):
        responses = elastic_responses(grid, c_ref, not g_is_zero)
        indicators = panel_indicators(grid, responses)
        flagged = indicators > threshold
        if not flagged.any():
            break
        edges = _split(grid.panels.edges, flagged, indicators / threshold, singular)
        if len(edges) - 1 > MAX_PANELS:
            resolved = False
            break
        grid = build_grid(lam, edges, m, g)
    estimate = max(float(np.max(indicators)) * ESTIMATE_FACTOR, ROUND_OFF)
    return AdaptiveGrid(grid, estimate, resolved and not flagged.any(), rounds, indicators)


# ------------------------------------------------------------------- bordered solves

_UNKNOWN_COLUMN = {"settlement": 0, "tilt": 1, "force": 2, "moment": 3}


class BorderedSystem:
    """The factorized bordered matrix of one statement at one relative modulus ``c``.

    Unknowns ``[q (N); the two unknown scalars]``; rows: the nodal equations, then force
    and moment balance. :meth:`unit_responses` solves once for a unit value of each
    given quantity and for the gap; any loads are then a linear combination.
    """

    def __init__(self, grid: NystromGrid, c: float, given: frozenset[str]) -> None:
        n = grid.size
        self.grid, self.c, self.given = grid, c, given
        self.unknown_names = tuple(q for q in ("settlement", "tilt", "force", "moment")
                                   if q not in given)
        matrix = np.zeros((n + 2, n + 2))
        matrix[:n, :n] = grid.operator
        matrix[np.arange(n), np.arange(n)] += c * grid.m
        matrix[n, :n] = grid.panels.weights
        matrix[n + 1, :n] = grid.panels.weights * grid.nodes
        columns = {"settlement": (slice(0, n), -np.ones(n)),
                   "tilt": (slice(0, n), -grid.nodes),
                   "force": (n, -1.0), "moment": (n + 1, -1.0)}
        for k, name in enumerate(self.unknown_names):
            rows, values = columns[name]
            matrix[rows, n + k] = values
        self._lu = lu_factor(matrix, check_finite=False)

    def unit_responses(self) -> dict[str, np.ndarray]:
        """Solution vectors (N + 2,) for each given quantity = 1 and for the gap."""
        n = self.grid.size
        rhs: dict[str, np.ndarray] = {}
        for name in sorted(self.given):
            column = np.zeros(n + 2)
            if name == "settlement":
                column[:n] = 1.0
            elif name == "tilt":
                column[:n] = self.grid.nodes
            elif name == "force":
                column[n] = 1.0
            else:
                column[n + 1] = 1.0
            rhs[name] = column
        gap = np.zeros(n + 2)
        gap[:n] = -self.grid.g
        rhs["gap"] = gap
        keys = list(rhs)
        solved = lu_solve(self._lu, np.column_stack([rhs[k] for k in keys]),
                          check_finite=False)
        return {k: solved[:, i] for i, k in enumerate(keys)}
