"""A rigid punch on the bare base that creeps or ages: elastic unit responses and scalar
Volterra equations in time.

Without coating the coating term ``c(t) m q`` vanishes and the problem is

    (I - V) F q*(., t) = delta*(t) + alpha(t) t - g*(t)

(``q* = 2 (1 - nu^2) q / E(t)``, the model notes' scaling). ``V`` acts on time alone and
``F`` on space alone, so they commute: ``Q = (I - V) q*`` solves the elastic problem,
``Q = Q_g + delta* Q_delta + alpha Q_alpha`` with the unit responses of
:class:`core.engines.layered.LayeredResponse` (exact layered kernel, empty stack). Hence

    q*(t) = Q_g w_1(t) + Q_delta w_delta(t) + Q_alpha w_alpha(t),   w_f = (I - V)^-1 f,

three scalar Volterra equations of the second kind (``w_1`` for the gap's constant 1;
``w_delta``, ``w_alpha`` for the given kinematics), and a given force or moment enters
through ``(I - V) P* = P_g + delta* P_delta + alpha P_alpha`` (and likewise M*): ``V P*``
is a by-product of the same stepping (:class:`core.time.ModalProblem`'s known functions).
The unknown kinematics are then a 2 x 2 solve at each time, and their ``w`` follow
without another equation (``(I - V)^-1`` of a known combination is that combination of
the ``w``'s: e.g. ``w_delta = (P* - P_g w_1 - P_alpha w_alpha) / P_delta``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from core.creep import stepping_kernel
from core.engines.layered.solve import LayeredResponse, _chebyshev_rows
from core.time import ModalProblem, solve_degenerate, solve_general

__all__ = ["BareCreepAnswer", "TIME_SHARE", "solve_bare_creep"]

#: The time stepping aims this many times below tol: its step-doubling estimate read up
#: to ~20x the true error on decaying creep (the floor of the default engine's aim, which
#: otherwise takes half of what its panel rule and the kernel's fit leave of tol:
#: ``time_tolerance`` in core/engines/nystrom/prepared.py).
TIME_SHARE = 30.0


@dataclass(frozen=True)
class BareCreepAnswer:
    """The dimensionless histories over ``times`` (``settlement`` delta*, ``tilt`` alpha,
    ``force`` P*, ``moment`` M*), the weights ``w`` (3, times) of the unit responses in
    ``q*`` (the gap's, the settlement's, the tilt's), the time stepping's estimate
    ``time_error`` (the creep kernel's sum-of-exponentials fit ``fit_error`` included),
    ``steps``, ``success`` and ``message``."""

    settlement: np.ndarray
    tilt: np.ndarray
    force: np.ndarray
    moment: np.ndarray
    w: np.ndarray
    time_error: float
    steps: int
    success: bool
    message: str
    fit_error: float = 0.0

    def regular_part(self, response: LayeredResponse, t: np.ndarray) -> np.ndarray:
        """``sqrt(1 - t^2) q*(t)`` at points ``t`` of [-1, 1]: (len(t), len(times))."""
        c = response.coefficients
        return _chebyshev_rows(t, c.shape[0]) @ (c @ self.w)


def _history(load: Any) -> Callable[[np.ndarray], np.ndarray]:
    if callable(load):
        return lambda tt: np.broadcast_to(np.asarray(load(tt), dtype=float), tt.shape)
    value = float(load)
    return lambda tt: np.full(tt.shape, value)


def solve_bare_creep(response: LayeredResponse, problem: Any, times: np.ndarray,
                     tol: float) -> BareCreepAnswer:
    """The four histories and the weights of ``q*`` on a bare creeping base.

    ``response``: the elastic unit responses; ``problem``: the dimensionless problem
    (``loads``, ``kernel``, ``time_breaks``); ``times``: dimensionless output times
    (>= 1); ``tol`` [-]: the time stepping aims at ``tol / TIME_SHARE``.
    """
    loads = {name: _history(load) for name, load in problem.loads.items()}
    kinematic = [n for n in ("settlement", "tilt") if n in loads]
    static = [n for n in ("force", "moment") if n in loads]
    # modes: w_1 and the w of each given kinematic history; known: the given statics
    n_modes = 1 + len(kinematic)

    def drives(tt: np.ndarray) -> np.ndarray:
        return np.stack([np.ones(tt.shape)] + [loads[n](tt) for n in kinematic])

    def known(tt: np.ndarray) -> np.ndarray:
        if not static:
            return np.zeros((0, tt.size))
        return np.stack([loads[n](tt) for n in static])

    modal = ModalProblem(d=lambda tt: np.ones((n_modes, np.size(tt))), r=drives, u=known,
                         coupling=np.zeros((n_modes, len(static))))
    kernel, fit_error = stepping_kernel(problem.kernel, float(times[-1]), 0.5 * tol)
    breaks = tuple(float(b) for b in problem.time_breaks)
    if hasattr(kernel, "rates") and hasattr(kernel, "exponential_parts"):
        sol = solve_degenerate(kernel, modal, times, tol=tol / TIME_SHARE, breaks=breaks)
    else:
        sol = solve_general(kernel, modal, times, tol=tol / TIME_SHARE, breaks=breaks)
    w_one = sol.w[0]
    w = {n: sol.w[1 + k] for k, n in enumerate(kinematic)}
    value = {n: loads[n](times) for n in loads}
    # (I - V) of a given static history, and its (I - V)^-1 is the history itself
    effective = {n: value[n] - sol.vu[k] for k, n in enumerate(static)}
    c = response.coefficients
    force = np.pi * c[0]          # P_g, P_delta, P_alpha
    moment = 0.5 * np.pi * c[1]   # M_g, M_delta, M_alpha
    rows = {"force": force, "moment": moment}
    unknown = [n for n in ("settlement", "tilt") if n not in loads]
    if unknown:
        # rows of the statics given: (I - V) S = S_g + delta S_delta + alpha S_alpha, solved
        # for the unknown kinematics; the same rows with (I - V)^-1 applied give their w
        column = {"settlement": 1, "tilt": 2}
        matrix = np.array([[rows[s][column[k]] for k in unknown] for s in static])
        rhs, rhs_w = [], []
        for s in static:
            known_part = sum(rows[s][column[k]] * value[k] for k in kinematic)
            known_w = sum(rows[s][column[k]] * w[k] for k in kinematic)
            rhs.append(effective[s] - rows[s][0] - known_part)
            rhs_w.append(value[s] - rows[s][0] * w_one - known_w)
        solved = np.linalg.solve(matrix, np.array(rhs))
        solved_w = np.linalg.solve(matrix, np.array(rhs_w))
        for k, n in enumerate(unknown):
            value[n] = solved[k]
            w[n] = solved_w[k]
    weights = np.stack([w_one, w["settlement"], w["tilt"]])
    histories = {"force": force @ weights, "moment": moment @ weights}
    for n in static:
        histories[n] = value[n]  # given: kept exactly as given
    return BareCreepAnswer(value["settlement"], value["tilt"], histories["force"],
                           histories["moment"], weights, float(sol.error_estimate + fit_error),
                           int(sol.steps), bool(sol.success), sol.message, float(fit_error))
