"""core.engines.projection."""

from __future__ import annotations

from core.engines.projection.caches import DEFAULT_STAGE_BYTES, PROJECTION_CACHES
from core.engines.projection.solve import solve_projection
from core.engines.projection.stages import validate_inputs

__all__ = [
    "DEFAULT_STAGE_BYTES",
    "PROJECTION_CACHES",
    "solve_projection",
    "validate_inputs",
]
