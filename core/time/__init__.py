"""core.time."""

from __future__ import annotations

from core.time.integration import solve_degenerate
from core.time.product_quadrature import solve_general
from core.time.volterra import ModalProblem

__all__ = [
    "ModalProblem",
    "solve_degenerate",
    "solve_general",
]
