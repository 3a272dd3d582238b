"""The projection engine's stage caches (:mod:`core.cache`).

Each stage of the projection method keeps its results in one bounded cache here;
:func:`core.budget.set_stage_cache_budget` shares the solver's total among them.
"""

from __future__ import annotations

from core.cache import StageCache

# Bytes per stage sum to STAGE_CACHE_BYTES (512 MiB), sized from the largest items
# measured on the hard cases of tests/support/scenes.py: operator and correction ~9 MiB,
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
PROJECTION_CACHES = (_PANELS, _OPERATOR, _BASIS, _GALERKIN, _CORRECTION, _GAP, _MODES, _RESPONSE,
           _SAMPLE_ROWS)
#: Each cache's default bound [bytes]: the proportions of the shared budget.
DEFAULT_STAGE_BYTES = {cache.name: cache.max_bytes for cache in PROJECTION_CACHES}
