"""core.engines.nystrom."""

from __future__ import annotations

from core.engines.nystrom.prepared import PREPARED, PREPARED_BYTES, prepare, solve_with_prepared

__all__ = [
    "prepare",
    "PREPARED",
    "PREPARED_BYTES",
    "solve_with_prepared",
]
