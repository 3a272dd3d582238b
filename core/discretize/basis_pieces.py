"""The pieces every basis is built from, for the inner product int u v / m dx.

Orthonormal polynomials on one interval by the discretized Stieltjes procedure
(:class:`Recurrence`, :func:`stieltjes`), the :class:`Basis` value that joins them into
one basis on [-1, 1], and its orthonormality check. The bases themselves are built by
:mod:`core.discretize.basis` (global and piecewise) and
:mod:`core.discretize.graded_basis` (hp-graded).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Recurrence:
    """Orthonormal polynomials on ``[lo, hi]``.

    Recurrence ``p_{k+1} = ((x - a_k) p_k - b_k p_{k-1}) / b_{k+1}``.
    """

    lo: float
    hi: float
    a: np.ndarray
    b: np.ndarray  # b[0] = sqrt(total mass), b[k] for k >= 1 the recurrence norms

    def evaluate(self, x: np.ndarray, count: int) -> np.ndarray:
        """Values (len(x), count) at ``x``; zero outside ``[lo, hi]``."""
        x = np.asarray(x, dtype=float)
        out = np.zeros((x.size, count))
        inside = (x >= self.lo) & (x <= self.hi)
        xi = x[inside]
        p_prev = np.zeros(xi.size)
        p = np.full(xi.size, 1.0 / self.b[0])
        vals = np.empty((xi.size, count))
        for k in range(count):
            vals[:, k] = p
            if k + 1 < count:
                p_next = ((xi - self.a[k]) * p - self.b[k] * p_prev) / self.b[k + 1]
                p_prev, p = p, p_next
        out[inside] = vals
        return out


def stieltjes(nodes: np.ndarray, weights: np.ndarray, count: int, lo: float,
              hi: float) -> tuple[Recurrence, np.ndarray]:
    """Discretized Stieltjes procedure for the discrete measure ``sum w_a delta(x - x_a)``.

    Returns the recurrence and the values ``V`` (len(nodes), count) of the orthonormal
    polynomials at the nodes, with ``V.T @ diag(weights) @ V = I`` to round-off.
    """
    if count > len(nodes):
        raise ValueError(f"count: at most {len(nodes)} functions on this rule, got {count}")
    total = float(weights.sum())
    vals = np.empty((len(nodes), count))
    a = np.zeros(count)
    b = np.zeros(count + 1)
    b[0] = np.sqrt(total)
    vals[:, 0] = 1.0 / b[0]
    for k in range(count - 1):
        pk = vals[:, k]
        a[k] = np.dot(weights * nodes * pk, pk)
        u = (nodes - a[k]) * pk - (b[k] * vals[:, k - 1] if k > 0 else 0.0)
        # Second Gram-Schmidt pass: keeps orthogonality at machine precision.
        for _ in range(2):
            u = u - vals[:, : k + 1] @ (vals[:, : k + 1].T @ (weights * u))
        b[k + 1] = np.sqrt(np.dot(weights * u, u))
        vals[:, k + 1] = u / b[k + 1]
    if count >= 1:
        pk = vals[:, count - 1]
        a[count - 1] = np.dot(weights * nodes * pk, pk)
    return Recurrence(lo, hi, a, b), vals


@dataclass(frozen=True)
class Basis:
    """Orthonormal functions for the weight ``1/m`` and their values at the quadrature nodes.

    ``values`` (N, n) are ``p_j(x_a)``; ``evaluate(x)`` gives them anywhere in [-1, 1].
    ``moments`` holds ``J_0, J_1, J_2`` (``J_i = int x^i / m dx``). The first function is
    ``1/sqrt(J_0)`` and the second ``(x - J_1/J_0)/sqrt((J_0 J_2 - J_1^2)/J_0)``.
    """

    kind: str
    values: np.ndarray
    pieces: tuple[Recurrence, ...]
    piece_counts: tuple[int, ...]
    transform: np.ndarray  # (sum of piece counts, n): basis = [piece values] @ transform
    moments: tuple[float, float, float]
    orthonormality_error: float

    @property
    def size(self) -> int:
        return self.values.shape[1]

    def evaluate(self, x: np.ndarray, count: int | None = None) -> np.ndarray:
        """Values (len(x), count) of the first ``count`` basis functions at ``x``."""
        count = self.size if count is None else count
        x = np.atleast_1d(np.asarray(x, dtype=float))
        raw = np.concatenate(
            [rec.evaluate(x, c) for rec, c in zip(self.pieces, self.piece_counts, strict=True)],
            axis=1,
        )
        # A point on a breakpoint belongs to two pieces; average their one-sided values.
        cover = np.zeros(x.size)
        for rec in self.pieces:
            cover += (x >= rec.lo) & (x <= rec.hi)
        return (raw @ self.transform[:, :count]) / np.maximum(cover, 1.0)[:, None]


def orthonormality_error(values: np.ndarray, weights: np.ndarray) -> float:
    """Largest entry of ``V^T diag(w) V - I`` for the basis values ``V`` (N, n) at nodes
    with weights ``w / m`` (dimensionless): how far the basis is from orthonormal."""
    gram = values.T @ (weights[:, None] * values)
    return float(np.max(np.abs(gram - np.eye(values.shape[1]))))

