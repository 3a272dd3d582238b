"""The dimensionless problem itself: its inputs, its statements and the result every engine gives.

- :mod:`~core.problem.inputs`: the validated inputs, split into what an engine prepares
  once (:class:`Geometry`: ``lam``, ``m``, ``g``, breakpoints, ``tol``;
  :func:`validate_geometry`) and what a solve takes (:class:`TimeInputs`: times, ``c``,
  the creep kernel, the two given loads; :func:`validate_time_inputs`); each refusal names
  the argument;
- :mod:`~core.problem.statements`: the four statements (:data:`STATEMENTS`, which two of
  delta, alpha, P, M are given), the modal decomposition of the Galerkin rows
  (:func:`modal_system`) and :class:`UnresolvedOperator`, how an engine declines;
- :mod:`~core.problem.result`: :class:`ContactSolution`, the result type of every engine,
  and the schema of its ``info`` (:data:`INFO_KEYS`, documented there); the one
  acceptance rule :func:`accepts`.
"""

from __future__ import annotations

from core.problem.inputs import (
    Geometry,
    Scalar,
    TimeInputs,
    as_function,
    check_held_compliance,
    check_values,
    validate_geometry,
    validate_time_inputs,
    validate_times,
)
from core.problem.result import (
    INFO_KEYS,
    UNRESOLVED_ADVICE,
    ContactSolution,
    SolveOutcome,
    accepts,
    positions,
    pressure_positions,
)
from core.problem.statements import (
    QUANTITIES,
    STATEMENTS,
    ModalSystem,
    UnresolvedOperator,
    check_mode_probe,
    modal_system,
    mode_probe,
    real_modes,
    statement_number,
)

__all__ = [
    "accepts",
    "as_function",
    "check_held_compliance",
    "check_mode_probe",
    "check_values",
    "ContactSolution",
    "Geometry",
    "INFO_KEYS",
    "modal_system",
    "mode_probe",
    "positions",
    "pressure_positions",
    "ModalSystem",
    "QUANTITIES",
    "real_modes",
    "Scalar",
    "SolveOutcome",
    "statement_number",
    "STATEMENTS",
    "TimeInputs",
    "UnresolvedOperator",
    "validate_geometry",
    "validate_time_inputs",
    "validate_times",
    "UNRESOLVED_ADVICE",
]
