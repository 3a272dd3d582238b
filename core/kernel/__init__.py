"""core.kernel.plane."""

from __future__ import annotations

from core.kernel.layered import (
    COARSE_PANEL_DEGREE,
    PANEL_DEGREE,
    RegularPartTable,
    UniformLayer,
    symbol_at_infinity,
    table_cost,
)
from core.kernel.log_moments import legendre_log_moments
from core.kernel.values import FULL_ACCURACY, kernel_block, kernel_regular

__all__ = [
    "COARSE_PANEL_DEGREE",
    "FULL_ACCURACY",
    "kernel_block",
    "kernel_regular",
    "legendre_log_moments",
    "PANEL_DEGREE",
    "RegularPartTable",
    "symbol_at_infinity",
    "table_cost",
    "UniformLayer",
]
