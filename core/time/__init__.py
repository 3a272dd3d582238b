"""Time stepping of the modal Volterra equations of a creeping base.

``integration.py`` holds ``solve_degenerate`` (kernels that are sums of exponentials)
and ``solve_general`` (any kernel); the steppers behind them:

- ``exponential.py``, ``exponential_weights.py``, ``exponential_modes.py``: exponential
  collocation for kernels that are sums of exponentials (the default; error from three
  grids); ``exponential_moments``, the integrals of ``exp(-x (1 - u)) u^k`` on [0, 1]
  its weights are made of (the contact march's memory integrates its decays by them);
- ``radau.py``: adaptive Radau IIA, the fallback and the reference; ``JUMP_SIDE``, how
  far from a load's jump each side of it is read (the time grids of the contact march
  hold both sides);
- ``product_quadrature.py``: a general kernel by the product trapezoid rule with
  Richardson extrapolation;
- ``volterra.py``: the problem and solution types the steppers share;
- ``grids.py``: ``time_grid``, the fixed grids of the steppers that march on them (the
  collocation engine, the unilateral contact march, the bare base's growing zone);
- ``jumps.py``: ``undeclared_jumps``, the jumps of a given history its caller did not
  declare (found by sampling and bisection).
"""

from __future__ import annotations

from core.time.exponential_weights import moments as exponential_moments
from core.time.grids import history_key_times, time_grid
from core.time.integration import solve_degenerate
from core.time.jumps import undeclared_jumps
from core.time.product_quadrature import solve_general
from core.time.radau import JUMP_SIDE
from core.time.volterra import ModalProblem

__all__ = [
    "JUMP_SIDE",
    "history_key_times",
    "exponential_moments",
    "ModalProblem",
    "solve_degenerate",
    "solve_general",
    "time_grid",
    "undeclared_jumps",
]
