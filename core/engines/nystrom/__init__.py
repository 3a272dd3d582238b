"""core.engines.nystrom."""

from __future__ import annotations

from core.engines.nystrom.engine import NYSTROM, NystromEngine
from core.engines.nystrom.prepared import (
    PREPARED,
    PREPARED_BYTES,
    PreparedContact,
    prepare,
    prepared_for,
    solve_with_prepared,
)

__all__ = [
    "NYSTROM",
    "NystromEngine",
    "prepare",
    "PREPARED",
    "PREPARED_BYTES",
    "prepared_for",
    "PreparedContact",
    "solve_with_prepared",
]
