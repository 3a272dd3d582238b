"""core.engines."""

from __future__ import annotations

from core.engines.registry import (
    DEFAULT_METHOD,
    DEFAULT_ORDER,
    ENGINES,
    Engine,
    engine_options,
    get_engine,
    register_engine,
)

__all__ = [
    "DEFAULT_METHOD",
    "DEFAULT_ORDER",
    "Engine",
    "engine_options",
    "ENGINES",
    "get_engine",
    "register_engine",
]
