"""What the solver's stage caches may hold, for callers outside ``core``.

The caches themselves stay private to :mod:`core.solver` (another module must not
rebind or clear them); this module reads their bounds, which the explorer reports per
worker process and tests compare with :func:`core.solver.set_stage_cache_budget`.
"""

from __future__ import annotations


def stage_cache_bounds() -> dict[str, int]:
    """Each solver stage cache's name and its current bound on held memory [bytes]."""
    from core import solver

    return {cache.name: cache.max_bytes for cache in solver._STAGES}


def stage_cache_bytes() -> int:
    """The bound on the memory all solver stage caches may hold together [bytes]."""
    return sum(stage_cache_bounds().values())
