"""Composite Gauss-Legendre panels on [-1, 1]: the grid of the discrete operator.

Panels break at every point where the coating compliance ``m`` or the gap ``g`` may jump,
are graded geometrically toward those points and toward ``x = +-1`` (where the densities
have end-point behaviour) and are refined until sampled functions are resolved on every
panel. On each panel a function is represented by its Legendre interpolant on 16 Gauss
nodes (:func:`panel_legendre_coefficients`, :func:`interpolation_weights`). The operator
on these panels is in :mod:`core.discretize.quadrature`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.polynomial import legendre as npleg

NODES_PER_PANEL = 16
#: Gauss-Legendre nodes and weights of one panel's rule on [-1, 1].
GAUSS_NODES, GAUSS_WEIGHTS = npleg.leggauss(NODES_PER_PANEL)
# Values P_n(t_j), n < 16, of the Legendre polynomials at the nodes.
_P = npleg.legvander(GAUSS_NODES, NODES_PER_PANEL - 1)  # (16 nodes, 16 degrees)
#: The matrix from values at the nodes to Legendre coefficients, shape (degree, node).
VALUES_TO_LEGENDRE = ((_P * GAUSS_WEIGHTS[:, None]).T
                      * (np.arange(NODES_PER_PANEL) + 0.5)[:, None])
#: Barycentric weights of the Gauss-Legendre nodes: (-1)^j sqrt((1 - t_j^2) w_j).
BARYCENTRIC_WEIGHTS = ((-1.0) ** np.arange(NODES_PER_PANEL)
                       * np.sqrt((1.0 - GAUSS_NODES**2) * GAUSS_WEIGHTS))


#: How far from mirror symmetry about the punch's centre node values may be and still count
#: as symmetric (:func:`even_per_node`, :func:`even_overall`; the engine's split of even
#: and odd modes, ``core.engines.nystrom.modal``, and the march of an even lift-off on
#: half the punch, ``core.contact.systems.Mirror``, judge their operators by it too):
#: below the backward error of their eigendecompositions and factorizations (~N eps, 6e-14
#: at 288 nodes); measured on the symmetric presets ~1e-16. A compliance is compared node
#: by node (a stiff part beside a soft one is not symmetric to a share of the largest
#: compliance: a modulus 3e-11 off left to right made 1e-11 between the two kinds of
#: modes, and q 2.7e-10 off where split).
MIRROR_TOL = 1e-14


def mirrored_rule(x: np.ndarray, w: np.ndarray) -> bool:
    """Whether node ``N-1-i`` of a rule is at ``-x_i`` with the same weight (to a few
    roundings: a rule whose edges are exact mirror images is symmetric to 0)."""
    eps = np.finfo(float).eps
    return bool(np.max(np.abs(x + x[::-1]), initial=0.0) <= 4.0 * eps
                and np.max(np.abs(w - w[::-1]), initial=0.0) <= 4.0 * eps * np.max(w))


def even_per_node(values: np.ndarray, mirrored: np.ndarray) -> bool:
    """Whether ``values`` equal their mirror images ``mirrored`` point by point to
    :data:`MIRROR_TOL` of each value (a coating compliance, positive)."""
    return bool(np.all(np.abs(values - mirrored) <= MIRROR_TOL * np.abs(values)))


def even_overall(values: np.ndarray, mirrored: np.ndarray) -> bool:
    """Whether ``values`` equal their mirror images ``mirrored`` to :data:`MIRROR_TOL` of
    the largest |value| (a gap, which may vanish)."""
    return bool(np.max(np.abs(values - mirrored), initial=0.0)
                <= MIRROR_TOL * np.max(np.abs(values), initial=0.0))


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
        nodes = (centers[:, None] + half[:, None] * GAUSS_NODES[None, :]).ravel()
        weights = (half[:, None] * GAUSS_WEIGHTS[None, :]).ravel()
        return cls(edges, nodes, weights, centers, half)

    @classmethod
    def side_by_side(cls, rules: Sequence[Panels]) -> Panels:
        """``rules`` as one rule, their panels in the order given (they need not touch nor
        be sorted: ``edges`` are then only the rules' edges one after the other)."""
        if not rules:
            return cls(*(np.zeros(0) for _ in range(5)))
        return cls(*(np.concatenate([getattr(rule, name) for rule in rules])
                     for name in ("edges", "nodes", "weights", "centers", "half_widths")))

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


#: The finest panel of a short interval, a share of its length (:func:`base_panels`).
SHORT_SHARE = 1.0 / 8.0


def base_panels(lam: float, breakpoints: Sequence[float] = (), *,
                edge_width: float | None = 1e-4, max_width: float = 0.25,
                soft_cuts: Sequence[float] = (), soft_width: float | None = None,
                ratio: float = 2.0, short_share: float = SHORT_SHARE) -> Panels:
    """Panels on [-1, 1] broken at ``breakpoints`` and graded toward them and toward +-1.

    ``edge_width`` is the width of the finest panel at each graded point; panels are at
    most ``min(max_width, 3/lam)`` wide so the kernel's decay length ``~1/lam`` is resolved.

    ``soft_cuts`` are further points where panels must break (the element ends of a
    piecewise basis, see :func:`core.discretize.basis.graded_cuts`). Basis functions have kinks or
    jumps there, hence ``F(p/m)`` has ``(x - c)^k ln|x - c|`` terms that the plain Gauss
    rule integrates poorly on the neighbouring panels. Either correct the Galerkin form by
    :func:`core.discretize.galerkin_correction` (exact at every panel end: then no grading is
    needed at all, ``edge_width=None``), or grade the panels toward soft cuts to ``soft_width``
    (measured: ~1e-3 absolute was needed, tripling the node count). Between cuts, grading
    toward ``+-1`` or a breakpoint only happens on intervals wider than ``8 edge_width``: a
    narrower interval is itself the fine panel the grading would make. Without
    ``soft_cuts`` (and with a number for ``edge_width``) the panels are those of the plain
    call, whose finest panel on an interval of length ``L`` is at most ``short_share L``
    (:data:`SHORT_SHARE`: an interval narrower than ``edge_width / short_share`` is
    graded to its share of itself, not to ``edge_width``).
    """
    widest = min(max_width, 3.0 / lam)
    hard = [-1.0] + sorted(float(b) for b in breakpoints) + [1.0]
    if edge_width is None:
        edge_width = np.inf  # no interval is wider than 8 edge_width: nothing is graded
    if not len(soft_cuts) and np.isfinite(edge_width):
        edges: list[float] = [-1.0]
        for a, b in zip(hard[:-1], hard[1:], strict=True):
            sub = _graded_interval(a, b, True, True, min(edge_width, (b - a) * short_share),
                                   widest, ratio=ratio)
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


#: Points of the even sample of [-1, 1] on which :func:`refine_to_resolve` checks the
#: panels' interpolants (spacing 2.4e-4): a feature of m or g between the nodes (a
#: coating stripe 0.002 wide) left their values smooth, so the panels were taken as
#: resolving it.
DENSE_SAMPLES = 8193


def refine_to_resolve(panels: Panels, functions: Sequence[Callable[[np.ndarray], np.ndarray]],
                      *, rel_tol: float = 1e-12, min_width: float = 1e-9,
                      max_panels: int = 160, dense: int = DENSE_SAMPLES
                      ) -> tuple[Panels, bool]:
    """Bisect panels until every function's Legendre tail is below ``rel_tol`` of its
    scale, and its interpolant on each panel meets it at the points of an even sample of
    ``dense`` points to ``rel_tol`` of its scale too.

    The tails are read from the values at the nodes, which do not see a feature between
    them: a Gaussian spike of m 0.002 wide at x = 0.2 left q 1.5e-2 off with success at
    every tol. The even sample sees what is wider than its spacing (``2 / (dense - 1)``);
    narrower still can hide between its points. Points within 1e-12 of a panel end are
    left out of that check (a jump at a breakpoint takes either side's value there).

    Returns the refined panels and whether everything was resolved within the limits
    (``min_width`` stops the bisection of an undeclared jump, ``max_panels`` bounds the work).
    """
    edges = np.asarray(panels.edges, dtype=float)
    sample = np.linspace(-1.0, 1.0, dense)[1:-1] if dense > 2 else np.zeros(0)
    sampled = [np.asarray(f(sample), dtype=float) * np.ones(sample.size) for f in functions]
    resolved = True
    for _ in range(60):
        current = Panels.from_edges(edges)
        bad = np.zeros(current.n_panels, dtype=bool)
        if sample.size:
            ends = current.edges
            index = np.clip(np.searchsorted(ends, sample, side="right") - 1, 0,
                            current.n_panels - 1)
            # (the sample's points at a panel end are left out)
            inside = np.minimum(sample - ends[index], ends[index + 1] - sample) > 1e-12
            index = index[inside]
            local = (sample[inside] - current.centers[index]) / current.half_widths[index]
        for f, at_sample in zip(functions, sampled, strict=True):
            values = np.asarray(f(current.nodes), dtype=float).reshape(current.n_panels, -1)
            scale = max(float(np.max(np.abs(values))),
                        float(np.max(np.abs(at_sample), initial=0.0))) or 1.0
            coef = values @ VALUES_TO_LEGENDRE.T  # (panels, degrees)
            tail = np.max(np.abs(coef[:, -3:]), axis=1)
            bad |= tail > rel_tol * scale
            if sample.size:
                # each panel's interpolant at its sample points (Clenshaw: ~3x cheaper
                # than the barycentric weights)
                between = npleg.legval(local, coef[index].T, tensor=False)
                missed = np.abs(between - at_sample[inside]) > rel_tol * scale
                bad[np.unique(index[missed])] = True
        bad &= 2 * current.half_widths > 2 * min_width
        if not bad.any():
            return current, resolved
        if current.n_panels + int(bad.sum()) > max_panels:
            return current, False
        mids = current.centers[bad]
        edges = np.sort(np.concatenate([edges, mids]))
    return Panels.from_edges(edges), False


def panel_legendre_coefficients(values: np.ndarray) -> np.ndarray:
    """Legendre coefficients of node values on each panel.

    ``values`` has shape (N, ...) with N = 16 P; returns shape (P, 16, ...): coefficient
    ``k`` of the degree-15 interpolant on panel ``p`` (dimensionless, units of the values).
    """
    values = np.asarray(values, dtype=float)
    per_panel = values.reshape((-1, NODES_PER_PANEL) + values.shape[1:])
    return np.einsum("kj,pj...->pk...", VALUES_TO_LEGENDRE, per_panel)


def panel_index(panels: Panels, x: np.ndarray) -> np.ndarray:
    """Index of the panel holding each point of ``x`` (len(x),); a point on a panel end
    belongs to the panel on its right (the last end to the last panel)."""
    x = np.asarray(x, dtype=float)
    return np.clip(np.searchsorted(panels.edges, x, side="right") - 1, 0, panels.n_panels - 1)


def interpolation_weights(panels: Panels, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Panel index (len(x),) and weights (len(x), 16) of the panel-wise interpolant at ``x``.

    ``f(x_i) ~ sum_j weights[i, j] f(node j of panel index[i])``: the degree-15 polynomial
    through the panel's 16 Gauss nodes. A point on a panel end belongs to the panel on
    its right (the last end to the last panel), so evaluate a jump's two sides slightly
    off it.
    """
    x = np.asarray(x, dtype=float)
    index = panel_index(panels, x)
    t = (x - panels.centers[index]) / panels.half_widths[index]
    # Barycentric form (stable on Gauss-Legendre nodes; 3-4x cheaper than the Legendre
    # Vandermonde times the coefficient map, the same weights to ~1e-15).
    difference = t[:, None] - GAUSS_NODES[None, :]
    on_node = difference == 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        terms = BARYCENTRIC_WEIGHTS[None, :] / difference
    hit = on_node.any(axis=1)
    if hit.any():
        terms[hit] = on_node[hit]
    terms /= terms.sum(axis=1, keepdims=True)
    return index, terms
