"""Undo for the explorer: the scenes shown, newest last (no Panel import)."""

from __future__ import annotations

import copy
from typing import Any

#: Scenes kept for undo (a scene dict is a few kB).
UNDO_DEPTH = 50


class UndoStack:
    """The scenes a session went through; :meth:`undo` gives the one before the current."""

    def __init__(self, depth: int = UNDO_DEPTH) -> None:
        self.depth = depth
        self._scenes: list[dict[str, Any]] = []

    def push(self, scene: dict[str, Any]) -> None:
        """Record ``scene`` as the current one (a repeat of the current is ignored)."""
        if self._scenes and self._scenes[-1] == scene:
            return
        self._scenes.append(copy.deepcopy(scene))
        del self._scenes[: -self.depth]

    def undo(self) -> dict[str, Any] | None:
        """The scene before the current one (which is dropped), or None at the start."""
        if len(self._scenes) < 2:
            return None
        self._scenes.pop()
        return copy.deepcopy(self._scenes[-1])

    @property
    def can_undo(self) -> bool:
        return len(self._scenes) > 1
