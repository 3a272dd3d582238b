"""The memory budget of the solver's stage caches, shared by all engines, and the freed
memory given back to the system.

The caches themselves stay inside their engines (no other module may rebind or clear
them); this module bounds them together and reads their bounds, which the explorer
reports per worker process.
"""

from __future__ import annotations

import ctypes
import ctypes.util
from typing import Any

_MiB = 2**20
#: Upper bound of the memory all stage caches of the solver may hold together [bytes].
STAGE_CACHE_BYTES = 512 * _MiB


def set_stage_cache_budget(total_bytes: int) -> None:
    """Bound the solver's stage caches together by ``total_bytes`` [bytes].

    The budget is shared among the stages in their default proportions (the default
    total is :data:`STAGE_CACHE_BYTES`). A process among several that solve (the
    explorer's worker processes) takes its share of the machine's budget this way. Items
    beyond a smaller bound are dropped at the next store.
    """
    if isinstance(total_bytes, bool) or not (isinstance(total_bytes, int) and total_bytes > 0):
        raise ValueError(f"total_bytes: must be a positive integer, got {total_bytes!r}")
    # Imported here: the exact layered kernel's module loads scipy.fft, which a scene
    # without uniform layers never needs.
    from core.engines.layered import share_budget
    from core.engines.nystrom import PREPARED, PREPARED_BYTES
    from core.engines.projection import DEFAULT_STAGE_BYTES, PROJECTION_CACHES

    default_total = sum(DEFAULT_STAGE_BYTES.values())
    # The default engine's prepared geometries, and the exact layered kernel's operators,
    # take their share in the same proportion.
    PREPARED.max_bytes = max(1, PREPARED_BYTES * total_bytes // default_total)
    share_budget(total_bytes, default_total)
    for cache in PROJECTION_CACHES:
        cache.max_bytes = max(1, DEFAULT_STAGE_BYTES[cache.name] * total_bytes
                              // default_total)


def stage_cache_bounds() -> dict[str, int]:
    """Each projection stage cache's name and its current bound on held memory [bytes]."""
    from core.engines.projection import PROJECTION_CACHES

    return {cache.name: cache.max_bytes for cache in PROJECTION_CACHES}


def stage_cache_bytes() -> int:
    """The bound on the memory all projection stage caches may hold together [bytes]."""
    return sum(stage_cache_bounds().values())


def _malloc_trim() -> Any:
    name = ctypes.util.find_library("c")
    try:
        return ctypes.CDLL(name).malloc_trim if name else None
    except (OSError, AttributeError):  # not glibc: memory is returned as the allocator does
        return None


_MALLOC_TRIM = _malloc_trim()


def release_freed_memory() -> bool:
    """Give the heap memory this process has freed back to the system.

    glibc keeps the pages of freed memory for the process's own reuse, so a long-running
    process (a server, its solver workers) stays at its peak after heavy work; this asks
    it to return them (``malloc_trim``). Costs well under a millisecond after ordinary
    solves, ~70 ms after an FE coating check.

    Returns
    -------
    bool
        Whether any memory was returned (always False without glibc).
    """
    return bool(_MALLOC_TRIM(0)) if _MALLOC_TRIM is not None else False
