"""Reference tables of panel pairs for the operator at panel nodes (quadrature.node_rows).

A target panel and a source panel are, up to an affine map, fixed by the ratio of their
half-widths and the offset of their centres (in source half-widths); on graded panels a
few such pairs recur. Each pair's key (ratio, offset), rounded to 1e-12, has tables in
the source panel's coordinate (z the target nodes there, t_j and W_j the Gauss rule):

* ``near`` (16,): the target nodes within NEAR_FIELD of the source centre;
* ``reference`` (16, 16): the product weights ``R = M(z) @ _TO_COEF`` of ln|z - t|;
* ``correction`` (16, 16): ``W_j ln|z_i - t_j| - R`` (``-R`` on a node, z_i = t_j);
* ``slope`` (16, 16): ``W_j / (z_i - t_j)`` (0 on a node) and ``steepest`` (16,): the
  largest ``1 / |z_i - t_j|`` of each target node (nodes excepted).

The tables of all keys seen are kept stacked in arrays, so that one call gathers the
rows it needs with one index instead of stacking a list of small arrays (~0.03 ms a
call, 3-4 calls a new scene). Rows are only appended (under a lock); a reader keeps the
store it started with, so a store replaced meanwhile (grown, or emptied at MAX_KEYS)
stays consistent for it.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

import numpy as np

from core.log_moments import legendre_log_moments
from core.panels import _T, _TO_COEF, _W, NODES_PER_PANEL

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
        for name in ("near", "reference", "correction", "slope", "steepest"):
            getattr(out, name)[:size] = getattr(self, name)[:size]
        out.index.update(self.index)
        return out


_LOCK = threading.Lock()
_STORE = PairTables.empty(_FIRST_CAPACITY)


def tables_of(keys: np.ndarray, near_field: float) -> tuple[np.ndarray, ...]:
    """The tables of (ratio, offset) keys (K, 2): near, reference, correction, slope,
    steepest (each with a leading K axis)."""
    z = keys[:, 1:] + keys[:, :1] * _T[None, :]  # (K, 16)
    moments = legendre_log_moments(z.ravel(), NODES_PER_PANEL - 1) @ _TO_COEF
    moments = moments.reshape(len(keys), NODES_PER_PANEL, NODES_PER_PANEL)
    apart = z[:, :, None] - _T[None, None, :]
    on_node = apart == 0.0
    apart[on_node] = 1.0
    correction = np.where(on_node, 0.0, _W * np.log(np.abs(apart))) - moments
    slope = np.where(on_node, 0.0, _W / apart)
    return (np.abs(z) <= near_field, moments, correction, slope,
            np.max(np.where(on_node, 0.0, 1.0 / np.abs(apart)), axis=2))


def lookup(keys: list[tuple[float, float]], near_field: float
           ) -> tuple[PairTables, np.ndarray]:
    """The store holding the tables of ``keys`` and their rows in it (len(keys),)."""
    store = _STORE
    rows = [store.index.get(k) for k in keys]
    if None in rows:
        store = _add([k for k, r in zip(keys, rows, strict=True) if r is None], near_field)
        rows = [store.index[k] for k in keys]
    return store, np.array(rows, dtype=np.intp)


def _add(missing: list[tuple[float, float]], near_field: float) -> PairTables:
    global _STORE
    with _LOCK:
        store = _STORE
        missing = [k for k in dict.fromkeys(missing) if k not in store.index]
        if not missing:
            return store
        size = len(store.index)
        if size + len(missing) > MAX_KEYS:
            store, size = PairTables.empty(max(_FIRST_CAPACITY, len(missing))), 0
        if size + len(missing) > store.near.shape[0]:
            store = store.grown(max(2 * store.near.shape[0], size + len(missing)))
        new = tables_of(np.array(missing), near_field)
        part = slice(size, size + len(missing))
        for name, values in zip(("near", "reference", "correction", "slope", "steepest"),
                                new, strict=True):
            getattr(store, name)[part] = values
        # the rows are written before their keys appear (a reader sees whole rows only)
        for i, key in enumerate(missing):
            store.index[key] = size + i
        _STORE = store
        return store


def clear() -> None:
    """Forget every table (tests; the store refills on use)."""
    global _STORE
    with _LOCK:
        _STORE = PairTables.empty(_FIRST_CAPACITY)
