"""The hp-graded basis (``kind="graded"`` of :func:`core.discretize.build_basis`).

Continuous piecewise polynomials on a mesh graded geometrically toward +-1 and every
breakpoint (:func:`graded_cuts`), with degrees growing away from them; the candidate
functions are ranked by an a-priori error model (the constants below, tuned on seven test
scenes) and orthonormalized in that order, so truncation is taking the first columns.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterable, Sequence

import numpy as np
from numpy.polynomial import legendre as npleg

from core.discretize.basis_pieces import Basis, Recurrence, orthonormality_error, stieltjes
from core.discretize.panels import Panels

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
#: ``min(m, 1/lam)`` (the width of the pressure's edge layer). The pressure is promised on
#: the whole of [-1, 1], and at a singular point itself the element touching it converges
#: only like its width: measured on eight scenes (the whole-interval error against
#: the Nystrom answer at tol 1e-11), 0.1 left q 5e-5 to 7e-4 off at x = +-1 whatever the
#: count, while 1e-7 reaches 1e-8 there (1e-9 and 1e-11 needed as many functions).
GRADED_DEPTH = 1e-7
#: At most this many geometric layers toward one singular point (the depth above needs
#: ~22 at m = 1e-3; :data:`GRADED_FINEST` stops a half-width of 1 at 27).
GRADED_MAX_LAYERS = 40
#: No element narrower than this (absolute, dimensionless x): next to +-1 doubles are
#: 1.1e-16 apart, so an element of 1e-12 still holds ~1e4 distinct points for its nodes.
#: Below m ~ 1e-5 the mesh therefore stops short of the edge layer, and the ranking of
#: :func:`_element_model` reads a layer of ``GRADED_FINEST / GRADED_DEPTH`` (a nearly
#: first-kind equation: its q is not resolved anyway, and the estimate says so).
GRADED_FINEST = 1e-12
#: Highest degree on one element: polynomials of degree <= 15 are integrated exactly by
#: the 16-node product rule on every panel of the element, whatever its subdivision
#: (allowing 24 or 31 changed nothing up to 256 functions).
GRADED_MAX_DEGREE = 15
#: A-priori model ranking the candidate functions (see :func:`_element_model`). The
#: constants were tuned on seven scenes (uniform, one and two jumps, near-uncoated, thick
#: soft and thin stiff bases, smoothly varying coating) for the number of functions that
#: reach 1e-4, 1e-6, 1e-8 and 1e-9 in settlement, tilt and interior pressure together;
#: the amplitude's power was then lowered from 2 to 0.75 for the pressure at the edges
#: (the pointwise error of the element touching a singular point falls like its width,
#: not its square): summed log2-counts to 1e-4 / 1e-6 / 1e-8 on the whole of [-1, 1] over
#: eight scenes 56 / 64 / 73 at 1, 54 / 61 / 68 at 0.75, 53 / 61 / 70 at 0.5. The optimum
#: is flat: any one constant halved or doubled moved the summed log-counts by < 2 %,
#: single counts by up to 30 %.
AMPLITUDE_POWER = 0.75
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
    about ``depth * min(m, 1/lam)`` (not below :data:`GRADED_FINEST`): ``m q`` has
    ``(x - x_e) ln|x - x_e|`` at every hard point ``x_e`` and a layer of width ~``m``
    (thin base: ~``1/lam``) next to it, and a geometric mesh with degrees growing away
    from ``x_e`` approximates both at an exponential rate. ``m`` (dimensionless
    compliance, a number or a vectorized callable) is sampled just inside each end.
    Returns the sorted soft cuts (dimensionless x).
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
            finest = max(depth * scale, GRADED_FINEST)
            layers = int(np.ceil(np.log(half / finest) / np.log(1.0 / ratio)))
            layers = min(max(layers, 0), max_layers)
            fractions = [f for f in outer if ratio < f < 1.0] if layers else []
            fractions += [ratio**j for j in range(1, layers + 1)]
            cuts.extend(end + inward * half * f for f in fractions)
    return tuple(sorted(cuts))


#: Candidates orthogonalized against the chosen functions at once (one matrix product
#: instead of one per candidate: the basis of 512 functions took 0.29 s, memory-bound).
ORTHOGONALIZE_BLOCK = 64


def _orthonormal_columns(vectors: Iterable[np.ndarray], size: int, count: int
                         ) -> np.ndarray:
    """The first ``count`` orthonormal columns Gram-Schmidt makes of ``vectors`` in their
    order (each twice orthogonalized), skipping those already in the span: shape
    ``(size, <= count)``. Blocks of :data:`ORTHOGONALIZE_BLOCK` are orthogonalized
    against the columns chosen before them together, then one by one within the block;
    the same columns as one at a time, to rounding."""
    chosen = np.zeros((size, count))
    n_chosen = 0
    vectors = iter(vectors)
    while n_chosen < count:
        block = list(itertools.islice(vectors, ORTHOGONALIZE_BLOCK))
        if not block:
            break
        v_block = np.column_stack(block)
        norms0 = np.linalg.norm(v_block, axis=0)
        before = chosen[:, :n_chosen]
        for _ in range(2):
            v_block -= before @ (before.T @ v_block)
        start = n_chosen
        for j in range(v_block.shape[1]):
            if n_chosen == count:
                break
            v = v_block[:, j]
            inside = chosen[:, start:n_chosen]
            for _ in range(2):
                v = v - inside @ (inside.T @ v)
            norm = np.linalg.norm(v)
            # In-span candidates leave ~1e-16 of their norm; new directions keep >~ 1e-4.
            if norm < 1e-9 * norms0[j]:
                continue
            chosen[:, n_chosen] = v / norm
            n_chosen += 1
    return chosen[:, :n_chosen]


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


def graded_basis(panels: Panels, wm: np.ndarray, count: int, breakpoints: Sequence[float],
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

    raw_1 = project(range(n_el), lambda e, t: np.ones_like(t))
    raw_x = project(range(n_el), lambda e, t: t)
    ordered = itertools.chain((raw_1, raw_x), (candidate(*c[2:]) for c in cands))
    chosen = _orthonormal_columns(ordered, n_raw, count)
    n_chosen = chosen.shape[1]
    if n_chosen < 2:
        raise ValueError("basis: the graded basis needs at least 2 functions")
    if np.dot(raw_x, chosen[:, 1]) < 0:
        chosen[:, 1] *= -1
    raw = np.zeros((len(x), n_raw))
    for e, idx in enumerate(members):
        raw[idx, offsets[e]:offsets[e + 1]] = blocks[e]
    basis_vals = raw @ chosen
    err = orthonormality_error(basis_vals, wm)
    return Basis("graded", basis_vals, tuple(recs), tuple(int(c) for c in need), chosen,
                 moments, err)
