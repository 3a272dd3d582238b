"""core.creep.models."""

from __future__ import annotations

from core.creep.code_inputs import RANGES
from core.creep.design_codes import creep_coefficient_curve
from core.creep.kernel_fit import stepping_kernel
from core.creep.models import Elastic, UserKernel, creep_model_from_spec

__all__ = [
    "creep_coefficient_curve",
    "creep_model_from_spec",
    "Elastic",
    "RANGES",
    "stepping_kernel",
    "UserKernel",
]
