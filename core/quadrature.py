"""Composite Gauss-Legendre panels and the discrete layer operator F.

The operator of the model is

    (F phi)(x) = int_{-1}^{1} k(x - xi) phi(xi) dxi,   k(d) = k_pl(lam d) / pi,

with ``k_pl(s) = -ln|s| + k_reg(s)`` (``k_reg`` smooth, see :mod:`core.kernel`). On each
panel the density is represented by its Legendre interpolant on 16 Gauss nodes; the log
part is integrated *exactly* against that interpolant (product integration, using
``int_{-1}^{1} ln|z - t| P_n(t) dt = 2 [Q_{n+1}(z) - Q_{n-1}(z)] / (2n + 1)``) whenever the
target lies within three half-widths of the panel centre, and by the plain Gauss rule
farther away, where the log is analytic in a Bernstein ellipse with rho >= 5.8 and the
plain rule is accurate to ~2e-15. The smooth part ``k_reg(lam d)`` has its nearest
complex singularities at ``d = +-2i/lam``, so panels no wider than ``3/lam`` integrate
it to machine precision.

Assembly: rows are built in cache-sized blocks of targets; at panel nodes the product
weights come from tables of reference panel pairs (:func:`node_rows`); an operator on a
refined grid copies the blocks of the panels it shares with the coarser one
(:func:`kernel_operator`); the kernel values may be asked for to a looser absolute accuracy
than rounding (a truncated series, and exact zeros where the kernel has decayed below it).

Panels break at every point where the coating compliance ``m`` or the gap ``g`` may
jump, are graded geometrically toward those points and toward ``x = +-1`` (where the
densities and ``F phi`` have end-point behaviour), and are refined adaptively until the
sampled functions are resolved on every panel.

The Galerkin form ``int v F u`` is the rule's sum ``sum_i w_i v(x_i) (F u)(x_i)``, exact in
the inner integral only. :func:`galerkin_correction` makes the outer one exact as well for
panel-wise polynomials of degree <= 15, which a basis with kinks or jumps at panel ends
(``"graded"`` in :mod:`core.basis`) needs; with it no panel grading is needed at all.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.polynomial import legendre as npleg

from core.kernel_values import FULL_ACCURACY, kernel_block, kernel_regular
from core.log_moments import legendre_log_moments

NODES_PER_PANEL = 16
_T, _W = npleg.leggauss(NODES_PER_PANEL)
# Values P_n(t_j), n < 16, and the interpolation matrix nodes -> Legendre coefficients.
_P = npleg.legvander(_T, NODES_PER_PANEL - 1)  # (16 nodes, 16 degrees)
_TO_COEF = (_P * _W[:, None]).T * (np.arange(NODES_PER_PANEL) + 0.5)[:, None]  # (deg, node)
_J = np.arange(NODES_PER_PANEL)

#: Targets closer than this many half-widths to a panel centre use product integration.
#: Farther out the plain Gauss rule integrates ``ln|z - t| P_n(t)``, n <= 15, to within
#: (measured against the exact moments) 2.5e-15 at |z| = 3 and 1.3e-15 at 4, but 4.8e-12
#: at 2 (P_15 grows like rho^15 on the ellipse, so the rule errs like rho^(15 - 32)).
NEAR_FIELD = 3.0


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
                     widest: float, *, finest_b: float | None = None,
                     ratio: float = 2.0) -> list[float]:
    """Panel edges on [a, b], geometric (``ratio``) from the finest width at graded ends.

    ``finest`` is the finest width at ``a`` (and at ``b`` unless ``finest_b`` is given).
    """
    length = b - a
    left: list[float] = []
    right: list[float] = []
    w = finest
    # Grading from both ends must not overlap: stop each at a third of the interval.
    while grade_a and w < min(widest, length / 3):
        left.append(w)
        w *= ratio
    w = finest if finest_b is None else finest_b
    while grade_b and w < min(widest, length / 3):
        right.append(w)
        w *= ratio
    # Each geometric run can sum to nearly 2/3 of the interval, so on a short interval the
    # two runs overlapped (a negative panel width, e.g. on [0.3, 1] with max_width 0.25).
    # Drop the widest graded panels until the middle is at least 1/8 of them wide (valid
    # layouts with a wider middle are unchanged).
    while (left or right) and length - sum(left) - sum(right) < 0.125 * max(left[-1:] + right[-1:]):
        (left if (left[-1:] or [0.0])[0] >= (right[-1:] or [0.0])[0] else right).pop()
    used = sum(left) + sum(right)
    middle = length - used
    n_mid = max(1, int(np.ceil(middle / widest - 1e-9)))
    widths = left + [middle / n_mid] * n_mid + right[::-1]
    edges = a + np.concatenate([[0.0], np.cumsum(widths)])
    edges[-1] = b
    return list(edges)


def base_panels(lam: float, breakpoints: Sequence[float] = (), *,
                edge_width: float | None = 1e-4, max_width: float = 0.25,
                soft_cuts: Sequence[float] = (), soft_width: float | None = None,
                ratio: float = 2.0) -> Panels:
    """Panels on [-1, 1] broken at ``breakpoints`` and graded toward them and toward +-1.

    ``edge_width`` is the width of the finest panel at each graded point; panels are at
    most ``min(max_width, 3/lam)`` wide so the kernel's decay length ``~1/lam`` is resolved.

    ``soft_cuts`` are further points where panels must break (the element ends of a
    piecewise basis, see :func:`core.basis.graded_cuts`). Basis functions have kinks or
    jumps there, hence ``F(p/m)`` has ``(x - c)^k ln|x - c|`` terms that the plain Gauss
    rule integrates poorly on the neighbouring panels. Either correct the Galerkin form by
    :func:`galerkin_correction` (exact at every panel end: then no grading is needed at
    all, ``edge_width=None``), or grade the panels toward soft cuts to ``soft_width``
    (measured: ~1e-3 absolute was needed, tripling the node count). Between cuts, grading
    toward ``+-1`` or a breakpoint only happens on intervals wider than ``8 edge_width``: a
    narrower interval is itself the fine panel the grading would make. Without
    ``soft_cuts`` (and with a number for ``edge_width``) the panels are those of the plain
    call.
    """
    widest = min(max_width, 3.0 / lam)
    hard = [-1.0] + sorted(float(b) for b in breakpoints) + [1.0]
    if edge_width is None:
        edge_width = np.inf  # no interval is wider than 8 edge_width: nothing is graded
    if not len(soft_cuts) and np.isfinite(edge_width):
        edges: list[float] = [-1.0]
        for a, b in zip(hard[:-1], hard[1:], strict=True):
            sub = _graded_interval(a, b, True, True, min(edge_width, (b - a) / 8), widest,
                                   ratio=ratio)
            edges.extend(sub[1:])
        return Panels.from_edges(np.array(edges))
    soft = sorted({float(c) for c in soft_cuts})
    if any(not -1.0 < c < 1.0 for c in soft):
        raise ValueError("soft_cuts: each must lie in (-1, 1)")
    # A soft cut closer than 1e-12 to a hard point would leave a degenerate panel.
    soft = [c for c in soft if min(abs(c - h) for h in hard) > 1e-12]
    points = sorted(set(hard) | set(soft))
    hard_set = set(hard)
    edges = [-1.0]
    for a, b in zip(points[:-1], points[1:], strict=True):
        length = b - a

        def finest_at(p: float, _length: float = length) -> float | None:
            if p in hard_set:
                return min(edge_width, _length / 8) if _length > 8 * edge_width else None
            if soft_width is not None and _length > 8 * soft_width:
                return soft_width
            return None

        fa, fb = finest_at(a), finest_at(b)
        sub = _graded_interval(a, b, fa is not None, fb is not None,
                               fa if fa is not None else length, widest,
                               finest_b=fb if fb is not None else length)
        edges.extend(sub[1:])
    return Panels.from_edges(np.array(edges))


def refine_to_resolve(panels: Panels, functions: Sequence[Callable[[np.ndarray], np.ndarray]],
                      *, rel_tol: float = 1e-12, min_width: float = 1e-9,
                      max_panels: int = 160) -> tuple[Panels, bool]:
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


def _near_pairs(panels: Panels, targets: np.ndarray, sources: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray]:
    """(target, source position) pairs closer than NEAR_FIELD half-widths to the centre."""
    return np.nonzero(np.abs(targets[:, None] - panels.centers[None, sources])
                      <= NEAR_FIELD * panels.half_widths[None, sources])


def _log_weights(panels: Panels, targets: np.ndarray, near_t: np.ndarray,
                 near_p: np.ndarray) -> np.ndarray:
    """Product weights of ``ln|x - xi|`` (pairs x 16) for target/panel pairs, one batch."""
    if not near_t.size:
        return np.empty((0, NODES_PER_PANEL))
    c, h = panels.centers[near_p], panels.half_widths[near_p]
    moments = legendre_log_moments((targets[near_t] - c) / h, NODES_PER_PANEL - 1)
    return h[:, None] * (np.log(h)[:, None] * _W[None, :] + moments @ _TO_COEF)


#: Target rows per block of :func:`operator_rows`: rows x nodes about this many entries,
#: so that every temporary of a block stays in cache (whole-matrix temporaries made the
#: element-wise passes, not the kernel, the main cost: 18 of 30 ms at 704 nodes).
_BLOCK_ENTRIES = 1 << 15


def operator_rows(lam: float, panels: Panels, targets: np.ndarray,
                  sources: np.ndarray | None = None, accuracy: float = FULL_ACCURACY
                  ) -> np.ndarray:
    """Rows of the discrete operator for arbitrary targets (len(targets) x N).

    ``sources`` (panel indices, default all) restricts the columns to the nodes of those
    panels, in that order (len(targets) x 16 len(sources)). Far pairs take the Gauss rule
    of the whole kernel ``k_reg(lam d) - ln(lam d)``; near pairs the Gauss rule of its
    smooth part and product integration of the log part. ``accuracy``: absolute accuracy
    of the kernel values (default: rounding; a looser one evaluates them faster).
    """
    targets = np.asarray(targets, dtype=float)
    sources = (np.arange(panels.n_panels) if sources is None
               else np.asarray(sources, dtype=np.intp))
    near_t, near_s = _near_pairs(panels, targets, sources)
    log_weights = _log_weights(panels, targets, near_t, sources[near_s])
    return _rows(lam, panels, targets, sources, near_t, near_s, log_weights, accuracy)


def node_rows(lam: float, panels: Panels, target_panels: Panels, target_index: np.ndarray,
              sources: np.ndarray | None = None, accuracy: float = FULL_ACCURACY
              ) -> np.ndarray:
    """:func:`operator_rows` at the nodes of the panels ``target_panels[target_index]``.

    The same numbers (to ~1e-15), but the product weights come from tables of reference
    panel pairs: a target panel and a source panel are, up to an affine map, fixed by the
    ratio of their half-widths and the offset of their centres, and on graded panels a few
    such pairs recur (neighbours of equal width, of half or double width).
    """
    target_index = np.asarray(target_index, dtype=np.intp)
    sources = (np.arange(panels.n_panels) if sources is None
               else np.asarray(sources, dtype=np.intp))
    targets = target_panels.nodes.reshape(-1, NODES_PER_PANEL)[target_index].ravel()
    tc = target_panels.centers[target_index]
    th = target_panels.half_widths[target_index]
    sc, sh = panels.centers[sources], panels.half_widths[sources]
    # Panel pairs with a target node possibly within NEAR_FIELD source half-widths.
    pair_t, pair_s = np.nonzero(np.abs(tc[:, None] - sc[None, :])
                                <= NEAR_FIELD * sh[None, :] + th[:, None])
    if not pair_t.size:
        return _rows(lam, panels, targets, sources, pair_t, pair_s, np.empty((0, 16)),
                     accuracy)
    ratio = np.round(th[pair_t] / sh[pair_s], 12)
    offset = np.round((tc[pair_t] - sc[pair_s]) / sh[pair_s], 12)
    keys = list(zip(ratio.tolist(), offset.tolist(), strict=True))
    # Looked up into a local dict first: another thread may empty the shared one.
    found = {k: _PAIR_TABLES.get(k) for k in dict.fromkeys(keys)}
    missing = [k for k, v in found.items() if v is None]
    if missing:
        keys_array = np.array(missing)  # (missing, 2): ratio, offset
        z = keys_array[:, 1:] + keys_array[:, :1] * _T[None, :]  # (missing, 16)
        moments = legendre_log_moments(z.ravel(), NODES_PER_PANEL - 1) @ _TO_COEF
        moments = moments.reshape(len(missing), NODES_PER_PANEL, NODES_PER_PANEL)
        new = {key: (np.abs(zk) <= NEAR_FIELD, table)
               for key, zk, table in zip(missing, z, moments, strict=True)}
        found.update(new)
        if len(_PAIR_TABLES) + len(new) > _PAIR_TABLES_MAX:
            _PAIR_TABLES.clear()
        _PAIR_TABLES.update(new)
    tables = [found[k] for k in keys]
    near = np.array([t[0] for t in tables])  # (pairs, 16 target nodes)
    which, node = np.nonzero(near)
    reference = np.array([t[1] for t in tables])[which, node]  # (near pairs, 16)
    h = sh[pair_s[which]]
    log_weights = h[:, None] * (np.log(h)[:, None] * _W[None, :] + reference)
    near_t = pair_t[which] * NODES_PER_PANEL + node
    return _rows(lam, panels, targets, sources, near_t, pair_s[which], log_weights,
                 accuracy)


#: Reference tables of :func:`node_rows`, keyed by (half-width ratio, centre offset) of a
#: (target, source) panel pair rounded to 1e-12 (moments move by ~1e-12 of their size):
#: near mask (16,) and ``M(z) @ _TO_COEF`` (16 x 16). Emptied when it holds more.
_PAIR_TABLES: dict[tuple[float, float], tuple[np.ndarray, np.ndarray]] = {}
_PAIR_TABLES_MAX = 4096


def _rows(lam: float, panels: Panels, targets: np.ndarray, sources: np.ndarray,
          near_t: np.ndarray, near_s: np.ndarray, log_weights: np.ndarray,
          accuracy: float = FULL_ACCURACY) -> np.ndarray:
    """Operator rows given the near (target, source position) pairs and their log weights.

    ``accuracy``: absolute accuracy of the kernel values (see
    :func:`core.kernel_values.kernel_block`).
    """
    cols_all = (sources[:, None] * NODES_PER_PANEL + _J[None, :]).ravel()
    nodes = panels.nodes[cols_all]
    weights = panels.weights[cols_all] / np.pi
    rows = np.empty((targets.size, nodes.size))
    step = max(1, _BLOCK_ENTRIES // max(nodes.size, 1))
    for start in range(0, targets.size, step):
        block = rows[start:start + step]
        distance = np.abs(targets[start:start + step, None] - nodes[None, :])
        distance *= lam
        block[...] = kernel_block(distance, accuracy)
        block *= weights[None, :]
    if near_t.size:
        cols = near_s[:, None] * NODES_PER_PANEL + _J[None, :]  # positions among sources
        smooth = kernel_regular(lam * np.abs(targets[near_t, None] - nodes[cols]), accuracy)
        smooth -= np.log(lam)
        rows[near_t[:, None], cols] = smooth * weights[cols] - log_weights / np.pi
    return rows


def shared_panels(old: Panels, new: Panels) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Panels of ``new`` that ``old`` has too (same ends): their indices in ``new`` and in
    ``old``, and the indices in ``new`` of the other (fresh) panels."""
    old_index = {key: i for i, key in enumerate(zip(old.edges[:-1].tolist(),
                                                    old.edges[1:].tolist(), strict=True))}
    kept_new, kept_old, fresh = [], [], []
    for i, key in enumerate(zip(new.edges[:-1].tolist(), new.edges[1:].tolist(),
                                strict=True)):
        if key in old_index:
            kept_new.append(i)
            kept_old.append(old_index[key])
        else:
            fresh.append(i)
    as_index = lambda v: np.asarray(v, dtype=np.intp)  # noqa: E731
    return as_index(kept_new), as_index(kept_old), as_index(fresh)


def panel_nodes(panel_index: np.ndarray) -> np.ndarray:
    """Node indices of the panels ``panel_index`` (16 each, in panel order)."""
    return (np.asarray(panel_index, dtype=np.intp)[:, None] * NODES_PER_PANEL
            + _J[None, :]).ravel()


def kernel_operator(lam: float, panels: Panels, previous: KernelOperator | None = None,
                    accuracy: float = FULL_ACCURACY) -> KernelOperator:
    """The discrete operator F on the nodes of ``panels`` (N x N, units of the density).

    ``previous``: the operator on an earlier grid with the same ``lam`` (e.g. before a
    refinement). Blocks between panels both grids share (same ends) are copied from it,
    so only the rows and columns of new panels are computed. ``accuracy``: absolute
    accuracy of the kernel values (as in :func:`operator_rows`).
    """
    every = np.arange(panels.n_panels)
    if previous is None or previous.lam != lam:
        return KernelOperator(lam, panels, node_rows(lam, panels, panels, every,
                                                     accuracy=accuracy))
    kept_new, kept_old, fresh = shared_panels(previous.panels, panels)
    if not kept_new.size:
        return KernelOperator(lam, panels, node_rows(lam, panels, panels, every,
                                                     accuracy=accuracy))
    matrix = np.empty((panels.size, panels.size))
    kn, ko = panel_nodes(kept_new), panel_nodes(kept_old)
    matrix[np.ix_(kn, kn)] = previous.matrix[np.ix_(ko, ko)]
    if fresh.size:
        fn = panel_nodes(fresh)
        matrix[fn, :] = node_rows(lam, panels, panels, fresh, accuracy=accuracy)
        matrix[np.ix_(kn, fn)] = node_rows(lam, panels, panels, kept_new, fresh, accuracy)
    return KernelOperator(lam, panels, matrix)


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
    nodes = (0.5 * (lo + hi)[:, None] + 0.5 * (hi - lo)[:, None] * _T[None, :]).ravel()
    weights = (0.5 * (hi - lo)[:, None] * _W[None, :]).ravel()
    return nodes, weights


def galerkin_correction(panels: Panels, *, reach: float = 1.0) -> np.ndarray:
    """Correction ``C`` (N x N) that makes ``v^T (diag(w) F + C) u`` an exact double integral.

    The Galerkin form ``int int k(x - xi) v(x) u(xi) dx dxi`` of the projection method is
    computed as ``sum_i w_i v(x_i) (F u)(x_i)``: exact in ``xi`` (product integration) but
    Gauss in ``x``. Where ``u`` has a jump or a kink at a panel end (a basis that is
    piecewise across panels, e.g. the ``"graded"`` basis of :mod:`core.basis`), ``F u``
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
        exact = np.einsum("ai,pab,bj->pij", _TO_COEF, exact_coef, _TO_COEF)
        # What diag(w) F holds there: the target panel's Gauss rule times the exact inner
        # integral (log_product_weights, batched over the pairs).
        x_t = panels.nodes.reshape(-1, NODES_PER_PANEL)[p]
        z_t = (x_t - c[q, None]) / h[q, None]
        m_t = legendre_log_moments(z_t.ravel(), NODES_PER_PANEL - 1).reshape(
            len(p), NODES_PER_PANEL, NODES_PER_PANEL)
        inner_t = h[q, None, None] * (np.log(h[q])[:, None, None] * _W[None, None, :]
                                      + m_t @ _TO_COEF)
        approx = panels.weights.reshape(-1, NODES_PER_PANEL)[p][:, :, None] * inner_t
        block = -(exact - approx) / np.pi
        for k in range(len(p)):
            rows = slice(p[k] * NODES_PER_PANEL, (p[k] + 1) * NODES_PER_PANEL)
            cols = slice(q[k] * NODES_PER_PANEL, (q[k] + 1) * NODES_PER_PANEL)
            out[rows, cols] = block[k]
    return out


def panel_legendre_coefficients(values: np.ndarray) -> np.ndarray:
    """Legendre coefficients of node values on each panel.

    ``values`` has shape (N, ...) with N = 16 P; returns shape (P, 16, ...): coefficient
    ``k`` of the degree-15 interpolant on panel ``p`` (dimensionless, units of the values).
    """
    values = np.asarray(values, dtype=float)
    per_panel = values.reshape((-1, NODES_PER_PANEL) + values.shape[1:])
    return np.einsum("kj,pj...->pk...", _TO_COEF, per_panel)


def interpolation_weights(panels: Panels, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Panel index (len(x),) and weights (len(x), 16) of the panel-wise interpolant at ``x``.

    ``f(x_i) ~ sum_j weights[i, j] f(node j of panel index[i])``: the degree-15 polynomial
    through the panel's 16 Gauss nodes. A point on a panel end belongs to the panel on
    its right (the last end to the last panel), so evaluate a jump's two sides slightly
    off it.
    """
    x = np.asarray(x, dtype=float)
    index = np.clip(np.searchsorted(panels.edges, x, side="right") - 1, 0, panels.n_panels - 1)
    t = (x - panels.centers[index]) / panels.half_widths[index]
    return index, npleg.legvander(t, NODES_PER_PANEL - 1) @ _TO_COEF
