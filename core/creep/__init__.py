"""Creep and aging of the base, and the kernels the solver steps with.

- ``models.py``: the creep models (elastic, exponential, Arutyunyan aging, Prony series,
  user kernel) giving ``E(age)``, ``C(t, tau)`` and the kernel ``K(t, tau)``, and
  ``creep_model_from_spec`` for scene files;
- ``kernels.py``: those kernels in the solver's time (``DegenerateKernel``: sums of
  exponentials, stepped in O(1) per mode and step);
- ``inputs.py``: the checked inputs of the models (messages naming the field);
- ``design_codes.py``, ``code_formulas.py``, ``code_inputs.py``: fib Model Code 2010 and
  EN 1992-1-1 Annex B creep, clause by clause, and ``creep_coefficient_curve``;
- ``kernel_fit.py``, ``fitted_kernel.py``: any kernel fitted by a sum of exponentials,
  with its measured ``fit_error`` (``stepping_kernel``).
"""

from __future__ import annotations

from core.creep.code_inputs import CEMENT_CLASSES, CUBE_STRENGTHS, RANGES, STRENGTH_CLASS
from core.creep.design_codes import (
    DEFAULT_TOL_LADDER,
    FIT_ERROR_SHARE,
    CodeCreep,
    creep_coefficient_curve,
    default_tolerance,
    fit_advice,
)
from core.creep.design_codes import MAX_DURATION as MAX_CODE_DURATION
from core.creep.design_codes import SPEC_FIELDS as CODE_SPEC_FIELDS
from core.creep.fitted_kernel import integrated_kernel
from core.creep.inputs import MAX_RATE, MAX_TERMS
from core.creep.kernel_fit import stepping_kernel
from core.creep.models import (
    KNOWN_MODELS,
    SPEC_FIELDS,
    TERM_FIELDS,
    Elastic,
    UserKernel,
    creep_model_from_spec,
)

__all__ = [
    "CEMENT_CLASSES",
    "CODE_SPEC_FIELDS",
    "CodeCreep",
    "creep_coefficient_curve",
    "creep_model_from_spec",
    "default_tolerance",
    "DEFAULT_TOL_LADDER",
    "FIT_ERROR_SHARE",
    "fit_advice",
    "integrated_kernel",
    "Elastic",
    "KNOWN_MODELS",
    "MAX_CODE_DURATION",
    "MAX_RATE",
    "MAX_TERMS",
    "RANGES",
    "SPEC_FIELDS",
    "stepping_kernel",
    "STRENGTH_CLASS",
    "CUBE_STRENGTHS",
    "TERM_FIELDS",
    "UserKernel",
]
