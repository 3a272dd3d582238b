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
             in the settlement, tilt *and* the interior pressure (measured, m = 0.05:
             pressure 2.5e-5 / 4e-8 / 2e-10 at 64 / 128 / 192 functions, against
             8.8e-5 / 7.9e-6 / 1.4e-6 for ``global``). Its functions have kinks at the
             element ends, so the Galerkin form needs
             :func:`core.galerkin.galerkin_correction` on panels broken at the ends.

Functions are ordered so that the first ``n`` of a basis are the best ``n`` to keep
(degree scaled by the interval length), hence the bases are nested and truncation to
``n`` is simply taking the first ``n`` columns.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.polynomial import legendre as npleg

from core.quadrature import Panels


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
        return _graded_basis(panels, wm, count, breakpoints, cuts, (j0, j1, j2))
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
        err = _orthonormality_error(basis_vals, wm)
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
    err = _orthonormality_error(basis_vals, wm)
    return Basis("piecewise", basis_vals, tuple(recs), tuple(counts), transform, (j0, j1, j2),
                 err)


def _orthonormality_error(values: np.ndarray, weights: np.ndarray) -> float:
    gram = values.T @ (weights[:, None] * values)
    return float(np.max(np.abs(gram - np.eye(values.shape[1]))))


# ------------------------------------------------------------------ hp-graded basis

#: Ratio of consecutive element widths toward a singular point (hp-FEM's sigma). The
#: classic 0.15-0.2 minimizes the count for the energy norm; the interior pressure needs
#: every element to reach ~1e-9 at degree 15, which 0.35 does (Bernstein rho ~3.9 per
#: layer against 2.6 at 0.2): measured, 0.35 reached 1e-9 on 6 of 7 test scenes within
#: 400 functions, 0.2 on 2 of 7, with about the same counts at 1e-4 and 1e-6.
GRADED_RATIO = 0.35
#: Extra cuts at these fractions of the half-interval from each end, between the first
#: geometric cut and the middle: they keep the middle element well away from the ends.
GRADED_OUTER = (0.5,)
#: The finest element toward a singular point is this fraction of the local length scale
#: ``min(m, 1/lam)`` (the width of the pressure's edge layer). Deeper meshes (1e-2, 1e-3)
#: needed more functions for the same pressure error on the test scenes.
GRADED_DEPTH = 0.1
#: At most this many geometric layers toward one singular point.
GRADED_MAX_LAYERS = 12
#: Highest degree on one element: polynomials of degree <= 15 are integrated exactly by
#: the 16-node product rule on every panel of the element, whatever its subdivision
#: (allowing 24 or 31 changed nothing up to 256 functions).
GRADED_MAX_DEGREE = 15
#: A-priori model ranking the candidate functions (see :func:`_element_model`). The
#: constants were tuned on seven scenes (uniform, one and two jumps, near-uncoated, thick
#: soft and thin stiff bases, smoothly varying coating) for the number of functions that
#: reach 1e-4, 1e-6, 1e-8 and 1e-9 in settlement, tilt and interior pressure together.
#: The optimum is flat: any one constant halved or doubled (the depth 0.1 -> 0.03) moved
#: the summed log-counts by < 2 %, single counts by up to 30 %.
AMPLITUDE_POWER = 2.0
RHO_POWER = 0.75
TOUCHING_DECAY = 2.0


def graded_cuts(breakpoints: Sequence[float], lam: float,
                m: float | Callable[[np.ndarray], np.ndarray], *,
                ratio: float = GRADED_RATIO, outer: Sequence[float] = GRADED_OUTER,
                depth: float = GRADED_DEPTH,
                max_layers: int = GRADED_MAX_LAYERS) -> tuple[float, ...]:
    """Element ends of the ``"graded"`` basis besides ``-1``, ``1`` and ``breakpoints``.

    Every interval ``[a, b]`` between consecutive hard points (``+-1`` and the jumps of
    ``m`` or ``g``) is cut at ``a + l f`` and ``b - l f`` for ``f`` in ``outer`` and
    ``f = ratio^j`` (``l = (b - a)/2``, ``j = 1, 2, ...``), down to an element of width
    about ``depth * min(m, 1/lam)``: ``m q`` has ``(x - x_e) ln|x - x_e|`` at every hard
    point ``x_e`` and a layer of width ~``m`` (thin base: ~``1/lam``) next to it, and a
    geometric mesh with degrees growing away from ``x_e`` approximates both at an
    exponential rate. ``m`` (dimensionless compliance, a number or a vectorized callable)
    is sampled just inside each end. Returns the sorted soft cuts (dimensionless x).
    """
    if not 0.0 < ratio < 1.0:
        raise ValueError(f"ratio: must lie in (0, 1), got {ratio}")
    hard = [-1.0] + sorted(float(b) for b in breakpoints) + [1.0]
    cuts: list[float] = []
    for a, b in zip(hard[:-1], hard[1:], strict=True):
        half = 0.5 * (b - a)
        for end, inward in ((a, 1.0), (b, -1.0)):
            probe = end + inward * half * ratio * np.linspace(1e-6, 1.0, 33)
            m_local = float(np.min(m(probe))) if callable(m) else float(m)
            scale = min(m_local, 1.0 / lam, half)
            if not scale > 0.0:
                raise ValueError(f"m: must be > 0 near x = {end:.6g}, got {m_local:.6g}")
            layers = int(np.ceil(np.log(half / (depth * scale)) / np.log(1.0 / ratio)))
            layers = min(max(layers, 0), max_layers)
            fractions = [f for f in outer if ratio < f < 1.0] if layers else []
            fractions += [ratio**j for j in range(1, layers + 1)]
            cuts.extend(end + inward * half * f for f in fractions)
    return tuple(sorted(cuts))


def _bernstein_rho(gap: float, width: float) -> float:
    """Ellipse parameter of an element ``width`` wide whose nearest singularity is ``gap``
    beyond one of its ends: polynomial best approximation converges like ``rho^-d``."""
    a = 1.0 + 2.0 * gap / width
    return a + np.sqrt(a * a - 1.0)


def _element_model(lo: float, hi: float, a: float, b: float, scale_a: float,
                   scale_b: float) -> tuple[float, float, bool]:
    """A-priori error model of ``m q`` on the element ``[lo, hi]`` of the interval ``[a, b]``.

    Returns ``(log amplitude, log decay per degree, touching)``; the candidate of degree
    ``d`` is ranked by ``log amplitude - (d - 1) log decay``. The amplitude falls like
    ``(r/s)^AMPLITUDE_POWER`` inside the edge layer (``r`` the distance of the element's far
    end from its singular point, ``s`` the layer width ``scale_a`` or ``scale_b``); the decay
    is the Bernstein-ellipse parameter of the element's distance to the singular point
    (power ``RHO_POWER``), and a steep ``TOUCHING_DECAY`` on an element touching it, where
    raising the degree converges only algebraically (refinement does better there).
    """
    da, db = lo - a, b - hi
    reach, scale = (hi - a, scale_a) if da <= db else (b - lo, scale_b)
    log_amp = AMPLITUDE_POWER * min(0.0, float(np.log(reach / scale)))
    touching = min(da, db) <= 0.0
    if touching:
        return log_amp, TOUCHING_DECAY, True
    return log_amp, RHO_POWER * float(np.log(_bernstein_rho(min(da, db), hi - lo))), False


def _graded_basis(panels: Panels, wm: np.ndarray, count: int, breakpoints: Sequence[float],
                  cuts: Sequence[float], moments: tuple[float, float, float]) -> Basis:
    """The ``"graded"`` basis (see :func:`build_basis` and :func:`graded_cuts`).

    Continuous piecewise polynomials on each interval between hard points (discontinuous
    only at ``+-1`` and the breakpoints), in the hierarchical form of hp-FEM: the interval's
    ``1`` and ``x``, a hat function at every soft cut (zero at the neighbouring cuts present
    when it is added) and the bubbles ``P_d - P_{d-2}`` (d >= 2) on every element.
    Continuity matters: a jump of the discrete ``m q`` at a cut is cheap in the energy norm
    of the operator (~H^-1/2 when m is small), so a discontinuous basis leaves its
    pointwise error at the cuts, and each jump puts an O(1) ``(x - c) ln|x - c|`` kink
    into ``F(p/m)`` that the panel rule then has to resolve.

    The candidates are sorted by an a-priori estimate of the error each one removes
    (:func:`_element_model`), and
    orthonormalized after the global ``1`` and ``x`` with functions already in the span
    skipped: the first ``n`` functions are the best hp space of dimension ``n`` this model
    knows, and truncation is taking columns. Returns at most ``count`` functions (fewer
    only if every element has reached :data:`GRADED_MAX_DEGREE`).
    """
    x = panels.nodes
    hard = [-1.0] + sorted(float(b) for b in breakpoints) + [1.0]
    soft = {float(c) for c in cuts if min(abs(float(c) - h) for h in hard) > 1e-12}
    if any(not -1.0 < c < 1.0 for c in soft):
        raise ValueError("cuts: each must lie in (-1, 1)")
    edges = np.array(sorted(set(hard) | soft))
    gap = np.min(np.abs(edges[:, None] - panels.edges[None, :]), axis=1)
    if np.any(gap > 1e-12):
        bad = edges[int(np.argmax(gap))]
        raise ValueError(f"panels: must break at every element end, not at x = {bad:.6g} "
                         "(build them with base_panels(..., soft_cuts=cuts))")
    n_el = len(edges) - 1
    members = [np.nonzero((x > edges[i]) & (x < edges[i + 1]))[0] for i in range(n_el)]
    sizes = np.array([len(idx) for idx in members])
    if np.any(sizes < 2):
        raise ValueError("panels: every element of the graded basis needs nodes inside")
    is_hard = np.isin(edges, hard)

    # Candidates: (priority, tie-break, kind, data). Larger priority first.
    cands: list[tuple[float, tuple, str, tuple]] = []
    for i0 in np.nonzero(is_hard[:-1])[0]:
        i1 = int(np.nonzero(is_hard[i0 + 1:])[0][0]) + i0 + 1  # next hard point
        a, b = edges[i0], edges[i1]
        cands.append((np.inf, (0, a), "poly", (i0, i1, 0)))
        cands.append((np.inf, (1, a), "poly", (i0, i1, 1)))
        # Edge-layer width at each end, read off the depth of the grading (graded_cuts).
        scale_a = (edges[i0 + 1] - a) / GRADED_DEPTH
        scale_b = (b - edges[i1 - 1]) / GRADED_DEPTH
        for e in range(i0, i1):
            lo, hi = edges[e], edges[e + 1]
            log_amp, log_rho, _ = _element_model(lo, hi, a, b, scale_a, scale_b)
            top = min(GRADED_MAX_DEGREE, int(sizes[e]) - 1)
            for d in range(2, top + 1):
                decay = (d - 1) * log_rho
                cands.append((log_amp - decay, (d, lo), "bubble", (e, d)))
            if e > i0:
                # The hat at this element's left end ranks as the linear function of the
                # element on the end side of that cut (the one it splits off).
                toward_a = (lo - a) <= (b - lo)
                inner = e - 1 if toward_a else e
                amp_in = _element_model(edges[inner], edges[inner + 1], a, b, scale_a,
                                        scale_b)[0]
                cands.append((amp_in, (1, -min(lo - a, b - lo)), "hat", (i0, i1, e)))
    cands.sort(key=lambda c: (-c[0], c[1]))

    # Raw pieces: orthonormal polynomials on each element, as many as the bubbles need.
    need = np.full(n_el, 2)
    for _, _, kind, data in cands:
        if kind == "bubble":
            need[data[0]] = max(need[data[0]], data[1] + 1)
    need = np.minimum(need, sizes)
    recs: list[Recurrence] = []
    blocks: list[np.ndarray] = []
    for i, idx in enumerate(members):
        rec, vals = stieltjes(x[idx], wm[idx], int(need[i]), float(edges[i]),
                              float(edges[i + 1]))
        recs.append(rec)
        blocks.append(vals)
    offsets = np.concatenate([[0], np.cumsum(need)])
    n_raw = int(offsets[-1])

    def project(elements: range, f: Callable[[int, np.ndarray], np.ndarray]) -> np.ndarray:
        """Raw coordinates of the function with values ``f(e, x)`` on ``elements``."""
        v = np.zeros(n_raw)
        for e in elements:
            idx = members[e]
            v[offsets[e]:offsets[e + 1]] = blocks[e].T @ (wm[idx] * f(e, x[idx]))
        return v

    inserted: dict[int, list[int]] = {}  # interval start -> vertex indices present

    def candidate(kind: str, data: tuple) -> np.ndarray:
        if kind == "poly":
            i0, i1, d = data
            return project(range(i0, i1), lambda e, t: t**d)
        if kind == "bubble":
            e, d = data
            lo, hi = edges[e], edges[e + 1]

            def bubble(_e: int, t: np.ndarray) -> np.ndarray:
                s = (2.0 * t - lo - hi) / (hi - lo)
                return npleg.legval(s, np.eye(d + 1)[d] - np.eye(d + 1)[d - 2])

            return project(range(e, e + 1), bubble)
        i0, i1, v = data
        present = inserted.setdefault(i0, [i0, i1])
        left = max(p for p in present if p < v)
        right = min(p for p in present if p > v)
        present.append(v)
        xl, xv, xr = edges[left], edges[v], edges[right]

        def hat(_e: int, t: np.ndarray) -> np.ndarray:
            return np.where(t <= xv, (t - xl) / (xv - xl), (xr - t) / (xr - xv))

        return project(range(left, right), hat)

    chosen = np.zeros((n_raw, count))
    n_chosen = 0
    raw_1 = project(range(n_el), lambda e, t: np.ones_like(t))
    raw_x = project(range(n_el), lambda e, t: t)
    for k in range(len(cands) + 2):
        if n_chosen == count:
            break
        v = (raw_1, raw_x)[k] if k < 2 else candidate(*cands[k - 2][2:])
        norm0 = np.linalg.norm(v)
        q = chosen[:, :n_chosen]
        for _ in range(2):
            v = v - q @ (q.T @ v)
        norm = np.linalg.norm(v)
        # In-span candidates leave ~1e-16 of their norm; new directions keep >~ 1e-4.
        if norm < 1e-9 * norm0:
            continue
        chosen[:, n_chosen] = v / norm
        n_chosen += 1
    chosen = chosen[:, :n_chosen]
    if n_chosen < 2:
        raise ValueError("basis: the graded basis needs at least 2 functions")
    if np.dot(raw_x, chosen[:, 1]) < 0:
        chosen[:, 1] *= -1
    raw = np.zeros((len(x), n_raw))
    for e, idx in enumerate(members):
        raw[idx, offsets[e]:offsets[e + 1]] = blocks[e]
    basis_vals = raw @ chosen
    err = _orthonormality_error(basis_vals, wm)
    return Basis("graded", basis_vals, tuple(recs), tuple(int(c) for c in need), chosen,
                 moments, err)
