"""core.coating."""

from __future__ import annotations

from core.coating.fem_check import solve_stack
from core.coating.fem_stack import CoatingStrip, Stack
from core.coating.model import (
    DEFAULT_INTERFACE,
    DEFAULT_MODEL_TOL,
    INTERFACES,
    MODEL_TOL_RANGE,
    NEGLIGIBLE_SHARE,
    layer_compliance,
    model_error_estimate,
    model_error_map,
    tilt_share,
)

__all__ = [
    "CoatingStrip",
    "DEFAULT_INTERFACE",
    "DEFAULT_MODEL_TOL",
    "INTERFACES",
    "layer_compliance",
    "model_error_estimate",
    "model_error_map",
    "MODEL_TOL_RANGE",
    "NEGLIGIBLE_SHARE",
    "solve_stack",
    "Stack",
    "tilt_share",
]
