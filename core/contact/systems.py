"""The bordered systems of the nodal active set, and their solver that keeps factors.

On the contact nodes ``idx`` of a panel rule (q = 0 elsewhere) one solve is

    (c m + s F) q - delta - alpha x = rhs   on idx,   int q = P,  int x q = M

with the unknown ones of delta, alpha as border columns and the given ones of P, M as
border rows (:func:`bordered_solve`). :class:`StepSolver` carries the LU factors from one
creep step to the next.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from scipy.linalg import lu_factor
from scipy.linalg.lapack import dgetrs


def restrict(op: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """``op`` on the nodes ``idx`` (sorted): a view when they are one run of nodes (one
    contact zone, the usual case: no copy of the block), a copy otherwise."""
    if idx.size and int(idx[-1]) - int(idx[0]) + 1 == idx.size:
        return op[idx[0]:idx[-1] + 1, idx[0]:idx[-1] + 1]
    return op[np.ix_(idx, idx)]


class StepSolver:
    """Solves the bordered systems of one panel rule, keeping the last factorization.

    Consecutive creep steps change only ``c`` and ``scale`` by a little, and the contact
    set rarely: the kept LU factors of the last matrix with the same contact nodes
    precondition a few steps of iterative refinement (each O(N^2)) instead of a new
    factorization (O(N^3)); a new one is made when the refinement does not converge
    within ``_REFINE_STEPS`` steps.
    """

    _REFINE_STEPS = 12
    _RESIDUAL = 1e-13
    REFRESH_AFTER = 6
    CHANGE_RESIDUAL = 1e-9
    #: start the refinement from the line through the last two solutions
    EXTRAPOLATE = True

    def __init__(self) -> None:
        self._key: tuple | None = None
        self._lu = None
        self._sub: np.ndarray | None = None  # F on the contact nodes of _key
        self._last: np.ndarray | None = None  # the last solution with these factors
        self._prev: np.ndarray | None = None  # the one before it (same contact nodes)
        self.factorizations = 0
        self.back_substitutions = 0

    def submatrix(self, op: np.ndarray, idx: np.ndarray, key: tuple) -> np.ndarray:
        """``op`` restricted to the nodes ``idx`` (kept while the contact nodes stay)."""
        if self._key != key or self._sub is None:
            self._sub = restrict(op, idx)
            self._key = key
            self._lu = None
            self._last = None
            self._prev = None
        return self._sub

    def snapshot(self) -> StepSolver:
        """A solver holding this one's current factors and contact nodes (shared, not
        copied: a new factorization replaces them here, never changes them), so that a
        change on this step (:func:`bordered_change`) can be solved after later steps."""
        kept = StepSolver()
        kept._key, kept._lu, kept._sub, kept._last = self._key, self._lu, self._sub, self._last
        return kept

    def _back(self, r: np.ndarray) -> np.ndarray:
        # LAPACK directly: the checked wrapper costs more than the O(N^2) solve here.
        x, _ = dgetrs(self._lu[0], self._lu[1], r)
        return x

    def solve(self, build: Callable[[], np.ndarray], apply: Callable[[np.ndarray], np.ndarray],
              b: np.ndarray) -> np.ndarray:
        """Solve ``A x = b`` for the matrix ``build()`` whose product is ``apply``.

        The refinement starts from the last solution on the same contact nodes (the next
        step's is close to it; extrapolated from the last two when there are two) and
        stops at a residual of ``_RESIDUAL`` relative to ``b``.
        """
        if self._lu is None and self._sub is not None and self._last is not None:
            self._factor(build)
        if self._lu is not None:
            scale = max(float(np.abs(b).max()), 1e-300)
            if self._last is None:
                x = self._back(b)
            elif self._prev is not None and self.EXTRAPOLATE:
                # the solutions of successive steps change smoothly: their line starts
                # the refinement closer than the last alone (in the 202-step march of
                # the lift-off preset 816 -> 728 back-substitutions)
                x = 2.0 * self._last - self._prev
            else:
                x = self._last
            for count in range(self._REFINE_STEPS):
                r = b - apply(x)
                if float(np.abs(r).max()) <= self._RESIDUAL * scale:
                    self._prev, self._last = self._last, x
                    if count > self.REFRESH_AFTER:
                        self._lu = None  # c/s has drifted: new factors next time
                    return x
                x = x + self._back(r)
                self.back_substitutions += 1
        self._factor(build)
        self._last = self._back(b)
        self._prev = None
        return self._last

    def _factor(self, build: Callable[[], np.ndarray]) -> None:
        self._lu = lu_factor(build(), check_finite=False)
        self.factorizations += 1

    def solve_change(self, build: Callable[[], np.ndarray],
                     apply: Callable[[np.ndarray], np.ndarray], b: np.ndarray) -> np.ndarray:
        """Solve ``A x = b`` for a small change ``b`` of a right-hand side just solved on
        the same contact nodes: refinement from zero with the kept factors to a residual
        of ``CHANGE_RESIDUAL`` relative to ``b`` (the change is itself small, so its
        error enters the total far below ``_RESIDUAL`` of it). The last solution and the
        factors are left as they were for the next step (new factors are kept only when
        there were none)."""
        if self._lu is None:
            self._factor(build)
        scale = max(float(np.abs(b).max()), 1e-300)
        x = self._back(b)
        self.back_substitutions += 1
        for _ in range(self._REFINE_STEPS):
            r = b - apply(x)
            if float(np.abs(r).max()) <= self.CHANGE_RESIDUAL * scale:
                return x
            x = x + self._back(r)
            self.back_substitutions += 1
        # the kept factors no longer precondition well (c/s drifted): exact ones
        return np.linalg.solve(build(), b)


def bordered_operator(sub: np.ndarray, diagonal: np.ndarray, border_cols: np.ndarray,
                      border_rows: np.ndarray
                      ) -> tuple[Callable[[], np.ndarray], Callable[[np.ndarray], np.ndarray]]:
    """``build()``, the bordered matrix ``[[diag + sub, cols], [rows, 0]]``, and
    ``apply(z)``, its product with ``z`` without building it (the refinement of
    :meth:`StepSolver.solve` needs only products)."""
    n, k = sub.shape[0], border_cols.shape[1]

    def build() -> np.ndarray:
        a = np.zeros((n + k, n + k))
        a[:n, :n] = sub
        a[np.arange(n), np.arange(n)] += diagonal
        a[:n, n:] = border_cols
        a[n:, :n] = border_rows
        return a

    def apply(z: np.ndarray) -> np.ndarray:
        zq = z[:n]
        top = diagonal * zq + sub @ zq + border_cols @ z[n:]
        return np.concatenate([top, border_rows @ zq])

    return build, apply


def _bordered_system(op: np.ndarray, m: np.ndarray, x: np.ndarray, w: np.ndarray, c: float,
                     scale: float, given: Sequence[str], idx: np.ndarray,
                     solver: StepSolver | None):
    """(build, apply, key, unknown border names) of the system on ``idx``, divided by
    ``scale``: see :func:`bordered_solve`."""
    n = idx.size
    cols, rows = [], []
    if "settlement" not in given:
        cols.append(-np.ones(n))
    if "tilt" not in given:
        cols.append(-x[idx])
    if "force" in given:
        rows.append(w[idx])
    if "moment" in given:
        rows.append(w[idx] * x[idx])
    k = len(cols)
    border_cols = np.array(cols).T.reshape(n, k)
    border_rows = np.array(rows).reshape(k, n)
    key = (idx.tobytes(), tuple(sorted(given)))
    sub = restrict(op, idx) if solver is None else solver.submatrix(op, idx, key)
    # Divided by the weight s of F, the system depends on c and s only through c/s (and
    # the border unknowns come out divided by s): kept factors then precondition the
    # next steps up to the change of c/s alone.
    diagonal = (c / scale) * m[idx]
    return bordered_operator(sub, diagonal, border_cols, border_rows)


def bordered_solve(op: np.ndarray, m: np.ndarray, x: np.ndarray, w: np.ndarray, c: float,
                   scale: float, given: dict[str, float], rhs: np.ndarray, idx: np.ndarray,
                   solver: StepSolver | None = None) -> tuple[np.ndarray, float, float]:
    """Solve the equation on the nodes ``idx`` (q = 0 elsewhere) with the given loads.

    Returns (q on idx, settlement, tilt). ``rhs`` = ``delta_g + alpha_g x - g + e`` at all
    nodes (with the given ones of delta, alpha; 0 for the unknown ones).
    """
    build, apply = _bordered_system(op, m, x, w, c, scale, tuple(given), idx, solver)
    extra = [given[name] for name in ("force", "moment") if name in given]
    b = np.concatenate([rhs[idx] / scale, extra])
    sol = np.linalg.solve(build(), b) if solver is None else solver.solve(build, apply, b)
    return _unpack(sol, idx.size, scale, given)


def bordered_change(op: np.ndarray, m: np.ndarray, x: np.ndarray, w: np.ndarray, c: float,
                    scale: float, given: dict[str, float], rhs: np.ndarray,
                    idx: np.ndarray, solver: StepSolver) -> tuple[np.ndarray, float, float]:
    """The change of :func:`bordered_solve`'s answer when its ``rhs`` and given loads
    change by ``rhs`` and ``given`` (the system is linear; given settlement or tilt change
    by their entries), solved with the kept factors of ``solver`` to a residual of
    ``StepSolver.CHANGE_RESIDUAL`` of the change, and leaving its state for the next step.
    Returns (change of q on idx, of the settlement, of the tilt)."""
    build, apply = _bordered_system(op, m, x, w, c, scale, tuple(given), idx, solver)
    extra = [given[name] for name in ("force", "moment") if name in given]
    b = np.concatenate([rhs[idx] / scale, extra])
    return _unpack(solver.solve_change(build, apply, b), idx.size, scale, given)


def _unpack(sol: np.ndarray, n: int, scale: float, given: dict[str, float]
            ) -> tuple[np.ndarray, float, float]:
    tail = list(sol[n:] * scale)
    delta = tail.pop(0) if "settlement" not in given else given["settlement"]
    alpha = tail.pop(0) if "tilt" not in given else given["tilt"]
    return sol[:n], float(delta), float(alpha)
