"""The bordered systems of the nodal active set, and their solver that keeps factors.

On the contact nodes ``idx`` of a panel rule (q = 0 elsewhere) one solve is

    (c m + s F) q - delta - alpha x = rhs   on idx,   int q = P,  int x q = M

with the unknown ones of delta, alpha as border columns and the given ones of P, M as
border rows (:func:`bordered_solve`). :class:`StepSolver` carries the LU factors from one
creep step to the next.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.linalg import lu_factor
from scipy.linalg.lapack import dgetrs


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

    def __init__(self) -> None:
        self._key: tuple | None = None
        self._lu = None
        self._sub: np.ndarray | None = None  # F on the contact nodes of _key
        self._last: np.ndarray | None = None  # the last solution with these factors
        self.factorizations = 0
        self.back_substitutions = 0

    def submatrix(self, op: np.ndarray, idx: np.ndarray, key: tuple) -> np.ndarray:
        """``op`` restricted to the nodes ``idx`` (kept while the contact nodes stay)."""
        if self._key != key or self._sub is None:
            self._sub = op[np.ix_(idx, idx)]
            self._key = key
            self._lu = None
            self._last = None
        return self._sub

    def _back(self, r: np.ndarray) -> np.ndarray:
        # LAPACK directly: the checked wrapper costs more than the O(N^2) solve here.
        x, _ = dgetrs(self._lu[0], self._lu[1], r)
        return x

    def solve(self, build: Callable[[], np.ndarray], apply: Callable[[np.ndarray], np.ndarray],
              b: np.ndarray) -> np.ndarray:
        """Solve ``A x = b`` for the matrix ``build()`` whose product is ``apply``.

        The refinement starts from the last solution on the same contact nodes (the next
        step's is close to it) and stops at a residual of ``_RESIDUAL`` relative to ``b``.
        """
        if self._lu is None and self._sub is not None and self._last is not None:
            self._lu = lu_factor(build(), check_finite=False)
            self.factorizations += 1
        if self._lu is not None:
            scale = max(float(np.abs(b).max()), 1e-300)
            x = self._last if self._last is not None else self._back(b)
            for count in range(self._REFINE_STEPS):
                r = b - apply(x)
                if float(np.abs(r).max()) <= self._RESIDUAL * scale:
                    self._last = x
                    if count > self.REFRESH_AFTER:
                        self._lu = None  # c/s has drifted: new factors next time
                    return x
                x = x + self._back(r)
                self.back_substitutions += 1
        self._lu = lu_factor(build(), check_finite=False)
        self.factorizations += 1
        self._last = self._back(b)
        return self._last


def bordered_solve(op: np.ndarray, m: np.ndarray, x: np.ndarray, w: np.ndarray, c: float,
                   scale: float, given: dict[str, float], rhs: np.ndarray, idx: np.ndarray,
                   solver: StepSolver | None = None) -> tuple[np.ndarray, float, float]:
    """Solve the equation on the nodes ``idx`` (q = 0 elsewhere) with the given loads.

    Returns (q on idx, settlement, tilt). ``rhs`` = ``delta_g + alpha_g x - g + e`` at all
    nodes (with the given ones of delta, alpha; 0 for the unknown ones).
    """
    n = idx.size
    cols, rows, extra = [], [], []
    if "settlement" not in given:
        cols.append(-np.ones(n))
    if "tilt" not in given:
        cols.append(-x[idx])
    if "force" in given:
        rows.append(w[idx])
        extra.append(given["force"])
    if "moment" in given:
        rows.append(w[idx] * x[idx])
        extra.append(given["moment"])
    k = len(cols)
    border_cols = np.array(cols).T.reshape(n, k)
    border_rows = np.array(rows).reshape(k, n)
    key = (idx.tobytes(), tuple(sorted(given)))
    sub = op[np.ix_(idx, idx)] if solver is None else solver.submatrix(op, idx, key)
    # Divided by the weight s of F, the system depends on c and s only through c/s (and
    # the border unknowns come out divided by s): kept factors then precondition the
    # next steps up to the change of c/s alone.
    diagonal = (c / scale) * m[idx]

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

    b = np.concatenate([rhs[idx] / scale, extra])
    sol = np.linalg.solve(build(), b) if solver is None else solver.solve(build, apply, b)
    sol[n:] *= scale
    tail = list(sol[n:])
    delta = tail.pop(0) if "settlement" not in given else given["settlement"]
    alpha = tail.pop(0) if "tilt" not in given else given["tilt"]
    return sol[:n], float(delta), float(alpha)
