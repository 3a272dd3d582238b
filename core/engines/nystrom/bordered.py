"""The direct graded-panel Nystrom discretization of the contact equation (the default engine).

The unknowns are the pressures ``q_i`` at the nodes ``x_i`` of a composite 16-point
Gauss-Legendre rule (:mod:`core.discretize.quadrature`), and the equation is imposed at the nodes:

    c m_i q_i + sum_j A_ij q_j = delta + alpha x_i - g_i,    sum_j w_j q_j = P,
    sum_j w_j x_j q_j = M,

with ``A`` the discrete layer operator (smooth part of the kernel by the Gauss rule, the
log part by product integration exact for the panel's degree-15 interpolant). Two of
``delta, alpha, P, M`` are given; the other two join ``q`` in one bordered solve.

Between the nodes the pressure comes from the equation itself (the Nystrom formula)

    q(x) = [delta + alpha x - g(x) - (F q)(x)] / (c m(x)),

which is as accurate as the nodal values, exact in ``m`` and ``g`` on both sides of a jump,
and far better than interpolating: next to ``+-1`` and every jump ``q`` has an
``(x - e) ln|x - e|`` term that polynomials on a panel follow only algebraically
(measured on a smooth coating with 192 nodes: nodal values 5e-8, the formula 9e-8, panel
interpolation 2.4e-4 off).

Refinement and the error estimate: :mod:`core.engines.nystrom.adapt`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.linalg import lu_factor, lu_solve
from scipy.linalg.lapack import dgetrs, sgetrs

from core.discretize import (
    FRESH_SHARE,
    NODES_PER_PANEL,
    KernelOperator,
    Panels,
    interpolation_weights,
    kernel_operator,
    operator_rows,
)
from core.kernel import FULL_ACCURACY

Function = Callable[[np.ndarray], np.ndarray]

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
    kernel_accuracy: float = FULL_ACCURACY  # absolute accuracy of the kernel values

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
        per_panel = nodal.reshape((nodal.shape[0] // NODES_PER_PANEL, NODES_PER_PANEL)
                                  + nodal.shape[1:])
        if nodal.ndim == 1:
            return np.einsum("ij,ij->i", weights, per_panel[index])
        # One product per panel holding points: gathering each point's 16 node rows of
        # every column first (einsum over per_panel[index]) cost ~10x as much for the
        # several punches' pressure at ~340 points and ~260 times (4.8 -> 0.5 ms).
        columns = per_panel.reshape(per_panel.shape[0], NODES_PER_PANEL,
                                    int(np.prod(nodal.shape[1:])))
        out = np.empty((index.size, columns.shape[2]), dtype=np.result_type(weights, nodal))
        order = np.argsort(index, kind="stable")
        # the runs of points of one panel (none for no points)
        bounds = np.append(np.flatnonzero(np.diff(index[order], prepend=-1)), index.size)
        for lo, hi in zip(bounds[:-1], bounds[1:], strict=True):
            rows = order[lo:hi]
            out[rows] = weights[rows] @ columns[index[rows[0]]]
        return out.reshape((index.size,) + nodal.shape[1:])

    def rows(self, x: np.ndarray) -> np.ndarray:
        """Rows of ``F`` at points ``x``: ``(F q)(x) = rows @ q`` (len(x), N)."""
        return operator_rows(self.lam, self.panels, np.asarray(x, dtype=float),
                             accuracy=self.kernel_accuracy)


def build_grid(lam: float, edges: np.ndarray, m: Function, g: Function,
               previous: NystromGrid | None = None,
               kernel_accuracy: float = FULL_ACCURACY) -> NystromGrid:
    """The discretization on panels with the given ``edges`` (dimensionless).

    ``previous``: a grid of the same ``lam`` and kernel accuracy whose operator blocks
    between the panels both share are reused (only rows and columns of new panels are
    computed). ``kernel_accuracy``: absolute accuracy of the kernel values.
    """
    panels = Panels.from_edges(edges)
    before = (None if previous is None or previous.kernel_accuracy != kernel_accuracy
              else KernelOperator(previous.lam, previous.panels, previous.operator))
    operator = kernel_operator(lam, panels, before, kernel_accuracy, FRESH_SHARE).matrix
    return NystromGrid(lam, panels, operator, np.asarray(m(panels.nodes), dtype=float),
                       np.asarray(g(panels.nodes), dtype=float), kernel_accuracy)


def rhs_columns(x: np.ndarray, g: np.ndarray, with_gap: bool) -> np.ndarray:
    """Right-hand sides ``[1, x(, -g)]`` of the statement-1 responses at ``x`` (len(x), 2|3)."""
    columns = [np.ones(x.size), x] + ([-g] if with_gap else [])
    return np.column_stack(columns)


def elastic_responses(grid: NystromGrid, c: float, with_gap: bool) -> np.ndarray:
    """Nodal pressures for ``delta = 1``, ``alpha = 1`` (and the gap alone), shape (N, 2|3).

    Solves ``(c m + A) q = [1, x, -g]``: every answer of the elastic problem is a
    combination of these columns (statement 1 form).
    """
    return factored_responses(grid, c, with_gap)[0]


def factored_responses(grid: NystromGrid, c: float, with_gap: bool
                       ) -> tuple[np.ndarray, NodalLU]:
    """:func:`elastic_responses` and the factors of ``c m + A`` (kept for the bordered
    solves of :class:`BorderedSystem` at the same ``c``).

    One dense LU per grid: splitting it into the panels a refinement leaves alone and the
    rest, to reuse the first block's factors on the refined grid, cost more than it saved
    once a refinement adds only one panel per graded side (measured on the eight elastic
    work-precision scenes at tol 1e-6: 0.45-4.1 ms per scene split, 0.2-3.4 ms plain).
    """
    factor = NodalLU(grid.operator, c * grid.m, grid.kernel_accuracy)
    return factor.solve(rhs_columns(grid.nodes, grid.g, with_gap)), factor


#: From this size on the nodal LU is taken in single precision and its solutions refined
#: against the double-precision matrix (sgetrf took 0.39-1.1 ms where dgetrf took 0.83-3.0
#: at 256-416 nodes, one thread; at 144 nodes they cost the same).
SINGLE_FROM = 200
#: Refinement steps of a single-precision solve: the correction shrinks by ~cond x 6e-8
#: per step (1e-4-1e-3 on the work-precision scenes), so three or four reach rounding.
MAX_REFINEMENTS = 8
#: A refined solution is final when its error (estimated from the last two corrections)
#: is below this share of it, or below a tenth of the operator's accuracy.
REFINED = 1e-15
#: ... and is accepted when that error is below this share (else double precision).
ACCEPTED = 1e-11


class NodalLU:
    """LU factors of the nodal matrix ``operator + diag(diagonal)`` (N x N).

    Large ones are factored in single precision and every solve is refined to double
    precision by residuals of the double-precision matrix (iterative refinement); a
    matrix too ill-conditioned for that is factored again in double precision.
    """

    def __init__(self, operator: np.ndarray, diagonal: np.ndarray,
                 accuracy: float = 0.0) -> None:
        """``accuracy``: absolute accuracy of the operator's entries (O(0.1-1)); a
        refined solution goes no further than a tenth of it, relative (the entries'
        own error moves it more)."""
        self._operator, self._diagonal = operator, diagonal
        self._goal = max(REFINED, 0.1 * accuracy)
        n = operator.shape[0]
        single = n >= SINGLE_FROM
        matrix = operator.astype(np.float32 if single else float)
        matrix.flat[::n + 1] += diagonal
        self._lu = lu_factor(matrix, overwrite_a=True, check_finite=False)
        self._single = single

    def _double(self) -> None:
        matrix = self._operator.copy()
        matrix.flat[::matrix.shape[0] + 1] += self._diagonal
        self._lu = lu_factor(matrix, overwrite_a=True, check_finite=False)
        self._single = False

    def rough_solve(self, rhs: np.ndarray) -> np.ndarray:
        """The factors' own solve, unrefined (single precision from SINGLE_FROM nodes on:
        ~cond x 6e-8 relative): for a preconditioner, whose steps are refined anyway."""
        lu, pivots = self._lu  # LAPACK directly: scipy.linalg's checks cost ~10 us a call
        if not self._single:
            return dgetrs(lu, pivots, rhs)[0]
        return sgetrs(lu, pivots, rhs.astype(np.float32))[0].astype(float)

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """Solution of ``matrix x = rhs`` for right-hand sides (N,) or (N, k)."""
        if not self._single:
            return lu_solve(self._lu, rhs, check_finite=False)
        rhs = np.asarray(rhs, dtype=float)
        x = lu_solve(self._lu, rhs.astype(np.float32), check_finite=False).astype(float)
        diagonal = self._diagonal if rhs.ndim == 1 else self._diagonal[:, None]
        previous = np.inf
        left = np.inf  # estimated relative error of x
        for _ in range(MAX_REFINEMENTS):
            residual = rhs - self._operator @ x - diagonal * x
            step = lu_solve(self._lu, residual.astype(np.float32), check_finite=False)
            x += step
            size = np.maximum(np.max(np.abs(x), axis=0), 1e-300)
            change = float(np.max(np.max(np.abs(step), axis=0) / size))
            # the error left is about the next correction, change^2 / previous; done at
            # the goal, or when the corrections stop shrinking (the residual's own
            # rounding, ~cond x 1e-16, which a double-precision LU leaves as well)
            left = change * min(1.0, change / previous) if previous < np.inf else change
            if left <= self._goal or change > 0.25 * previous:
                break
            previous = change
        if not (np.all(np.isfinite(x)) and left <= max(self._goal, ACCEPTED)):
            self._double()  # no contraction: the matrix needs double-precision factors
            return lu_solve(self._lu, rhs, check_finite=False)
        return x


def touches(panels: Panels, points: np.ndarray) -> np.ndarray:
    """Whether each panel ends at one of ``points`` (P,)."""
    edges = panels.edges
    left = np.min(np.abs(edges[:-1, None] - points[None, :]), axis=1) < 1e-14
    right = np.min(np.abs(edges[1:, None] - points[None, :]), axis=1) < 1e-14
    return left | right


def nystrom_values(grid: NystromGrid, c: float, x: np.ndarray, m_x: np.ndarray,
                   g_x: np.ndarray, nodal: np.ndarray, with_gap: bool,
                   rows: np.ndarray | None = None) -> np.ndarray:
    """The Nystrom formula for the statement-1 responses at points ``x`` (len(x), 2|3).

    ``rows``: the rows of the grid's operator at ``x``, if already known.
    """
    rows = grid.rows(x) if rows is None else rows
    return (rhs_columns(x, g_x, with_gap) - rows @ nodal) / (c * m_x[:, None])


# ------------------------------------------------------------------- bordered solves

_UNKNOWN_COLUMN = {"settlement": 0, "tilt": 1, "force": 2, "moment": 3}


class BorderedSystem:
    """The factorized bordered matrix of one statement at one relative modulus ``c``.

    Unknowns ``[q (N); the two unknown scalars]``; rows: the nodal equations, then force
    and moment balance. :meth:`unit_responses` solves once for a unit value of each
    given quantity and for the gap; any loads are then a linear combination.
    """

    def __init__(self, grid: NystromGrid, c: float, given: frozenset[str],
                 factor: NodalLU | None = None, responses: np.ndarray | None = None) -> None:
        """``factor``: factors of ``c m + A`` on this grid, if known (from :func:`adapt`);
        then the border is eliminated by a 2 x 2 Schur complement instead of a new LU.
        ``responses``: ``(c m + A)^-1 [1, x(, -g)]`` (N, 2|3) by those factors, if known:
        every nodal right-hand side of :meth:`unit_responses` is one of their columns (or
        zero), so no solve with the factors is needed at all."""
        n = grid.size
        self.grid, self.c, self.given = grid, c, given
        self.unknown_names = tuple(q for q in ("settlement", "tilt", "force", "moment")
                                   if q not in given)
        # Border: columns B (N x 2) and corner D (2 x 2) of the unknown scalars, rows C
        # (2 x N) of force and moment balance.
        border = np.zeros((n + 2, 2))
        columns = {"settlement": (slice(0, n), -np.ones(n)),
                   "tilt": (slice(0, n), -grid.nodes),
                   "force": (n, -1.0), "moment": (n + 1, -1.0)}
        for k, name in enumerate(self.unknown_names):
            rows, values = columns[name]
            border[rows, k] = values
        self._balance = np.vstack([grid.panels.weights, grid.panels.weights * grid.nodes])
        self._border = border
        self._factor = factor
        self._responses = responses if factor is not None else None
        self._lu = None
        if factor is None:
            matrix = np.zeros((n + 2, n + 2))
            matrix[:n, :n] = grid.operator
            matrix[np.arange(n), np.arange(n)] += c * grid.m
            matrix[n:, :n] = self._balance
            matrix[:, n:] = border
            self._lu = lu_factor(matrix, overwrite_a=True, check_finite=False)

    def _solve(self, rhs: np.ndarray, nodal_solved: np.ndarray | None = None) -> np.ndarray:
        """Solutions (N + 2, k) of the bordered system for right-hand sides (N + 2, k).

        ``nodal_solved``: ``(c m + A)^-1 [rhs[:N], border[:N]]`` (N, k + 2) if known.
        """
        if self._lu is not None:
            return lu_solve(self._lu, rhs, check_finite=False)
        n, k = self.grid.size, rhs.shape[1]
        solved = (self._factor.solve(np.column_stack([rhs[:n], self._border[:n]]))
                  if nodal_solved is None else nodal_solved)
        y_rhs, y_border = solved[:, :k], solved[:, k:]
        schur = self._border[n:] - self._balance @ y_border
        scalars = np.linalg.solve(schur, rhs[n:] - self._balance @ y_rhs)
        return np.vstack([y_rhs - y_border @ scalars, scalars])

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
        solved = self._solve(np.column_stack([rhs[k] for k in keys]),
                             self._nodal_solved(keys))
        return {k: solved[:, i] for i, k in enumerate(keys)}

    def _nodal_solved(self, keys: list[str]) -> np.ndarray | None:
        """``(c m + A)^-1`` of the nodal parts of the unit right-hand sides ``keys`` and of
        the border, from the known responses to ``[1, x, -g]`` (None if not known)."""
        if self._responses is None:
            return None
        r = self._responses
        zero = np.zeros(self.grid.size)
        # nodal right-hand side: settlement 1, tilt x, force and moment 0, gap -g (a zero
        # gap has no response column: its solution is zero)
        of = {"settlement": r[:, 0], "tilt": r[:, 1], "force": zero, "moment": zero,
              "gap": r[:, 2] if r.shape[1] > 2 else zero}
        # border: -1 for an unknown settlement, -x for an unknown tilt, 0 otherwise
        border = {"settlement": -r[:, 0], "tilt": -r[:, 1], "force": zero, "moment": zero}
        return np.column_stack([of[k] for k in keys]
                               + [border[name] for name in self.unknown_names])
