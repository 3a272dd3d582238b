"""core.engines.projection."""

from __future__ import annotations

from core.engines.projection.caches import DEFAULT_STAGE_BYTES, PROJECTION_CACHES
from core.engines.projection.engine import PROJECTION, ProjectionEngine, ProjectionSetup
from core.engines.projection.solve import SUCCESS_MARGIN, solve_projection
from core.engines.projection.stages import validate_inputs

__all__ = [
    "DEFAULT_STAGE_BYTES",
    "PROJECTION",
    "PROJECTION_CACHES",
    "ProjectionEngine",
    "ProjectionSetup",
    "solve_projection",
    "SUCCESS_MARGIN",
    "validate_inputs",
]
