"""A base for values that never change once built (profiles, parsed formulas).

They are shared between scenes, sessions and threads through caches, so a change made
through one reference would reach every holder: setting or deleting an attribute raises.
Subclasses set their attributes once, in ``__init__``, with ``object.__setattr__``.
"""

from __future__ import annotations

from typing import Any


class Immutable:
    """Refuses ``obj.name = value`` and ``del obj.name`` (AttributeError naming the class)."""

    __slots__ = ()

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError(f"{type(self).__name__} is immutable")

    def __delattr__(self, name: str) -> None:
        raise AttributeError(f"{type(self).__name__} is immutable")
