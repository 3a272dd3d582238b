"""Reference tables of panel pairs for the operator at panel nodes (quadrature.node_rows).

A target panel and a source panel are, up to an affine map, fixed by the ratio of their
half-widths and the offset of their centres (in source half-widths); on graded panels a
few such pairs recur. Each pair's key (ratio, offset), rounded to 1e-12, has tables in
the source panel's coordinate (z the target nodes there, t_j and W_j the Gauss rule):

* ``near`` (16,): the target nodes within NEAR_FIELD of the source centre;
* ``reference`` (16, 16): the product weights ``R = M(z) @ VALUES_TO_LEGENDRE`` of ln|z - t|;
* ``correction`` (16, 16): ``W_j ln|z_i - t_j| - R`` (``-R`` on a node, z_i = t_j);
* ``slope`` (16, 16): ``W_j / (z_i - t_j)`` (0 on a node) and ``steepest`` (16,): the
  largest ``1 / |z_i - t_j|`` of each target node (nodes excepted).

:func:`add_near` turns the far values of an operator's rows into its near entries with
them, at the loose kernel accuracy of a target tol. The tables of all keys seen are kept
stacked in arrays, so that one call gathers the
rows it needs with one index instead of stacking a list of small arrays (~0.03 ms a
call, 3-4 calls a new scene). Rows are only appended (under a lock); a reader keeps the
store it started with, so a store replaced meanwhile (grown, or emptied at MAX_KEYS)
stays consistent for it.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

import numpy as np

from core.discretize.panels import (
    GAUSS_NODES,
    GAUSS_WEIGHTS,
    NODES_PER_PANEL,
    VALUES_TO_LEGENDRE,
    Panels,
)
from core.kernel import kernel_regular, legendre_log_moments

#: Keys kept; the store is emptied when a new one would pass it (4096 keys hold ~25 MB).
MAX_KEYS = 4096
#: Rows of a new store (it doubles when full).
_FIRST_CAPACITY = 256


@dataclass(frozen=True)
class PairTables:
    """The stacked tables (rows beyond ``len(index)`` not yet filled)."""

    index: dict[tuple[float, float], int]
    near: np.ndarray  # (capacity, 16) bool
    reference: np.ndarray  # (capacity, 16, 16)
    correction: np.ndarray  # (capacity, 16, 16)
    slope: np.ndarray  # (capacity, 16, 16)
    steepest: np.ndarray  # (capacity, 16)

    @classmethod
    def empty(cls, capacity: int) -> PairTables:
        n = NODES_PER_PANEL
        return cls({}, np.zeros((capacity, n), dtype=bool), np.empty((capacity, n, n)),
                   np.empty((capacity, n, n)), np.empty((capacity, n, n)),
                   np.empty((capacity, n)))

    def grown(self, capacity: int) -> PairTables:
        """A copy with room for ``capacity`` rows."""
        out = PairTables.empty(capacity)
        size = len(self.index)
        for name in _TABLES:
            getattr(out, name)[:size] = getattr(self, name)[:size]
        out.index.update(self.index)
        return out


_TABLES = ("near", "reference", "correction", "slope", "steepest")
_LOCK = threading.Lock()
_STORE = PairTables.empty(_FIRST_CAPACITY)


def clear() -> None:
    """Forget every table (the next calls compute them again)."""
    global _STORE
    with _LOCK:
        _STORE = PairTables.empty(_FIRST_CAPACITY)


def stored() -> PairTables:
    """The current store (for inspection: its arrays are read-only)."""
    return _STORE


def tables_of(keys: np.ndarray, near_field: float) -> tuple[np.ndarray, ...]:
    """The tables of (ratio, offset) keys (K, 2): near, reference, correction, slope,
    steepest (each with a leading K axis)."""
    z = keys[:, 1:] + keys[:, :1] * GAUSS_NODES[None, :]  # (K, 16)
    # Each table a function of its key alone, not of the keys missing with it (else the
    # operator's last bits depend on what earlier solves cached): moments with Miller's
    # recurrence from each point's own start, and one 16 x 16 product per key (a product
    # of all rows at once rounds a row differently by batch size).
    moments = legendre_log_moments(z.ravel(), NODES_PER_PANEL - 1, own_start=True)
    moments = moments.reshape(len(keys), NODES_PER_PANEL, NODES_PER_PANEL) @ VALUES_TO_LEGENDRE
    apart = z[:, :, None] - GAUSS_NODES[None, None, :]
    on_node = apart == 0.0
    apart[on_node] = 1.0
    correction = np.where(on_node, 0.0, GAUSS_WEIGHTS * np.log(np.abs(apart))) - moments
    slope = np.where(on_node, 0.0, GAUSS_WEIGHTS / apart)
    return (np.abs(z) <= near_field, moments, correction, slope,
            np.max(np.where(on_node, 0.0, 1.0 / np.abs(apart)), axis=2))


def lookup(keys: list[tuple[float, float]], near_field: float
           ) -> tuple[PairTables, np.ndarray]:
    """The store holding the tables of ``keys`` and their rows in it (len(keys),)."""
    store = _STORE
    rows = [store.index.get(k) for k in keys]
    if None in rows:
        store = _add(keys, near_field)
        rows = [store.index[k] for k in keys]
    return store, np.array(rows, dtype=np.intp)


def _add(keys: list[tuple[float, float]], near_field: float) -> PairTables:
    """A store holding every one of ``keys`` (the current one, added to, or a new one)."""
    global _STORE
    with _LOCK:
        store = _STORE  # perhaps not the one the caller looked in: all keys are checked
        wanted = list(dict.fromkeys(keys))
        missing = [k for k in wanted if k not in store.index]
        if not missing:
            return store
        size = len(store.index)
        if size + len(missing) > MAX_KEYS:
            # emptied: the keys the old store held must come into the new one as well
            missing = wanted
            store, size = PairTables.empty(max(_FIRST_CAPACITY, len(missing))), 0
        if size + len(missing) > store.near.shape[0]:
            store = store.grown(max(2 * store.near.shape[0], size + len(missing)))
        new = tables_of(np.array(missing), near_field)
        part = slice(size, size + len(missing))
        for name, values in zip(_TABLES, new, strict=True):
            table = getattr(store, name)
            table.setflags(write=True)
            table[part] = values
            # read by every later call (and thread): an in-place write elsewhere raises
            table.setflags(write=False)
        # the rows are written before their keys appear (a reader sees whole rows only)
        for i, key in enumerate(missing):
            store.index[key] = size + i
        _STORE = store
        return store


#: Share of the kernel accuracy (relative to an entry's weight / pi, as the kernel values'
#: own error) left to the tables' approximations: the first-order term of a key's
#: rounding is skipped, and the tables' distances stand for the nodes' own, below it.
_TABLE_SHARE = 0.1


def add_near(rows: np.ndarray, lam: float, panels: Panels, targets: np.ndarray,
             sources: np.ndarray, store: PairTables, *, own: np.ndarray, u: np.ndarray,
             node: np.ndarray, near_t: np.ndarray, near_s: np.ndarray, shift: np.ndarray,
             accuracy: float) -> None:
    """The near entries of operator rows at panel nodes, at a loose kernel accuracy, in
    place: ``rows`` (targets x 16 len(sources)) holds the far values everywhere (kernel
    values to ``accuracy``, :func:`core.kernel.kernel_block`); the near entries add
    ``h/pi (W_j ln|z - t_j| - R)`` from the tables (the log of each entry's distance and
    the product weights cancel ``ln h``; no log is taken per entry).

    ``u``: each near row's table in ``store``; ``node``: its target node; ``shift``: the
    target's offset from the table's (the key's rounding, <= 5e-13), put back to first
    order where it could reach ``_TABLE_SHARE`` of the accuracy; ``own``: rows of a panel
    on itself (a target on a node, where the far value is -ln 0 and k_reg(0) - ln(lam h)
    is used).
    """
    by_pair = rows.reshape(targets.size, sources.size, NODES_PER_PANEL)
    h = panels.half_widths[sources[near_s]]
    correction = store.correction[u, node]
    steepest = store.steepest[u, node]  # 1 / the row's smallest |z - t_j|
    # The entries' distances are the nodes' (rounded to ~_NODE_ROUNDING), the tables' are
    # exact: ln differs by _NODE_ROUNDING / (h |z - t_j|), relative. Rows where that could
    # reach the tables' share of the accuracy (a target within ~1e-5 h of a node, or
    # panels narrower than ~1e-4) take the log of their own distances instead.
    exact = _NODE_ROUNDING * steepest > min(_TABLE_SHARE * accuracy, 1e-3) * h
    if exact.any():
        _exact_near(lam, panels, targets, sources, store.reference[u[exact], node[exact]],
                    by_pair, near_t[exact], near_s[exact], h[exact], accuracy)
        keep = ~exact
        u, node, near_t, near_s = u[keep], node[keep], near_t[keep], near_s[keep]
        own = own[keep]
        h, shift, steepest, correction = h[keep], shift[keep], steepest[keep], correction[keep]
    # the key's rounding moves ln by shift / (z - t_j): put back where it could matter
    far_off = np.nonzero(np.abs(shift) * steepest > _TABLE_SHARE * accuracy)[0]
    if far_off.size:
        correction[far_off] += (shift[far_off, None]
                                * store.slope[u[far_off], node[far_off]])
    correction *= (h / np.pi)[:, None]
    own = np.nonzero(own)[0]
    if own.size:
        at_zero = kernel_regular(np.zeros(1), accuracy)[0] - np.log(lam)
        column = node[own]
        weight = panels.weights[sources[near_s[own]] * NODES_PER_PANEL + column] / np.pi
        by_pair[near_t[own], near_s[own], column] = 0.0  # was -ln 0
        correction[own, column] += weight * (at_zero - np.log(h[own]))
    by_pair[near_t, near_s] += correction


#: Rounding of two node abscissae in [-1, 1] (2 ulp of 1): their distance errs by this.
_NODE_ROUNDING = 2 * np.finfo(float).eps


def _exact_near(lam: float, panels: Panels, targets: np.ndarray, sources: np.ndarray,
                reference: np.ndarray, by_pair: np.ndarray, near_t: np.ndarray,
                near_s: np.ndarray, h: np.ndarray, accuracy: float) -> None:
    """Near rows of :func:`add_near` from their own distances (as
    :func:`core.discretize.operator_rows` does), written into ``by_pair`` (targets,
    sources, 16) in place; ``reference``: their rows of the tables' product weights."""
    src = sources[near_s][:, None] * NODES_PER_PANEL + np.arange(NODES_PER_PANEL)[None, :]
    offset = np.abs(targets[near_t][:, None] - panels.nodes[src])
    weights = panels.weights[src] / np.pi
    log_weights = h[:, None] * (np.log(h)[:, None] * GAUSS_WEIGHTS[None, :] + reference)
    near = near_from_far(by_pair[near_t, near_s], offset, weights, lam, accuracy)
    by_pair[near_t, near_s] = near - log_weights / np.pi


def near_from_far(far: np.ndarray, offset: np.ndarray, weights: np.ndarray, lam: float,
                  accuracy: float) -> np.ndarray:
    """``(k_reg(lam d) - ln lam) w`` of near entries from their far values ``far`` =
    ``k_pl(lam d) w`` (dimensionless): ``k_reg(lam d) - ln lam = k_pl(lam d) + ln d``, a
    log instead of the series again (~15x cheaper an entry; the sum errs by ~|ln d| x
    1e-16, and by the decayed k_pl, below ``accuracy``, where those are zeros). ``offset``:
    the distances d; d = 0 (a target on a node) takes ``k_reg(0) - ln lam``."""
    with np.errstate(divide="ignore", invalid="ignore"):
        near = far + np.log(offset) * weights
    on_node = offset == 0.0
    if on_node.any():
        near[on_node] = (kernel_regular(np.zeros(1), accuracy)[0] - np.log(lam)) \
            * weights[on_node]
    return near
