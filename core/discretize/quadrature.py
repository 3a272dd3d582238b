"""Composite Gauss-Legendre panels and the discrete layer operator F.

The operator of the model is

    (F phi)(x) = int_{-1}^{1} k(x - xi) phi(xi) dxi,   k(d) = k_pl(lam d) / pi,

with ``k_pl(s) = -ln|s| + k_reg(s)`` (``k_reg`` smooth, see :mod:`core.kernel.plane`). On each
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

The panels themselves (breaks at every jump of ``m`` or ``g``, grading toward those points
and ``x = +-1``, refinement, interpolation) are in :mod:`core.discretize.panels`.

The Galerkin form ``int v F u`` of the projection method is the rule's sum
``sum_i w_i v(x_i) (F u)(x_i)``, exact in the inner integral only;
:func:`core.discretize.galerkin_correction` makes the outer one exact as well.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from core.discretize import pair_tables
from core.discretize.panels import (
    GAUSS_NODES,
    GAUSS_WEIGHTS,
    NODES_PER_PANEL,
    VALUES_TO_LEGENDRE,
    Panels,
)
from core.kernel import FULL_ACCURACY, kernel_block, kernel_regular, legendre_log_moments

_J = np.arange(NODES_PER_PANEL)

#: Targets closer than this many half-widths to a panel centre use product integration.
#: Farther out the plain Gauss rule integrates ``ln|z - t| P_n(t)``, n <= 15, to within
#: (measured against the exact moments) 2.5e-15 at |z| = 3 and 1.3e-15 at 4, but 4.8e-12
#: at 2 (P_15 grows like rho^15 on the ellipse, so the rule errs like rho^(15 - 32)).
NEAR_FIELD = 3.0


def log_product_weights(center: float, half_width: float, targets: np.ndarray) -> np.ndarray:
    """Weights ``W`` (targets x 16) with ``sum_j W[i, j] phi(x_j) = int_panel ln|x_i - xi| phi``.

    Exact when ``phi`` is a polynomial of degree < 16 on the panel.
    """
    z = (np.asarray(targets, dtype=float) - center) / half_width
    moments = legendre_log_moments(z, NODES_PER_PANEL - 1)  # (targets, deg)
    # On a node itself (z = t_j) the forward recurrence is exact; no special case needed.
    return half_width * (np.log(half_width) * GAUSS_WEIGHTS[None, :] + moments @ VALUES_TO_LEGENDRE)


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


#: Absolute error of the log moments per unit of kernel accuracy: an error d in the
#: moments moves an operator entry by at most h d max_j sum_n |VALUES_TO_LEGENDRE[n, j]| / pi
#: (= 4.33 h d / pi), the kernel's accuracy e by e h W_j / pi >= 0.027 e h / pi; this keeps
#: the first at a third of the second (0.017 / 3).
_MOMENT_SHARE = 0.017 / 3


def _log_weights(panels: Panels, targets: np.ndarray, near_t: np.ndarray,
                 near_p: np.ndarray, accuracy: float = FULL_ACCURACY) -> np.ndarray:
    """Product weights of ``ln|x - xi|`` (pairs x 16) for target/panel pairs, one batch.

    ``accuracy``: the kernel values' absolute accuracy (their moments follow it)."""
    if not near_t.size:
        return np.empty((0, NODES_PER_PANEL))
    c, h = panels.centers[near_p], panels.half_widths[near_p]
    moments = legendre_log_moments((targets[near_t] - c) / h, NODES_PER_PANEL - 1,
                                   _MOMENT_SHARE * accuracy)
    return h[:, None] * (np.log(h)[:, None] * GAUSS_WEIGHTS[None, :] + moments @ VALUES_TO_LEGENDRE)


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
    log_weights = _log_weights(panels, targets, near_t, sources[near_s], accuracy)
    return operator_rows_from_pairs(lam, panels, targets, sources, near_t, near_s, log_weights,
                                    accuracy)


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
        return operator_rows_from_pairs(lam, panels, targets, sources, pair_t, pair_s,
                                        np.empty((0, 16)), accuracy)
    raw_ratio = th[pair_t] / sh[pair_s]
    raw_offset = (tc[pair_t] - sc[pair_s]) / sh[pair_s]
    ratio, offset = np.round(raw_ratio, 12), np.round(raw_offset, 12)
    # The distinct keys (a few on graded panels) by one np.unique of ratio + i offset.
    unique, inverse = np.unique(ratio + 1j * offset, return_inverse=True)
    store, rows_of_keys = pair_tables.lookup(
        list(zip(unique.real.tolist(), unique.imag.tolist(), strict=True)), NEAR_FIELD)
    inverse = inverse.ravel()
    table_of_pair = rows_of_keys[inverse]
    which, node = np.nonzero(store.near[table_of_pair])  # near (pair, target node)
    u = table_of_pair[which]
    near_t = pair_t[which] * NODES_PER_PANEL + node
    if accuracy > FULL_ACCURACY:
        # the far values everywhere, then the near entries from the tables
        rows = operator_rows_from_pairs(lam, panels, targets, sources, near_t[:0], near_t[:0],
                     np.empty((0, NODES_PER_PANEL)), accuracy)
        pair_tables.add_near(rows, lam, panels, targets, sources, store,
                             own=(unique == 1.0)[inverse[which]], u=u, node=node,
                             near_t=near_t, near_s=pair_s[which],
                             shift=(raw_offset - offset)[which]
                             + (raw_ratio - ratio)[which] * GAUSS_NODES[node], accuracy=accuracy)
        return rows
    h = sh[pair_s[which]]
    log_weights = h[:, None] * (np.log(h)[:, None] * GAUSS_WEIGHTS[None, :]
                                + store.reference[u, node])
    return operator_rows_from_pairs(lam, panels, targets, sources, near_t, pair_s[which],
                                    log_weights, accuracy)


def operator_rows_from_pairs(lam: float, panels: Panels, targets: np.ndarray, sources: np.ndarray,
          near_t: np.ndarray, near_s: np.ndarray, log_weights: np.ndarray,
          accuracy: float = FULL_ACCURACY) -> np.ndarray:
    """Operator rows given the near (target, source position) pairs and their log weights.

    ``accuracy``: absolute accuracy of the kernel values (see
    :func:`core.kernel.kernel_block`).
    """
    cols_all = (sources[:, None] * NODES_PER_PANEL + _J[None, :]).ravel()
    nodes = panels.nodes[cols_all]
    weights = panels.weights[cols_all] / np.pi
    rows = np.empty((targets.size, nodes.size))
    if targets.size == nodes.size and np.array_equal(targets, nodes):
        _far_symmetric(lam * nodes, weights, rows, accuracy)
    else:
        step = max(1, _BLOCK_ENTRIES // max(nodes.size, 1))
        for start in range(0, targets.size, step):
            block = rows[start:start + step]
            distance = np.abs(targets[start:start + step, None] - nodes[None, :])
            distance *= lam
            block[...] = kernel_block(distance, accuracy)
            block *= weights[None, :]
    if near_t.size:
        # (target, source panel) blocks of 16 through a view: whole rows of 16 gathered and
        # scattered, not 16 index pairs each
        by_pair = rows.reshape(targets.size, sources.size, NODES_PER_PANEL)
        near_w = weights.reshape(-1, NODES_PER_PANEL)[near_s]
        offset = np.abs(targets[near_t, None] - nodes.reshape(-1, NODES_PER_PANEL)[near_s])
        if accuracy > FULL_ACCURACY:
            # the far value just computed plus a log (pair_tables.near_from_far)
            near = pair_tables.near_from_far(by_pair[near_t, near_s], offset, near_w, lam,
                                             accuracy)
            by_pair[near_t, near_s] = near - log_weights / np.pi
        else:
            smooth = kernel_regular(lam * offset, accuracy)
            smooth -= np.log(lam)
            by_pair[near_t, near_s] = smooth * near_w - log_weights / np.pi
    return rows


@lru_cache(maxsize=16)
def _upper_pairs(n_panels: int) -> tuple[np.ndarray, np.ndarray]:
    """Panel pairs (i, j), i <= j (np.triu_indices: 0.1 ms at 16 panels, kept per size)."""
    first, second = np.triu_indices(n_panels)
    first.setflags(write=False)
    second.setflags(write=False)
    return first, second


def _far_symmetric(scaled: np.ndarray, weights: np.ndarray, rows: np.ndarray,
                   accuracy: float) -> None:
    """Far-field rows ``k_pl(|s_i - s_j|) w_j`` of targets equal to the nodes, in place.

    The kernel values are symmetric (``s_i - s_j`` and ``s_j - s_i`` round alike), so they
    are evaluated on the panel pairs on and above the diagonal only (16 x 16 blocks, a
    cache-sized batch of pairs at a time) and each block is written twice: (p + 1) / 2p of
    the square. Blocks of whole rows from the diagonal on evaluated 75-88 % of it at
    192-256 nodes. On panels symmetric about 0 (every scene without jumps), a pair of
    panels that are not near each other has the block of its mirror image, flipped: about
    half of those are evaluated (at a loose kernel accuracy only: the mirrored distances
    agree to rounding, ~1e-16 absolute).
    """
    n_panels = scaled.size // NODES_PER_PANEL
    first, second = _upper_pairs(n_panels)
    x = scaled.reshape(n_panels, NODES_PER_PANEL)
    w = weights.reshape(n_panels, NODES_PER_PANEL)
    blocks = rows.reshape(n_panels, NODES_PER_PANEL, n_panels, NODES_PER_PANEL)
    mirror = (_mirror_pairs(x, first, second)
              if accuracy > FULL_ACCURACY and n_panels >= MIRROR_FROM else None)
    evaluate = np.arange(first.size) if mirror is None else np.nonzero(mirror < 0)[0]
    values = np.empty((first.size, NODES_PER_PANEL, NODES_PER_PANEL))
    # batches of at most a cache-sized number of pairs, of equal size (no short last one)
    most = max(1, _BLOCK_ENTRIES // NODES_PER_PANEL**2)
    batch = -(-first.size // -(-first.size // most))
    for start in range(0, evaluate.size, batch):
        pairs = evaluate[start:start + batch]
        a, b = first[pairs], second[pairs]
        values[pairs] = kernel_block(np.abs(x[a, :, None] - x[b, None, :]), accuracy)
    if mirror is not None:
        copied = np.nonzero(mirror >= 0)[0]
        # block(p - 1 - b, p - 1 - a) = block(a, b) transposed and flipped in both indices
        values[copied] = values[mirror[copied]].transpose(0, 2, 1)[:, ::-1, ::-1]
    for start in range(0, first.size, batch):
        part = slice(start, start + batch)
        a, b, block = first[part], second[part], values[part]
        blocks[a, :, b, :] = block * w[b, None, :]
        blocks[b, :, a, :] = block.transpose(0, 2, 1) * w[a, None, :]


#: Panels from which the mirror images of a symmetric grid's pairs are copied (below, the
#: bookkeeping costs what it saves: 7-9 panels 0.25 -> 0.29 ms, 24-26 panels 1.37 -> 1.25).
MIRROR_FROM = 16


def _mirror_pairs(x: np.ndarray, first: np.ndarray, second: np.ndarray
                  ) -> np.ndarray | None:
    """For panel nodes ``x`` (P, 16) symmetric about 0, each upper pair's mirror pair
    (its index) where that one is evaluated instead, else -1; ``None`` if not symmetric."""
    scale = max(float(np.max(np.abs(x))), 1e-300)
    if np.max(np.abs(x + x[::-1, ::-1])) > 4e-15 * scale:
        return None
    n_panels = x.shape[0]
    index = np.full((n_panels, n_panels), -1)
    index[first, second] = np.arange(first.size)
    partner = index[n_panels - 1 - second, n_panels - 1 - first]
    center, half = x.mean(axis=1), 0.5 * (x[:, -1] - x[:, 0])
    far = (np.abs(center[first] - center[second])
           > (NEAR_FIELD + 1.0) * (half[first] + half[second]))
    # the pair with the larger index takes its partner's block
    return np.where(far & (partner < np.arange(first.size)), partner, -1)


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


#: Share of new panels from which a refined grid's operator is cheaper assembled anew
#: (``anew_from`` of kernel_operator). Measured at tol 1e-6 after one grading level: 4 of
#: 9 panels fresh 0.62 -> 0.54 ms, 12 of 18 1.70 -> 1.30; 4 of 14 the same; 4 of 18 1.31
#: against 1.42.
FRESH_SHARE = 0.3


def kernel_operator(lam: float, panels: Panels, previous: KernelOperator | None = None,
                    accuracy: float = FULL_ACCURACY, anew_from: float = np.inf
                    ) -> KernelOperator:
    """The discrete operator F on the nodes of ``panels`` (N x N, units of the density).

    ``previous``: the operator on an earlier grid with the same ``lam`` (e.g. before a
    refinement). Blocks between panels both grids share (same ends) are copied from it,
    so only the rows and columns of new panels are computed. ``accuracy``: absolute
    accuracy of the kernel values (as in :func:`operator_rows`). ``anew_from``: from this
    share of new panels on, the operator is assembled anew (e.g. :data:`FRESH_SHARE`;
    the default reuses every shared block).
    """
    every = np.arange(panels.n_panels)
    if previous is None or previous.lam != lam:
        return KernelOperator(lam, panels, node_rows(lam, panels, panels, every,
                                                     accuracy=accuracy))
    kept_new, kept_old, fresh = shared_panels(previous.panels, panels)
    # Fresh panels' rows cover every column; the symmetric assembly evaluates half the
    # square: from ~30 % fresh panels on (FRESH_SHARE), it is cheaper to assemble anew.
    if not kept_new.size or fresh.size >= anew_from * panels.n_panels:
        return KernelOperator(lam, panels, node_rows(lam, panels, panels, every,
                                                     accuracy=accuracy))
    matrix = np.empty((panels.size, panels.size))
    kn, ko = panel_nodes(kept_new), panel_nodes(kept_old)
    matrix[np.ix_(kn, kn)] = previous.matrix[np.ix_(ko, ko)]
    if fresh.size:
        fn = panel_nodes(fresh)
        fresh_rows = node_rows(lam, panels, panels, fresh, accuracy=accuracy)
        matrix[fn, :] = fresh_rows
        matrix[np.ix_(kn, fn)] = _kept_on_fresh(lam, panels, kept_new, fresh, fresh_rows,
                                                accuracy)
    return KernelOperator(lam, panels, matrix)


def _kept_on_fresh(lam: float, panels: Panels, kept: np.ndarray, fresh: np.ndarray,
                   fresh_rows: np.ndarray, accuracy: float) -> np.ndarray:
    """Rows of the kept panels' nodes on the fresh panels' columns (16 kept x 16 fresh).

    Away from the fresh panels these are the fresh rows' far entries transposed (the
    kernel is even), reweighted from the kept nodes' weights to the fresh ones'; only the
    kept panels next to a fresh one, where either direction takes product integration,
    are computed (the kernel evaluations of the refined grid's new columns are saved).
    """
    kn, fn = panel_nodes(kept), panel_nodes(fresh)
    weights = panels.weights / np.pi
    block = (fresh_rows[:, kn] / weights[None, kn]).T * weights[None, fn]
    # Near in either direction: |c_P - c_Q| <= NEAR_FIELD h_Q + h_P or NEAR_FIELD h_P + h_Q.
    gap = np.abs(panels.centers[kept][:, None] - panels.centers[fresh][None, :])
    reach = (NEAR_FIELD + 1.0) * (panels.half_widths[kept][:, None]
                                  + panels.half_widths[fresh][None, :])
    close = np.nonzero(np.any(gap <= reach, axis=1))[0]
    if close.size:
        block[panel_nodes(close)] = node_rows(lam, panels, panels, kept[close], fresh,
                                              accuracy)
    return block
