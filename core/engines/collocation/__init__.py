"""core.engines.collocation."""

from __future__ import annotations

from core.engines.collocation.engine import COLLOCATION, CollocationEngine
from core.engines.collocation.solve import CollocationSolution, solve_collocation
from core.engines.collocation.steps import time_grid

__all__ = [
    "COLLOCATION",
    "CollocationEngine",
    "CollocationSolution",
    "solve_collocation",
    "time_grid",
]
