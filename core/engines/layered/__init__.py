"""core.engines.layered."""

from __future__ import annotations

from core.engines.layered.answer import (
    LIFT_OFF_SHARE,
    layered_declines,
    solve_scene_layered,
    uniform_layers,
)
from core.engines.layered.cache import gap_key, share_budget, stack_key
from core.engines.layered.galerkin import COARSE_TOL, MAX_MODES, default_modes
from core.engines.layered.solve import (
    COARSE_ERROR_FLOOR,
    ERROR_FLOOR,
    MAX_RATIO,
    PRESSURE_REACH,
    LayeredResponse,
    cached_response,
)

__all__ = [
    "cached_response",
    "COARSE_ERROR_FLOOR",
    "COARSE_TOL",
    "default_modes",
    "ERROR_FLOOR",
    "gap_key",
    "layered_declines",
    "LayeredResponse",
    "LIFT_OFF_SHARE",
    "MAX_MODES",
    "MAX_RATIO",
    "PRESSURE_REACH",
    "share_budget",
    "solve_scene_layered",
    "stack_key",
    "uniform_layers",
]
