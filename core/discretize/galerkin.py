"""The Galerkin correction of the projection method on composite Gauss-Legendre panels.

The Galerkin form ``int v F u`` is the rule's sum ``sum_i w_i v(x_i) (F u)(x_i)`` of
:mod:`core.discretize.quadrature`, exact in the inner integral only. :func:`galerkin_correction`
makes the outer one exact as well for panel-wise polynomials of degree <= 15, which a
basis with kinks or jumps at panel ends (``"graded"`` in :mod:`core.discretize.basis`)
needs; with it no panel grading is needed at all. The Nystrom engine does not use it.
"""

from __future__ import annotations

import numpy as np
from numpy.polynomial import legendre as npleg

from core.discretize.panels import (
    GAUSS_NODES,
    GAUSS_WEIGHTS,
    NODES_PER_PANEL,
    VALUES_TO_LEGENDRE,
    Panels,
)
from core.kernel import legendre_log_moments

#: Dyadic levels of the outer rule of :func:`galerkin_correction` toward a singular end:
#: the last piece, 2^-24 of the panel, holds ~1e-17 of an ``s ln s`` integrand.
_OUTER_LEVELS = 24


def _outer_rule(left: bool, right: bool) -> tuple[np.ndarray, np.ndarray]:
    """Composite 16-point Gauss rule on [-1, 1], graded dyadically toward flagged ends."""
    segments: list[tuple[float, float]] = []
    if left and right:
        for side in (-1.0, 1.0):
            pts = [0.0] + [side * (1.0 - 0.5**k) for k in range(1, _OUTER_LEVELS)] + [side]
            segments += [(min(p, q), max(p, q)) for p, q in zip(pts[:-1], pts[1:], strict=True)]
    else:
        side = 1.0 if right else -1.0
        pts = [-side] + [side * (1.0 - 2.0 * 0.5**k) for k in range(1, _OUTER_LEVELS)] + [side]
        segments = [(min(p, q), max(p, q)) for p, q in zip(pts[:-1], pts[1:], strict=True)]
    lo = np.array([s[0] for s in segments])
    hi = np.array([s[1] for s in segments])
    nodes = (0.5 * (lo + hi)[:, None] + 0.5 * (hi - lo)[:, None] * GAUSS_NODES[None, :]).ravel()
    weights = (0.5 * (hi - lo)[:, None] * GAUSS_WEIGHTS[None, :]).ravel()
    return nodes, weights


def galerkin_correction(panels: Panels, *, reach: float = 1.0) -> np.ndarray:
    """Correction ``C`` (N x N) that makes ``v^T (diag(w) F + C) u`` an exact double integral.

    The Galerkin form ``int int k(x - xi) v(x) u(xi) dx dxi`` of the projection method is
    computed as ``sum_i w_i v(x_i) (F u)(x_i)``: exact in ``xi`` (product integration) but
    Gauss in ``x``. Where ``u`` has a jump or a kink at a panel end (a basis that is
    piecewise across panels, e.g. the ``"graded"`` basis of :mod:`core.discretize.basis`), ``F u``
    has ``(x - c)^k ln|x - c|`` terms there and the outer Gauss rule on the neighbouring
    panels loses ~5 digits (measured: Galerkin entries off by 2e-2 of 9). ``C`` replaces,
    for every pair of panels closer than ``reach`` half-widths of the target panel (itself
    included), the log part of the block by its exact value for the panels' degree-15
    interpolants: the inner integral by Legendre log moments, the outer one by a Gauss rule
    graded toward the singular ends. The smooth part of the kernel needs no correction.
    Depends on the panels only (not on lam); about 0.15 s for 30 panels.
    """
    n = panels.size
    out = np.zeros((n, n))
    c, h = panels.centers, panels.half_widths
    lo, hi = c - h, c + h
    gap = np.maximum(np.maximum(lo[None, :] - hi[:, None], lo[:, None] - hi[None, :]), 0.0)
    near = gap <= reach * h[:, None]  # [target panel, source panel]
    targets, sources = np.nonzero(near)
    kinds = np.where(targets == sources, 0, np.where(c[sources] > c[targets], 1, -1))
    vander = {}
    for kind in (0, 1, -1):
        sel = kinds == kind
        if not sel.any():
            continue
        s, ws = _outer_rule(kind <= 0, kind >= 0)
        if kind not in vander:
            vander[kind] = npleg.legvander(s, NODES_PER_PANEL - 1) * ws[:, None]
        p, q = targets[sel], sources[sel]
        z = (c[p, None] + h[p, None] * s[None, :] - c[q, None]) / h[q, None]
        moments = legendre_log_moments(z.ravel(), NODES_PER_PANEL - 1).reshape(
            len(p), len(s), NODES_PER_PANEL)
        # int_Q ln|x - xi| P_b dxi = h_q (2 ln h_q delta_b0 + M_b(z))
        inner = h[q, None, None] * moments
        inner[:, :, 0] += (2.0 * h[q] * np.log(h[q]))[:, None]
        exact_coef = h[p, None, None] * np.einsum("ka,pkb->pab", vander[kind], inner)
        exact = np.einsum("ai,pab,bj->pij", VALUES_TO_LEGENDRE, exact_coef, VALUES_TO_LEGENDRE)
        # What diag(w) F holds there: the target panel's Gauss rule times the exact inner
        # integral (log_product_weights, batched over the pairs).
        x_t = panels.nodes.reshape(-1, NODES_PER_PANEL)[p]
        z_t = (x_t - c[q, None]) / h[q, None]
        m_t = legendre_log_moments(z_t.ravel(), NODES_PER_PANEL - 1).reshape(
            len(p), NODES_PER_PANEL, NODES_PER_PANEL)
        inner_t = h[q, None, None] * (np.log(h[q])[:, None, None] * GAUSS_WEIGHTS[None, None, :]
                                      + m_t @ VALUES_TO_LEGENDRE)
        approx = panels.weights.reshape(-1, NODES_PER_PANEL)[p][:, :, None] * inner_t
        block = -(exact - approx) / np.pi
        for k in range(len(p)):
            rows = slice(p[k] * NODES_PER_PANEL, (p[k] + 1) * NODES_PER_PANEL)
            cols = slice(q[k] * NODES_PER_PANEL, (q[k] + 1) * NODES_PER_PANEL)
            out[rows, cols] = block[k]
    return out
