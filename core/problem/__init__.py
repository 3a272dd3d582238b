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
from core.problem.result import ContactSolution, SolveOutcome
from core.problem.statements import (
    QUANTITIES,
    STATEMENTS,
    ModalSystem,
    UnresolvedOperator,
    modal_system,
    statement_number,
)

__all__ = [
    "as_function",
    "check_values",
    "ContactSolution",
    "Geometry",
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
