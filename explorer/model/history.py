"""Undo and reset of the scene on screen (the scenes themselves live in an UndoStack)."""

from __future__ import annotations

import time
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
        # when the session last sat idle, its answers in [s, monotonic]; None: not told
        self._idle_since: float | None = None
        # the drag of a slider under way (its id), if one: its steps are one step of undo
        self._gestures = 0
        self._gesture: int | None = None

    def drag_step(self) -> None:
        """A slider's handle moved (a drag's step, or a key press): the changes from here
        to the page's release of it (:meth:`drag_ended`) are one step of undo, however far
        apart they reach the session."""
        if self._gesture is None:
            self._gestures += 1
            self._gesture = self._gestures

    def drag_ended(self) -> None:
        """The page released a slider's handle (its last value, if new, is in the state):
        the next change starts a step of its own."""
        self._gesture = None

    def went_idle(self) -> None:
        """The session's answers are in and drawn (now, on the monotonic clock): a change
        from here on follows a pause of the user's, whose length decides whether it joins
        the change before (:meth:`UndoStack.push`)."""
        self._idle_since = time.monotonic()

    def remember(self) -> None:
        """Keep the scene now in the state (a change happened)."""
        if self._undoing:
            return
        try:
            self.stack.push(self.state.to_scene(), idle_since=self._idle_since,
                            gesture=self._gesture)
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
