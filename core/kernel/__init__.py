"""The kernels of the integral equation: the layer kernel and the exact stack kernel.

- ``plane.py``: the plane-strain kernel ``k_pl(s)`` of a layer on a rigid frictionless
  base (the seed's ``L(u)/u``) to rounding, and its regular part ``k_pl(s) + ln|s|``;
- ``values.py``: the same kernel to a chosen accuracy (``kernel_block``), as the engines
  evaluate it;
- ``log_moments.py``: the Legendre moments of ``ln|z - t|`` used by product integration;
- ``layered.py``: the exact plane-strain kernel of uniform coating layers (smooth or
  bonded) on the base.
"""

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
from core.kernel.values import (
    FULL_ACCURACY,
    KERNEL_DECAY,
    KERNEL_ENVELOPE,
    kernel_block,
    kernel_regular,
)

__all__ = [
    "COARSE_PANEL_DEGREE",
    "FULL_ACCURACY",
    "KERNEL_DECAY",
    "KERNEL_ENVELOPE",
    "kernel_block",
    "kernel_regular",
    "legendre_log_moments",
    "PANEL_DEGREE",
    "RegularPartTable",
    "symbol_at_infinity",
    "table_cost",
    "UniformLayer",
]
