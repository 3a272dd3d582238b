"""Undo and reset of the scene on screen (the scenes themselves live in an UndoStack)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ..model import UndoStack

if TYPE_CHECKING:
    from ..app import ExplorerApp


class SceneHistory:
    """Remembers each scene shown, to go back one change or to the scene as loaded."""

    def __init__(self, app: ExplorerApp) -> None:
        self.app = app
        self.stack = UndoStack()
        self._undoing = False
        #: the scene as it was loaded (the preset, the file, the link)
        self.loaded: dict[str, Any] | None = None

    def remember(self) -> None:
        """Keep the scene now in the state (a change happened)."""
        app = self.app
        if self._undoing:
            return
        try:
            self.stack.push(app.state.to_scene())
        except ValueError:
            return  # a state that is no scene (its message comes with the solve)
        if app._views:
            app.undo_button.disabled = not self.stack.can_undo

    def undo(self) -> None:
        """Go back to the scene before the last change."""
        scene = self.stack.undo()
        if scene is None:
            return
        self._undoing = True
        try:
            self.app.state.load_scene(scene)
        finally:
            self._undoing = False
        self.app.undo_button.disabled = not self.stack.can_undo

    def reset(self) -> None:
        """Back to the scene as it was loaded (the preset, the file, the link)."""
        if self.loaded is not None:
            self.app.state.load_scene(self.loaded)
