"""The result type of :func:`core.solver.solve_dimensionless` (full contact)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from core.discretize import Basis


class SolveOutcome:
    """How a solve went, read from its ``info`` dict: shared by the result types of both
    contact models (:class:`ContactSolution`, :class:`core.contact.result.UnilateralSolution`)."""

    info: dict[str, Any]

    @property
    def success(self) -> bool:
        """Whether the error estimates meet the requested tolerance."""
        return bool(self.info["success"])

    @property
    def message(self) -> str:
        """A one-line account of how the solve went."""
        return str(self.info["message"])

    @property
    def flags(self) -> list[str]:
        """Validity flags: ``tol_not_met``, and per contact model ``contact_lost``,
        ``unresolved_input`` (full) or ``contact_set_unverified`` (unilateral)."""
        return list(self.info["flags"])


@dataclass(frozen=True)
class ContactSolution(SolveOutcome):
    """The answer of :func:`solve_dimensionless` (all quantities dimensionless).

    ``times`` (T,), ``settlement`` (delta), ``tilt`` (alpha), ``force`` (P), ``moment`` (M)
    as arrays over ``times``; ``pressure(x)`` gives q at points of [-1, 1] (shape
    ``(len(x), T)``); ``info`` holds ``error_estimate`` (relative, see the module notes),
    ``seconds``, ``flags``, ``message``, ``success``, ``n_modes``, ``n_steps``, ``stages``,
    ``contact`` (``"full"``). ``contact_set`` holds, per time, the intervals of x where
    q > 0: ``[(-1.0, 1.0)]`` (full contact is assumed).
    """

    times: np.ndarray
    settlement: np.ndarray
    tilt: np.ndarray
    force: np.ndarray
    moment: np.ndarray
    info: dict[str, Any]
    _basis: Basis = field(repr=False)
    _coefficients: np.ndarray = field(repr=False)  # a_j(t), shape (n, T)
    _c: np.ndarray = field(repr=False)  # c(t) at the times
    _m: Callable[[np.ndarray], np.ndarray] = field(repr=False)
    _g: Callable[[np.ndarray], np.ndarray] = field(repr=False)
    #: q(x) at points x, shape (len(x), T), for engines without a basis (Nystrom).
    _evaluate: Callable[[np.ndarray], np.ndarray] | None = field(default=None, repr=False)
    contact_set: list[list[tuple[float, float]]] = field(default_factory=list)

    def pressure(self, x: np.ndarray) -> np.ndarray:
        """Contact pressure q(x, t) at points ``x`` of [-1, 1], shape ``(len(x), len(times))``.

        ``q = (-g(x)/c(t) + sum_j a_j(t) p_j(x)) / m(x)`` (dimensionless, the seed's (18)).
        """
        x = np.atleast_1d(np.asarray(x, dtype=float))
        if np.any(~np.isfinite(x)) or np.any(np.abs(x) > 1.0):
            raise ValueError("x: pressure is defined on [-1, 1] only")
        if self._evaluate is not None:
            return self._evaluate(x)
        phi = self._basis.evaluate(x, self._coefficients.shape[0])
        mq = phi @ self._coefficients - np.outer(self._g(x), 1.0 / self._c)
        return mq / self._m(x)[:, None]
