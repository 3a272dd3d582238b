"""Orthonormal bases for the inner product <u, v> = int u v / m dx on [-1, 1].

The projection method expands the smooth part of ``m q`` in functions orthonormal for
the weight ``1/m`` (the seed's ``p_j``). The seed builds them from Hankel determinants
of the moments ``J_i``, which loses about a digit per function. Here they come from the
discretized Stieltjes procedure (Gautschi 2004): three-term recurrence coefficients are
generated on the composite quadrature rule itself, with a second Gram-Schmidt pass, so
orthonormality holds to ~1e-15 with hundreds of functions.

Two bases are offered:

``global``   polynomials on [-1, 1] (the seed's basis). Where ``m`` or ``g`` jumps, ``m q``
             has an ``(x - x_j) ln|x - x_j|`` term at the jump and the expansion converges
             only algebraically (about n^-3 in the settlement).
``piecewise`` polynomials on each interval between the jumps, joined into one basis whose
             first two functions are the global ``p_0 ~ 1`` and ``p_1 ~ x - J1/J0`` (the
             structure the four statements need). The singular term then sits at an
             interval *end*, where polynomial approximation converges twice as fast, and
             the jump itself costs nothing.

Functions are ordered so that the first ``n`` of a basis are the best ``n`` to keep
(degree scaled by the interval length), hence the bases are nested and truncation to
``n`` is simply taking the first ``n`` columns.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from core.quadrature import Panels


@dataclass(frozen=True)
class Recurrence:
    """Orthonormal polynomials on ``[lo, hi]`` by ``p_{k+1} = ((x - a_k) p_k - b_k p_{k-1}) / b_{k+1}``."""

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


def build_basis(panels: Panels, m_values: np.ndarray, count: int, *,
                breakpoints: Sequence[float] = (), kind: str = "piecewise") -> Basis:
    """An orthonormal basis of ``count`` functions for the weight ``1/m`` on ``panels``.

    ``m_values`` are ``m`` at the panel nodes (dimensionless coating compliance, > 0).
    ``kind`` is ``"global"`` (polynomials on [-1, 1]) or ``"piecewise"`` (polynomials on
    each interval between ``breakpoints``; identical to global when there are none).
    """
    x = panels.nodes
    wm = panels.weights / m_values
    j0, j1, j2 = (float(np.sum(wm * x**i)) for i in range(3))
    cuts = [-1.0] + sorted(float(b) for b in breakpoints) + [1.0]
    if kind == "global" or len(cuts) == 2:
        rec, vals = stieltjes(x, wm, count, -1.0, 1.0)
        transform = np.eye(count)
        # Fix signs so p_0 > 0 and p_1 increases, as in the seed.
        signs = np.ones(count)
        if vals[:, 0].mean() < 0:
            signs[0] = -1
        if count > 1 and np.dot(wm * x, vals[:, 1]) < 0:
            signs[1] = -1
        transform = transform * signs[None, :]
        basis_vals = vals * signs[None, :]
        err = _orthonormality_error(basis_vals, wm)
        return Basis("global", basis_vals, (rec,), (count,), transform, (j0, j1, j2), err)
    if kind != "piecewise":
        raise ValueError(f"basis: unknown kind {kind!r} (expected 'global' or 'piecewise')")

    # Per-interval orthonormal polynomials, enough of each to fill `count` after ordering.
    lengths = np.diff(cuts)
    recs: list[Recurrence] = []
    piece_vals: list[np.ndarray] = []
    counts: list[int] = []
    order_keys: list[tuple[float, int, int]] = []
    for k, (lo, hi) in enumerate(zip(cuts[:-1], cuts[1:], strict=True)):
        inside = (x > lo) & (x < hi)
        n_k = int(min(inside.sum(), np.ceil(count * lengths[k] / 2.0) + 4))
        rec, vals_in = stieltjes(x[inside], wm[inside], n_k, lo, hi)
        full = np.zeros((len(x), n_k))
        full[inside] = vals_in
        recs.append(rec)
        piece_vals.append(full)
        counts.append(n_k)
        order_keys.extend(((d + 0.5) / lengths[k], k, d) for d in range(n_k))
    raw = np.concatenate(piece_vals, axis=1)
    offsets = np.concatenate([[0], np.cumsum(counts)])
    order = [offsets[k] + d for _, k, d in sorted(order_keys)]

    # Gram-Schmidt in the weighted inner product: 1 and x first, then the ordered pieces.
    n_raw = raw.shape[1]
    coef_1 = raw.T @ wm  # coefficients of the function 1 in the raw (orthonormal) pieces
    coef_x = raw.T @ (wm * x)
    chosen: list[np.ndarray] = []
    for candidate in [coef_1, coef_x] + [np.eye(n_raw)[i] for i in order]:
        if len(chosen) == count:
            break
        v = candidate.copy()
        norm0 = np.linalg.norm(v)
        for _ in range(2):
            for c in chosen:
                v -= np.dot(c, v) * c
        norm = np.linalg.norm(v)
        if norm < 1e-10 * norm0:
            continue  # already in the span (the constants and linears of the pieces)
        chosen.append(v / norm)
    if len(chosen) < count:
        raise ValueError(f"basis: only {len(chosen)} independent functions on this grid")
    transform = np.array(chosen).T
    if np.dot(coef_x, transform[:, 1]) < 0:
        transform[:, 1] *= -1
    basis_vals = raw @ transform
    err = _orthonormality_error(basis_vals, wm)
    return Basis("piecewise", basis_vals, tuple(recs), tuple(counts), transform, (j0, j1, j2),
                 err)


def _orthonormality_error(values: np.ndarray, weights: np.ndarray) -> float:
    gram = values.T @ (weights[:, None] * values)
    return float(np.max(np.abs(gram - np.eye(values.shape[1]))))
