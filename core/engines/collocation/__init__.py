"""core.engines.collocation."""

from __future__ import annotations

from core.engines.collocation.steps import time_grid

__all__ = [
    "time_grid",
]
