"""core.problem."""

from __future__ import annotations

from core.problem.inputs import (
    Geometry,
    Scalar,
    TimeInputs,
    as_function,
    check_values,
    validate_geometry,
    validate_time_inputs,
    validate_times,
)
from core.problem.result import INFO_KEYS, ContactSolution, SolveOutcome, accepts
from core.problem.statements import (
    QUANTITIES,
    STATEMENTS,
    ModalSystem,
    UnresolvedOperator,
    modal_system,
    statement_number,
)

__all__ = [
    "accepts",
    "as_function",
    "check_values",
    "ContactSolution",
    "Geometry",
    "INFO_KEYS",
    "modal_system",
    "ModalSystem",
    "QUANTITIES",
    "Scalar",
    "SolveOutcome",
    "statement_number",
    "STATEMENTS",
    "TimeInputs",
    "UnresolvedOperator",
    "validate_geometry",
    "validate_time_inputs",
    "validate_times",
]
