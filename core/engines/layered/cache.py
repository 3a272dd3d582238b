"""Bounded caches of the exact layered solve, so a load change re-solves nothing geometric.

:func:`core.engines.layered.solve_layered` builds, per geometry, three things that do not
depend on the loads, each kept in its own :class:`core.cache.StageCache` (counted, cleared
by :func:`core.cache.clear_caches`):

- ``layered_table``: the stack's regular part (:class:`core.kernel.RegularPartTable`),
  keyed by the stack (``a / H``, the layers, the base) and the table's degree; about a
  third of a new geometry's solve;
- ``layered_operator``: the Galerkin matrix, keyed by the stack, the table's degree, the
  modes it holds (room for one doubling) and its nodes (a gap change reuses it); about
  half of a new geometry's solve;
- ``layered_response``: the unit responses (to the gap, a unit settlement, a unit tilt),
  keyed by the stack, the degree, the modes, the nodes, the gap's values and its
  breakpoints.

A load slider's step (settlement, tilt, force, moment) is then the superposition of the
cached unit responses (:meth:`core.engines.layered.LayeredResponse.complete`).

Gaps are callables: they are recognised by their values on :data:`GAP_PROBES` Chebyshev
points and on both sides of each breakpoint (as :mod:`core.engines.nystrom.prepared` does).
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Hashable, Sequence
from typing import Any

import numpy as np

from core.cache import StageCache, fingerprint
from core.kernel import UniformLayer

__all__ = ["CHEBYSHEV_ROWS", "GAP_MOMENTS", "KeptValues", "LAYERED_BYTES", "LAYERED_OPERATOR",
           "LAYERED_RESPONSE", "LAYERED_TABLE", "gap_key", "share_budget", "stack_key"]

_MiB = 2**20
#: Points on which a callable gap is sampled for its key [-].
GAP_PROBES = 2049
#: Stacks' tables kept: one table holds panels x (degree + 1) coefficients (2 KiB for the
#: rounded_graded preset, more for a base much thinner than the punch).
LAYERED_TABLE = StageCache("layered_table", max_items=8, max_bytes=16 * _MiB,
                           sizeof=lambda table: int(table.coefficients.nbytes
                                                    + table.edges.nbytes))
#: Galerkin matrices: modes^2 doubles, 2 MiB at the most modes (512); a solve that doubles
#: its modes beyond the first matrix's room keeps each level, so a handful per geometry.
LAYERED_OPERATOR = StageCache("layered_operator", max_items=32, max_bytes=32 * _MiB)
#: Unit responses: 3 x modes doubles and two coarser copies, a few tens of KiB each.
LAYERED_RESPONSE = StageCache("layered_response", max_items=256, max_bytes=8 * _MiB)
#: The caches above with their default bounds [bytes] (:func:`share_budget`).
_LAYERED = (LAYERED_TABLE, LAYERED_OPERATOR, LAYERED_RESPONSE)
LAYERED_BYTES = {cache.name: cache.max_bytes for cache in _LAYERED}


def stack_key(half_width: float, layers: Sequence[UniformLayer], base_thickness: float,
              base_modulus: float, base_poisson: float) -> str:
    """The key of a stack under a punch of half-width a [m]: every number it depends on."""
    parts = tuple((lay.thickness, lay.modulus, lay.poisson, lay.interface) for lay in layers)
    return fingerprint("layered stack", float(half_width), parts, float(base_thickness),
                       float(base_modulus), float(base_poisson))


def gap_key(gap: Callable[[np.ndarray], np.ndarray] | float | None,
            breakpoints: Sequence[float]) -> str:
    """The key of a gap ``g*(t)`` [-] (a callable, a number or None) with its breakpoints."""
    bps = tuple(float(b) for b in breakpoints)
    if not callable(gap):
        return fingerprint("layered gap", None if gap is None else float(gap), bps)
    probe = np.cos(np.linspace(0.0, np.pi, GAP_PROBES))
    at = np.asarray(bps, dtype=float)
    probe = np.concatenate([probe, at - 1e-9, at + 1e-9])
    values: Any = np.broadcast_to(np.asarray(gap(probe), dtype=float), probe.shape)
    return fingerprint("layered gap", np.ascontiguousarray(values), bps)


def share_budget(total_bytes: int, default_total: int) -> None:
    """Bound each cache here by ``total_bytes / default_total`` of its default bound [-]
    (a worker process's share of the machine's budget,
    :func:`core.budget.set_stage_cache_budget`)."""
    for cache in _LAYERED:
        cache.max_bytes = max(1, LAYERED_BYTES[cache.name] * total_bytes // default_total)


class KeptValues:
    """The last ``max_items`` values computed per key, least recently used dropped first;
    safe across threads (solves may run in threads: a served explorer, Dask threads).
    Values are made read-only: every caller shares them."""

    def __init__(self, max_items: int) -> None:
        self.max_items = max_items
        self._kept: dict[Hashable, np.ndarray] = {}
        self._lock = threading.Lock()

    def get_or_compute(self, key: Hashable, compute: Callable[[], np.ndarray]) -> np.ndarray:
        """The value kept for ``key``, else ``compute()`` kept."""
        with self._lock:
            value = self._kept.pop(key, None)
            if value is not None:
                self._kept[key] = value  # now the most recently used
                return value
        value = compute()
        value.setflags(write=False)
        with self._lock:
            while len(self._kept) >= self.max_items:
                del self._kept[next(iter(self._kept))]
            self._kept[key] = value
        return value


#: Chebyshev rows of point sets (:func:`core.engines.layered.solve._chebyshev_rows`), at most 2 MiB
#: each: the error estimate and the pressure ask the same few sets at every load, and
#: their cosines were half of a load change's CPU time (measured on a 10,000-point load
#: study: 4.3 of 9 ms a point).
CHEBYSHEV_ROWS = KeptValues(16)
#: A gap's moments per (gap, modes): a new coating under the same punch reuses them (they
#: were a fifth of a new rounded_graded coating's solve).
GAP_MOMENTS = KeptValues(32)
