"""The projection engine's stage caches and their shared memory budget (:mod:`core.cache`).

Each stage of :func:`core.solver.solve_dimensionless` with ``method="projection"`` keeps its
results in one bounded cache here; :func:`set_stage_cache_budget` shares a total among them.
"""

from __future__ import annotations

from core.cache import StageCache

# Bytes per stage sum to STAGE_CACHE_BYTES (512 MiB), sized from the largest items
# measured on the hard cases of benchmarks/scenes.py: operator and correction ~9 MiB,
# basis ~8 MiB, all modes of a scene ~3 MiB, responses ~5 MiB.
_MiB = 2**20
_PANELS = StageCache("panels", max_items=32, max_bytes=8 * _MiB)
_OPERATOR = StageCache("operator", max_items=8, max_bytes=128 * _MiB)
_BASIS = StageCache("basis", max_items=16, max_bytes=64 * _MiB)
_GALERKIN = StageCache("galerkin", max_items=32, max_bytes=32 * _MiB)
_CORRECTION = StageCache("correction", max_items=8, max_bytes=128 * _MiB)
_GAP = StageCache("gap", max_items=32, max_bytes=8 * _MiB)
_MODES = StageCache("modes", max_items=256, max_bytes=64 * _MiB)
_RESPONSE = StageCache("response", max_items=256, max_bytes=64 * _MiB)
_SAMPLE_ROWS = StageCache("sample_rows", max_items=16, max_bytes=16 * _MiB)
_STAGES = (_PANELS, _OPERATOR, _BASIS, _GALERKIN, _CORRECTION, _GAP, _MODES, _RESPONSE,
           _SAMPLE_ROWS)
_DEFAULT_STAGE_BYTES = {cache.name: cache.max_bytes for cache in _STAGES}
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
    default_total = sum(_DEFAULT_STAGE_BYTES.values())
    from core.layered_cache import share_budget
    from core.prepared import PREPARED, PREPARED_BYTES

    # The default engine's prepared geometries, and the exact layered kernel's operators,
    # take their share in the same proportion.
    PREPARED.max_bytes = max(1, PREPARED_BYTES * total_bytes // default_total)
    share_budget(total_bytes, default_total)
    for cache in _STAGES:
        cache.max_bytes = max(1, _DEFAULT_STAGE_BYTES[cache.name] * total_bytes
                              // default_total)
