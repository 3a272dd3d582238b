"""Undo and reset of the scene on screen (the scenes themselves live in an UndoStack)."""

from __future__ import annotations

from typing import Any

import param

from .state import ExplorerState
from .undo import UndoStack


class SceneHistory(param.Parameterized):
    """Remembers each scene shown, to go back one change or to the scene as loaded."""

    can_undo = param.Boolean(default=False, doc="Whether there is a change to undo.")

    def __init__(self, state: ExplorerState, **params: Any) -> None:
        super().__init__(**params)
        self.state = state
        self.stack = UndoStack()
        self._undoing = False
        #: the scene as it was loaded (the preset, the file, the link)
        self.loaded: dict[str, Any] | None = None

    def remember(self) -> None:
        """Keep the scene now in the state (a change happened)."""
        if self._undoing:
            return
        try:
            self.stack.push(self.state.to_scene())
        except ValueError:
            return  # a state that is no scene (its message comes with the solve)
        self.can_undo = self.stack.can_undo

    def undo(self) -> None:
        """Go back to the scene before the last change."""
        scene = self.stack.undo()
        if scene is None:
            return
        self._undoing = True
        try:
            self.state.load_scene(scene)
        finally:
            self._undoing = False
        self.can_undo = self.stack.can_undo

    def reset(self) -> None:
        """Back to the scene as it was loaded (the preset, the file, the link)."""
        if self.loaded is not None:
            self.state.load_scene(self.loaded)
