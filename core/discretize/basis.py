"""Orthonormal bases for the inner product <u, v> = int u v / m dx on [-1, 1].

The projection method expands the smooth part of ``m q`` in functions orthonormal for
the weight ``1/m`` (the seed's ``p_j``). The seed builds them from Hankel determinants
of the moments ``J_i``, which loses about a digit per function. Here they come from the
discretized Stieltjes procedure (Gautschi 2004): three-term recurrence coefficients are
generated on the composite quadrature rule itself, with a second Gram-Schmidt pass, so
orthonormality holds to ~1e-15 with hundreds of functions.

Three bases are offered:

``global``   polynomials on [-1, 1] (the seed's basis). Where ``m`` or ``g`` jumps, ``m q``
             has an ``(x - x_j) ln|x - x_j|`` term at the jump and the expansion converges
             only algebraically (about n^-3 in the settlement).
``piecewise`` polynomials on each interval between the jumps, joined into one basis whose
             first two functions are the global ``p_0 ~ 1`` and ``p_1 ~ x - J1/J0`` (the
             structure the four statements need). The singular term then sits at an
             interval *end*, where polynomial approximation converges twice as fast, and
             the jump itself costs nothing.
``graded``   hp-FEM: continuous piecewise polynomials (degree <= 15) on a mesh graded
             geometrically toward +-1 and every breakpoint (:func:`graded_cuts`), with
             degrees growing away from them. ``m q`` has ``(x - x_e) ln|x - x_e|`` and an
             edge layer of width ~m at each such point; this basis converges geometrically
             in the settlement, tilt *and* the pressure on the whole of [-1, 1], edges
             included (measured, m = 0.05: pressure 5.3e-4 / 7.8e-6 / 3.0e-7 / 6e-10 at
             64 / 128 / 192 / 512 functions; on interior points only, ``global`` is still
             1.4e-6 off at 192). Its functions have kinks at the
             element ends, so the Galerkin form needs
             :func:`core.discretize.galerkin_correction` on panels broken at the ends.

Functions are ordered so that the first ``n`` of a basis are the best ``n`` to keep
(degree scaled by the interval length), hence the bases are nested and truncation to
``n`` is simply taking the first ``n`` columns.

This module builds the global and piecewise bases (:func:`build_basis`); the recurrences
and the :class:`Basis` value are in :mod:`core.discretize.basis_pieces`, the graded basis and its
mesh in :mod:`core.discretize.graded_basis`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from core.discretize.basis_pieces import Basis, Recurrence, orthonormality_error, stieltjes
from core.discretize.graded_basis import (
    graded_basis,
)
from core.discretize.panels import Panels


def build_basis(panels: Panels, m_values: np.ndarray, count: int, *,
                breakpoints: Sequence[float] = (), kind: str = "piecewise",
                cuts: Sequence[float] = ()) -> Basis:
    """An orthonormal basis of ``count`` functions for the weight ``1/m`` on ``panels``.

    ``m_values`` are ``m`` at the panel nodes (dimensionless coating compliance, > 0).
    ``kind`` is ``"global"`` (polynomials on [-1, 1]), ``"piecewise"`` (polynomials on
    each interval between ``breakpoints``; identical to global when there are none) or
    ``"graded"`` (hp-graded piecewise polynomials on the elements between ``breakpoints``
    and the soft ``cuts`` of :func:`graded_cuts`; ``panels`` must break at all of them).
    """
    if kind not in ("global", "piecewise", "graded"):
        raise ValueError(f"basis: unknown kind {kind!r} "
                         "(expected 'global', 'piecewise' or 'graded')")
    x = panels.nodes
    wm = panels.weights / m_values
    j0, j1, j2 = (float(np.sum(wm * x**i)) for i in range(3))
    if kind == "graded":
        return graded_basis(panels, wm, count, breakpoints, cuts, (j0, j1, j2))
    ends = [-1.0] + sorted(float(b) for b in breakpoints) + [1.0]
    if kind == "global" or len(ends) == 2:
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
        err = orthonormality_error(basis_vals, wm)
        return Basis("global", basis_vals, (rec,), (count,), transform, (j0, j1, j2), err)
    # Per-interval orthonormal polynomials, enough of each to fill `count` after ordering.
    lengths = np.diff(ends)
    recs: list[Recurrence] = []
    piece_vals: list[np.ndarray] = []
    counts: list[int] = []
    order_keys: list[tuple[float, int, int]] = []
    for k, (lo, hi) in enumerate(zip(ends[:-1], ends[1:], strict=True)):
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
    err = orthonormality_error(basis_vals, wm)
    return Basis("piecewise", basis_vals, tuple(recs), tuple(counts), transform, (j0, j1, j2),
                 err)

