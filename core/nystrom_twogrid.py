"""The refined grid's equations solved with the factors of the grid it refines (two-grid).

The grading loop of :func:`core.nystrom_adapt.adapt` solves on a grid and on its
refinement toward +-1 and the jumps, which splits the few panels there and keeps every
other one. The refined grid's nodal matrix ``M1 = c m + A1`` then needs no factors of its
own: one step of

    z = P M0^-1 R r,   z += M1_FF^-1 (r - M1 z)_F   on each run of split panels,

(``M0`` the coarser grid's matrix with its known factors; ``P`` the coarse panels'
interpolants at the refined nodes, exact because the coarse panels are unions of refined
ones; ``R`` the refined panels' interpolants at the coarse nodes; ``F`` the nodes of a run
of contiguous new panels, 32-64 nodes) contracts the error ~1e-8 per step on the eight
elastic work-precision scenes at tol 1e-6 and 1e-9 (measured against the dense solve: the
new panels are short, so what they do to the other rows is small and smooth). Started from
the coarse answer at the refined nodes, two steps reach rounding: ~0.15 ms where the LU of
256-416 nodes and its solves cost 0.6-1.8 ms.

A step that does not contract returns ``None`` and the caller factors the matrix.
"""

from __future__ import annotations

import threading

import numpy as np
from scipy.linalg.lapack import dgetrf, dgetrs

from core.nystrom import REFINED, NodalLU, NystromGrid
from core.quadrature import NODES_PER_PANEL, interpolation_weights, panel_nodes

#: Steps before giving up (two suffice on every scene measured; the rest is a margin).
MAX_STEPS = 6
#: A step must shrink the correction at least this much, else the factors are taken.
CONTRACTION = 0.1


class DeferredFactor:
    """Factors of ``c m + A`` on a grid (:class:`core.nystrom.NodalLU`), taken at the first
    solve: a grid solved by :class:`TwoGridSolver` needs none unless a later solve asks."""

    def __init__(self, grid: NystromGrid, c: float) -> None:
        self._grid, self._c = grid, c
        self._factor: NodalLU | None = None
        self._lock = threading.Lock()

    @property
    def factored(self) -> bool:
        """Whether the factors have been taken."""
        return self._factor is not None

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """Solution of ``(c m + A) x = rhs`` for right-hand sides (N,) or (N, k)."""
        with self._lock:
            if self._factor is None:
                self._factor = NodalLU(self._grid.operator, self._c * self._grid.m,
                                       self._grid.kernel_accuracy)
            factor = self._factor
        return factor.solve(rhs)


def _interpolate(weights: tuple[np.ndarray, np.ndarray], values: np.ndarray) -> np.ndarray:
    """Panel interpolants of nodal ``values`` (N, k) at the points of ``weights``."""
    index, w = weights
    per_panel = values.reshape(-1, NODES_PER_PANEL, values.shape[1])
    return np.einsum("ij,ijk->ik", w, per_panel[index])


class TwoGridSolver:
    """Solves ``(c m + A1) x = b`` on ``fine`` with the factors of ``c m + A0`` on ``coarse``.

    ``kept_new``, ``kept_old``, ``fresh``: :func:`core.quadrature.shared_panels` of the two
    grids. The coarse panels must be unions of fine ones (the refinements of
    :mod:`core.nystrom_adapt` only cut panels); :meth:`solve` returns ``None`` otherwise.
    """

    def __init__(self, coarse: NystromGrid, coarse_factor: NodalLU | DeferredFactor,
                 fine: NystromGrid, c: float, kept_new: np.ndarray, kept_old: np.ndarray,
                 fresh: np.ndarray) -> None:
        self._coarse_factor = coarse_factor
        self._fine, self._c = fine, c
        self._diagonal = c * fine.m
        # Nested partitions: every coarse end is a fine end (cuts keep the old ends exactly).
        ends, fine_ends = coarse.panels.edges, fine.panels.edges
        at = np.minimum(np.searchsorted(fine_ends, ends), fine_ends.size - 1)
        self.nested = bool(fresh.size) and bool(np.all(fine_ends[at] == ends))
        if not self.nested:
            return
        split = np.ones(coarse.panels.n_panels, dtype=bool)
        split[kept_old] = False
        self._kn, self._ko = panel_nodes(kept_new), panel_nodes(kept_old)
        self._fn, self._sn = panel_nodes(fresh), panel_nodes(np.nonzero(split)[0])
        self._n0 = coarse.size
        self._to_fine = interpolation_weights(coarse.panels, fine.nodes[self._fn])
        self._to_coarse = interpolation_weights(fine.panels, coarse.nodes[self._sn])
        # Runs of contiguous new panels: each a small dense block (32-64 nodes) solved
        # exactly (LAPACK called directly: scipy.linalg's checks cost more than the solve).
        # Blocks of single panel pairs contracted only ~1e-4 per step at a jump.
        runs = np.split(fresh, np.nonzero(np.diff(fresh) > 1)[0] + 1)
        self._blocks = []
        for run in runs:
            nodes = slice(run[0] * NODES_PER_PANEL, (run[-1] + 1) * NODES_PER_PANEL)
            block = fine.operator[nodes, nodes].copy()
            block[np.diag_indices_from(block)] += self._diagonal[nodes]
            lu, pivots, info = dgetrf(block, overwrite_a=True)
            if info != 0:
                self.nested = False  # singular block: leave it to the dense factors
                return
            self._blocks.append((nodes, lu, pivots))

    def _apply(self, x: np.ndarray) -> np.ndarray:
        return self._fine.operator @ x + self._diagonal[:, None] * x

    def _step(self, residual: np.ndarray) -> np.ndarray:
        """One application of the two-grid preconditioner to residuals (N1, k)."""
        restricted = np.empty((self._n0, residual.shape[1]))
        restricted[self._ko] = residual[self._kn]
        restricted[self._sn] = _interpolate(self._to_coarse, residual)
        coarse = self._coarse_factor.solve(restricted)
        z = np.empty_like(residual)
        z[self._kn] = coarse[self._ko]
        z[self._fn] = _interpolate(self._to_fine, coarse)
        fine = self._fine
        for nodes, lu, pivots in self._blocks:
            local = (residual[nodes] - fine.operator[nodes] @ z
                     - self._diagonal[nodes, None] * z[nodes])
            z[nodes] += dgetrs(lu, pivots, local)[0]
        return z

    def solve(self, rhs: np.ndarray, guess: np.ndarray | None = None) -> np.ndarray | None:
        """Solution (N1, k) for right-hand sides ``rhs`` (N1, k), from ``guess`` if given;
        ``None`` if the steps do not contract (then factor the matrix instead).

        Stops when the error left (estimated from the last two corrections, as
        :class:`core.nystrom.NodalLU` does) is below a tenth of the operator's accuracy,
        relative to the solution.
        """
        if not self.nested:
            return None
        goal = max(REFINED, 0.1 * self._fine.kernel_accuracy)
        x = np.zeros_like(rhs) if guess is None else np.array(guess, dtype=float)
        previous = np.inf
        for _ in range(MAX_STEPS):
            step = self._step(rhs - self._apply(x))
            x += step
            size = np.maximum(np.max(np.abs(x), axis=0), 1e-300)
            change = float(np.max(np.max(np.abs(step), axis=0) / size))
            if not np.isfinite(change) or change > CONTRACTION * previous:
                return None
            left = change * min(1.0, change / previous) if previous < np.inf else change
            if left <= goal:
                return x
            previous = change
        return None
