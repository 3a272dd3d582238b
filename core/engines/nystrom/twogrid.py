"""The refined grid's equations solved with the factors of the grid it refines (two-grid).

The grading loop of :func:`core.engines.nystrom.adapt` solves on a grid and on its
refinement toward +-1 and the jumps, which splits the few panels there and keeps every
other one. The refined grid's nodal matrix ``M1 = c m + A1`` then needs no factors of its
own: one step of

    z = P M0^-1 R r,   z += M1_FF^-1 (r - M1 z)_F   on each run of split panels,

(``M0`` the coarser grid's matrix with its known factors; ``P`` the coarse panels'
interpolants at the refined nodes, exact because the coarse panels are unions of refined
ones; ``R`` the refined panels' interpolants at the coarse nodes; ``F`` the nodes of a run
of contiguous new panels, 32-64 nodes) contracts the error ~1e-8 per step on the eight
elastic work-precision scenes at tol 1e-6 and 1e-9 (measured against the dense solve: the
new panels are short, so what they do to the other rows is small and smooth). The coarse
solve inside a step is the factors' own, unrefined (single precision from 200 nodes):
the steps refine it. Started from the coarse answer at the refined nodes, two steps per
refined grid reach rounding (tol 1e-6; 2-3 per grid at 1e-8): 0.38-0.87 ms where the LU
of 224-416 nodes and its refined solves cost 0.46-2.3 ms (one thread).

A step that does not contract returns ``None`` and the caller factors the matrix.
"""

from __future__ import annotations

import threading

import numpy as np
from numpy.polynomial import legendre as npleg
from scipy.linalg.lapack import dgetrf, dgetrs

from core.discretize import (
    GAUSS_NODES,
    NODES_PER_PANEL,
    VALUES_TO_LEGENDRE,
    Panels,
    panel_index,
    panel_nodes,
)
from core.engines.nystrom.bordered import REFINED, NodalLU, NystromGrid

#: Steps before giving up (two suffice on every scene measured; the rest is a margin).
MAX_STEPS = 6
#: A step must shrink the correction at least this much, else the factors are taken.
CONTRACTION = 0.1


class DeferredFactor:
    """Factors of ``c m + A`` on a grid (:class:`core.engines.nystrom.NodalLU`), taken at the first
    solve: a grid solved by :class:`TwoGridSolver` needs none unless a later solve asks."""

    def __init__(self, grid: NystromGrid, c: float) -> None:
        self._grid, self._c = grid, c
        self._factor: NodalLU | None = None
        self._lock = threading.Lock()

    @property
    def factored(self) -> bool:
        """Whether the factors have been taken."""
        return self._factor is not None

    def _factors(self) -> NodalLU:
        with self._lock:
            if self._factor is None:
                self._factor = NodalLU(self._grid.operator, self._c * self._grid.m,
                                       self._grid.kernel_accuracy)
            return self._factor

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """Solution of ``(c m + A) x = rhs`` for right-hand sides (N,) or (N, k)."""
        return self._factors().solve(rhs)

    def rough_solve(self, rhs: np.ndarray) -> np.ndarray:
        """:meth:`core.engines.nystrom.NodalLU.rough_solve` of the factors."""
        return self._factors().rough_solve(rhs)


#: Interpolation weights between a panel and the panels it was cut into, keyed by the
#: piece's width ratio and centre offset (in half-widths of the whole, rounded to 1e-12):
#: a grading cuts at the same few places, so a few keys recur. Emptied when it holds more.
_WEIGHTS: dict[tuple, np.ndarray] = {}
_WEIGHTS_MAX = 1024


def _piece_keys(whole: Panels, pieces: Panels, parent: np.ndarray, index: np.ndarray
                ) -> list[tuple[float, float]]:
    """(width ratio, centre offset) of ``pieces[index]`` in ``whole[parent]``."""
    h = whole.half_widths[parent]
    ratio = np.round(pieces.half_widths[index] / h, 12)
    offset = np.round((pieces.centers[index] - whole.centers[parent]) / h, 12)
    return list(zip(ratio.tolist(), offset.tolist(), strict=True))


def _weights(key: tuple, compute) -> np.ndarray:
    found = _WEIGHTS.get(key)
    if found is None:
        found = compute()
        if len(_WEIGHTS) >= _WEIGHTS_MAX:
            _WEIGHTS.clear()
        _WEIGHTS[key] = found
    return found


def _to_piece(ratio: float, offset: float) -> np.ndarray:
    """Values at a piece's 16 nodes of the whole panel's interpolant (16 x 16)."""
    return _interpolant_at(offset + ratio * GAUSS_NODES)


def _to_whole(pieces: tuple[tuple[float, float], ...]) -> np.ndarray:
    """Values at the whole panel's 16 nodes of the pieces' interpolants (16 x 16 pieces):
    each node takes the piece that holds it."""
    out = np.zeros((NODES_PER_PANEL, NODES_PER_PANEL * len(pieces)))
    taken = np.zeros(NODES_PER_PANEL, dtype=bool)
    for k, (ratio, offset) in enumerate(pieces):
        inside = (np.abs(GAUSS_NODES - offset) <= ratio * (1.0 + 1e-14)) & ~taken
        taken |= inside
        local = (GAUSS_NODES[inside] - offset) / ratio
        out[np.ix_(inside, np.arange(k * NODES_PER_PANEL, (k + 1) * NODES_PER_PANEL))] = (
            _interpolant_at(local))
    return out


def _interpolant_at(t: np.ndarray) -> np.ndarray:
    """Weights (len(t), 16) of the interpolant through the 16 Gauss nodes at ``t`` in [-1, 1]."""
    return npleg.legvander(t, NODES_PER_PANEL - 1) @ VALUES_TO_LEGENDRE


class TwoGridSolver:
    """Solves ``(c m + A1) x = b`` on ``fine`` with the factors of ``c m + A0`` on ``coarse``.

    ``kept_new``, ``kept_old``, ``fresh``: :func:`core.discretize.shared_panels` of the two
    grids. The coarse panels must be unions of fine ones (the refinements of
    :mod:`core.engines.nystrom.adapt` only cut panels); :meth:`solve` returns ``None`` otherwise.
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
        split = np.nonzero(split)[0]
        self._kn, self._ko = panel_nodes(kept_new), panel_nodes(kept_old)
        self._fn, self._sn = panel_nodes(fresh), panel_nodes(split)
        self._n0 = coarse.size
        # P on the new panels: each new panel's nodes from its coarse parent's.
        parent = panel_index(coarse.panels, fine.panels.centers[fresh])
        keys = _piece_keys(coarse.panels, fine.panels, parent, fresh)
        self._parent = parent
        self._to_fine = np.array([_weights(("piece",) + k, lambda k=k: _to_piece(*k))
                                  for k in keys])  # (new panels, 16, 16)
        # R on the split panels: each coarse node from the new panel that holds it.
        self._to_coarse = []
        for panel in split:
            pieces = fresh[parent == panel]  # contiguous and in order
            key = tuple(k for k, p in zip(keys, parent, strict=True) if p == panel)
            nodes = slice(pieces[0] * NODES_PER_PANEL, (pieces[-1] + 1) * NODES_PER_PANEL)
            self._to_coarse.append((nodes, _weights(("whole",) + key,
                                                    lambda key=key: _to_whole(key))))
        # Runs of contiguous new panels: each a small dense block (32-64 nodes) solved
        # exactly (LAPACK called directly: scipy.linalg's checks cost more than the solve).
        # Blocks of single panel pairs contracted only ~1e-4 per step at a jump.
        runs = np.split(fresh, np.nonzero(np.diff(fresh) > 1)[0] + 1)
        self._blocks = []
        for run in runs:
            nodes = slice(run[0] * NODES_PER_PANEL, (run[-1] + 1) * NODES_PER_PANEL)
            block = fine.operator[nodes, nodes].copy()
            block.flat[::block.shape[0] + 1] += self._diagonal[nodes]
            lu, pivots, info = dgetrf(block, overwrite_a=True)
            if info != 0:
                self.nested = False  # singular block: leave it to the dense factors
                return
            self._blocks.append((nodes, lu, pivots))

    def _apply(self, x: np.ndarray) -> np.ndarray:
        return self._fine.operator @ x + self._diagonal[:, None] * x

    def _step(self, residual: np.ndarray) -> np.ndarray:
        """One application of the two-grid preconditioner to residuals (N1, k)."""
        k = residual.shape[1]
        restricted = np.empty((self._n0, k))
        restricted[self._ko] = residual[self._kn]
        restricted[self._sn] = np.vstack([weights @ residual[nodes]
                                          for nodes, weights in self._to_coarse])
        coarse = self._coarse_factor.rough_solve(restricted)
        z = np.empty_like(residual)
        z[self._kn] = coarse[self._ko]
        per_panel = coarse.reshape(-1, NODES_PER_PANEL, k)[self._parent]
        z[self._fn] = np.matmul(self._to_fine, per_panel).reshape(-1, k)
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
        :class:`core.engines.nystrom.NodalLU` does) is below a tenth of the operator's accuracy,
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
