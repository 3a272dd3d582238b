"""Composite Gauss-Legendre panels and the discrete layer operator F.

The operator of the model is

    (F phi)(x) = int_{-1}^{1} k(x - xi) phi(xi) dxi,   k(d) = k_pl(lam d) / pi,

with ``k_pl(s) = -ln|s| + k_reg(s)`` (``k_reg`` smooth, see :mod:`core.kernel`). On each
panel the density is represented by its Legendre interpolant on 16 Gauss nodes; the log
part is integrated *exactly* against that interpolant (product integration, using
``int_{-1}^{1} ln|z - t| P_n(t) dt = 2 [Q_{n+1}(z) - Q_{n-1}(z)] / (2n + 1)``) whenever the
target lies within four half-widths of the panel centre, and by the plain Gauss rule
farther away, where the log is analytic in a Bernstein ellipse with rho >= 7.9 and the
plain rule is accurate to ~1e-16. The smooth part ``k_reg(lam d)`` has its nearest
complex singularities at ``d = +-2i/lam``, so panels no wider than ``3/lam`` integrate
it to machine precision.

Panels break at every point where the coating compliance ``m`` or the gap ``g`` may
jump, are graded geometrically toward those points and toward ``x = +-1`` (where the
densities and ``F phi`` have end-point behaviour), and are refined adaptively until the
sampled functions are resolved on every panel.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.polynomial import legendre as npleg

from core.kernel import plane_kernel_regular

NODES_PER_PANEL = 16
_T, _W = npleg.leggauss(NODES_PER_PANEL)
# Values P_n(t_j), n < 16, and the interpolation matrix nodes -> Legendre coefficients.
_P = npleg.legvander(_T, NODES_PER_PANEL - 1)  # (16 nodes, 16 degrees)
_TO_COEF = (_P * _W[:, None]).T * (np.arange(NODES_PER_PANEL) + 0.5)[:, None]  # (deg, node)

#: Targets closer than this many half-widths to a panel centre use product integration.
NEAR_FIELD = 4.0


@dataclass(frozen=True)
class Panels:
    """A composite Gauss-Legendre rule on [-1, 1].

    Attributes: ``edges`` (P+1 panel ends), ``nodes`` and ``weights`` (N = 16 P points),
    ``centers`` and ``half_widths`` (P), ``panel_of_node`` (N).
    """

    edges: np.ndarray
    nodes: np.ndarray
    weights: np.ndarray
    centers: np.ndarray
    half_widths: np.ndarray

    @property
    def n_panels(self) -> int:
        return len(self.centers)

    @property
    def size(self) -> int:
        return len(self.nodes)

    @classmethod
    def from_edges(cls, edges: np.ndarray) -> Panels:
        edges = np.asarray(edges, dtype=float)
        centers = 0.5 * (edges[1:] + edges[:-1])
        half = 0.5 * (edges[1:] - edges[:-1])
        nodes = (centers[:, None] + half[:, None] * _T[None, :]).ravel()
        weights = (half[:, None] * _W[None, :]).ravel()
        return cls(edges, nodes, weights, centers, half)

    def integrate(self, values: np.ndarray) -> np.ndarray:
        """Integral over [-1, 1] of node values (first axis), by the composite rule."""
        return np.tensordot(self.weights, values, axes=(0, 0))


def _graded_interval(a: float, b: float, grade_a: bool, grade_b: bool, finest: float,
                     widest: float) -> list[float]:
    """Panel edges on [a, b], geometric (ratio 2) from ``finest`` at graded ends."""
    length = b - a
    left: list[float] = []
    right: list[float] = []
    w = finest
    # Grading from both ends must not overlap: stop each at a third of the interval.
    while grade_a and w < min(widest, length / 3):
        left.append(w)
        w *= 2.0
    w = finest
    while grade_b and w < min(widest, length / 3):
        right.append(w)
        w *= 2.0
    used = sum(left) + sum(right)
    middle = length - used
    n_mid = max(1, int(np.ceil(middle / widest - 1e-9)))
    widths = left + [middle / n_mid] * n_mid + right[::-1]
    edges = a + np.concatenate([[0.0], np.cumsum(widths)])
    edges[-1] = b
    return list(edges)


def base_panels(lam: float, breakpoints: Sequence[float] = (), *, edge_width: float = 1e-4,
                max_width: float = 0.25) -> Panels:
    """Panels on [-1, 1] broken at ``breakpoints`` and graded toward them and toward +-1.

    ``edge_width`` is the width of the finest panel at each graded point; panels are at
    most ``min(max_width, 3/lam)`` wide so the kernel's decay length ``~1/lam`` is resolved.
    """
    widest = min(max_width, 3.0 / lam)
    cuts = [-1.0] + sorted(float(b) for b in breakpoints) + [1.0]
    edges: list[float] = [-1.0]
    for a, b in zip(cuts[:-1], cuts[1:], strict=True):
        sub = _graded_interval(a, b, True, True, min(edge_width, (b - a) / 8), widest)
        edges.extend(sub[1:])
    return Panels.from_edges(np.array(edges))


def refine_to_resolve(panels: Panels, functions: Sequence[Callable[[np.ndarray], np.ndarray]],
                      *, rel_tol: float = 1e-13, min_width: float = 1e-9,
                      max_panels: int = 600) -> tuple[Panels, bool]:
    """Bisect panels until every function's Legendre tail is below ``rel_tol`` of its scale.

    Returns the refined panels and whether everything was resolved within the limits
    (``min_width`` stops the bisection of an undeclared jump, ``max_panels`` bounds the work).
    """
    edges = np.asarray(panels.edges, dtype=float)
    resolved = True
    for _ in range(60):
        current = Panels.from_edges(edges)
        bad = np.zeros(current.n_panels, dtype=bool)
        for f in functions:
            values = np.asarray(f(current.nodes), dtype=float).reshape(current.n_panels, -1)
            scale = float(np.max(np.abs(values))) or 1.0
            coef = values @ _TO_COEF.T  # (panels, degrees)
            tail = np.max(np.abs(coef[:, -3:]), axis=1)
            bad |= tail > rel_tol * scale
        bad &= 2 * current.half_widths > 2 * min_width
        if not bad.any():
            return current, resolved
        if current.n_panels + int(bad.sum()) > max_panels:
            return current, False
        mids = current.centers[bad]
        edges = np.sort(np.concatenate([edges, mids]))
    return Panels.from_edges(edges), False


def legendre_log_moments(z: np.ndarray, degree: int) -> np.ndarray:
    """``M_n(z) = int_{-1}^{1} ln|z - t| P_n(t) dt`` for n = 0..degree (shape (len(z), degree+1)).

    Uses Legendre functions of the second kind ``Q_n``: forward recurrence where it is
    stable (|z| <= 1.05) and Miller's backward recurrence outside, where ``Q_n`` is the
    minimal solution and the forward recurrence loses ~2n log10(|z| + sqrt(z^2 - 1)) digits.
    """
    z = np.asarray(z, dtype=float)
    # M_n is continuous at |z| = 1 but Q_n is not defined there: step just inside.
    z = np.where(np.abs(np.abs(z) - 1.0) < 1e-13, np.sign(z) * (1.0 - 1e-13), z)
    nq = degree + 2
    q = np.empty((z.size, nq))
    with np.errstate(divide="ignore", invalid="ignore"):
        q0 = 0.5 * np.log(np.abs((1.0 + z) / (1.0 - z)))
    inner = np.abs(z) <= 1.05
    if inner.any():
        zi = z[inner]
        qi = np.empty((zi.size, nq))
        qi[:, 0] = q0[inner]
        qi[:, 1] = zi * qi[:, 0] - 1.0
        for n in range(1, nq - 1):
            qi[:, n + 1] = ((2 * n + 1) * zi * qi[:, n] - n * qi[:, n - 1]) / (n + 1)
        q[inner] = qi
    outer = ~inner
    if outer.any():
        zo = np.abs(z[outer])
        rho = zo + np.sqrt(zo * zo - 1.0)
        # Start index so that rho^-2(start - n) < 1e-18 for every needed n.
        start = nq + int(np.ceil(18 * np.log(10) / (2 * np.log(rho.min())))) + 5
        qa = np.zeros(zo.size)
        qb = np.full(zo.size, 1e-280)
        vals = np.empty((zo.size, nq))
        for n in range(start, 0, -1):
            # (n) Q_{n-1} = (2n+1) z Q_n - (n+1) Q_{n+1}
            qc = ((2 * n + 1) * zo * qb - (n + 1) * qa) / n
            qa, qb = qb, qc
            if n - 1 < nq:
                vals[:, n - 1] = qb
            big = np.abs(qb) > 1e250
            if big.any():
                qa[big] *= 1e-250
                qb[big] *= 1e-250
                vals[big] *= 1e-250
        exact0 = 0.5 * np.log((zo + 1.0) / (zo - 1.0))
        vals *= (exact0 / vals[:, 0])[:, None]
        # Q_n(-z) = (-1)^(n+1) Q_n(z)
        neg = z[outer] < 0
        if neg.any():
            signs = (-1.0) ** (np.arange(nq) + 1)
            vals[neg] *= signs[None, :]
        q[outer] = vals
    m = np.empty((z.size, degree + 1))
    with np.errstate(divide="ignore", invalid="ignore"):
        a = (1.0 + z) * np.log(np.abs(1.0 + z))
        b = (1.0 - z) * np.log(np.abs(1.0 - z))
    a = np.where(np.isfinite(a), a, 0.0)
    b = np.where(np.isfinite(b), b, 0.0)
    m[:, 0] = a + b - 2.0
    n = np.arange(1, degree + 1)
    m[:, 1:] = 2.0 * (q[:, 2 : degree + 2] - q[:, 0:degree]) / (2 * n + 1)
    return m


def log_product_weights(center: float, half_width: float, targets: np.ndarray) -> np.ndarray:
    """Weights ``W`` (targets x 16) with ``sum_j W[i, j] phi(x_j) = int_panel ln|x_i - xi| phi``.

    Exact when ``phi`` is a polynomial of degree < 16 on the panel.
    """
    z = (np.asarray(targets, dtype=float) - center) / half_width
    moments = legendre_log_moments(z, NODES_PER_PANEL - 1)  # (targets, deg)
    # On a node itself (z = t_j) the forward recurrence is exact; no special case needed.
    return half_width * (np.log(half_width) * _W[None, :] + moments @ _TO_COEF)


@dataclass(frozen=True)
class KernelOperator:
    """The discrete layer operator on a panel rule.

    ``matrix[i, j]`` maps node values of a density to ``(F phi)(x_i)``. ``apply_at``
    evaluates ``F phi`` at arbitrary targets in [-1, 1].
    """

    lam: float
    panels: Panels
    matrix: np.ndarray

    def apply_at(self, targets: np.ndarray, values: np.ndarray) -> np.ndarray:
        """``(F phi)(targets)`` for node values ``values`` (N,) or (N, k)."""
        return operator_rows(self.lam, self.panels, targets) @ values


def operator_rows(lam: float, panels: Panels, targets: np.ndarray) -> np.ndarray:
    """Rows of the discrete operator for arbitrary targets (len(targets) x N)."""
    targets = np.asarray(targets, dtype=float)
    d = targets[:, None] - panels.nodes[None, :]
    ad = np.abs(d)
    with np.errstate(divide="ignore"):
        log_d = np.log(ad)
    smooth = plane_kernel_regular(lam * ad) - np.log(lam)
    rows = (smooth - np.where(ad > 0, log_d, 0.0)) * panels.weights[None, :]
    for p in range(panels.n_panels):
        c, h = panels.centers[p], panels.half_widths[p]
        near = np.abs(targets - c) <= NEAR_FIELD * h
        if not near.any():
            continue
        cols = slice(p * NODES_PER_PANEL, (p + 1) * NODES_PER_PANEL)
        idx = np.nonzero(near)[0]
        rows[idx, cols] = (smooth[idx, cols] * panels.weights[None, cols]
                           - log_product_weights(c, h, targets[idx]))
    return rows / np.pi


def kernel_operator(lam: float, panels: Panels) -> KernelOperator:
    """The discrete operator F on the nodes of ``panels`` (N x N, units of the density)."""
    return KernelOperator(lam, panels, operator_rows(lam, panels, panels.nodes))
