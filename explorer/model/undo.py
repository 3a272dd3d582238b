"""Undo for the explorer: the scenes shown, newest last (no Panel import)."""

from __future__ import annotations

import copy
import time
from typing import Any

from .pins import NOT_MECHANICS, flatten

#: Scenes kept for undo (a scene dict is a few kB).
UNDO_DEPTH = 50
#: Changes of the same one number one way, each within this many seconds [s] of the last,
#: are one step of undo: a drag (one undo after dragging the force from 500 to 1128 kN/m
#: took ten presses, back through every value the handle passed, a teacher's audit). The
#: seconds are those the session sat idle, its last answer in (see :meth:`UndoStack.push`):
#: on a loaded server a drag's steps reached the session more than a second apart while it
#: drew the answers before them, and one drag made two steps of undo.
COALESCE_S = 1.0


def changed_fields(before: dict[str, Any], after: dict[str, Any]) -> set[str]:
    """The scene fields (flattened paths, ``loading.force``) that differ, but for its name
    and description (the first step of a drag renames the scene "(modified)")."""
    a, b = flatten(before), flatten(after)
    return {k for k in a.keys() | b.keys()
            if a.get(k) != b.get(k) and not k.startswith(NOT_MECHANICS)}


def _one_way(first: dict[str, Any], second: dict[str, Any], third: dict[str, Any],
             field: str) -> bool:
    """Whether ``field`` moves the same way from ``first`` to ``second`` as from
    ``second`` to ``third`` (numbers; a drag's steps do, where values typed one after the
    other, 1e6 then 500 then 2e6, need not)."""
    values = [flatten(scene).get(field) for scene in (first, second, third)]
    if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
        return False
    a, b, c = (float(v) for v in values)
    return (b - a) * (c - b) > 0


class UndoStack:
    """The scenes a session went through; :meth:`undo` gives the one before the current."""

    def __init__(self, depth: int = UNDO_DEPTH) -> None:
        self.depth = depth
        self._scenes: list[dict[str, Any]] = []
        self._last = float("-inf")  # when the last scene was pushed [s, monotonic]
        self._last_gesture: int | None = None  # the drag the last scene came from

    def push(self, scene: dict[str, Any], now: float | None = None,
             idle_since: float | None = None, gesture: int | None = None) -> None:
        """Record ``scene`` as the current one (a repeat of the current is ignored). A
        change of the same one number as the last change, the same way, within
        :data:`COALESCE_S` of it (``now`` [s], default the monotonic clock), replaces the
        last scene: one undo goes back to before them all.

        ``idle_since`` [s, the same clock]: when the session last sat idle (its answers
        in), if its caller knows. The pause is then counted from there: a change that
        came while the answer to the last one was still being solved or drawn is no
        pause (on a loaded server a drag's steps reach the session seconds apart), and
        one after the session went idle pauses from that moment. None: from the last
        change.

        ``gesture``: the drag of a slider the change is a step of (an id, from the first
        step to the page's release of the handle; None: none). A step of the same drag
        as the last change, of the same one number, joins it whichever way and however
        long after: a page or a server too busy to keep up spaced one drag's steps more
        than a second apart, and one undo went back to the middle of the drag."""
        if self._scenes and self._scenes[-1] == scene:
            return
        now = time.monotonic() if now is None else float(now)
        since = self._last
        if idle_since is not None and since > float("-inf"):  # (not just after an undo)
            # busy from the last change until now: no pause at all
            since = now if idle_since < since else float(idle_since)
        recent, self._last = now - since <= COALESCE_S, now
        same_drag = gesture is not None and gesture == self._last_gesture
        self._last_gesture = gesture
        if (recent or same_drag) and len(self._scenes) >= 2:
            last = changed_fields(self._scenes[-2], self._scenes[-1])
            if (len(last) == 1 and changed_fields(self._scenes[-1], scene) == last
                    and (same_drag or _one_way(self._scenes[-2], self._scenes[-1], scene,
                                               *last))):
                self._scenes[-1] = copy.deepcopy(scene)
                return
        self._scenes.append(copy.deepcopy(scene))
        del self._scenes[: -self.depth]

    def undo(self) -> dict[str, Any] | None:
        """The scene before the current one (which is dropped), or None at the start."""
        if len(self._scenes) < 2:
            return None
        self._scenes.pop()
        # the next change starts a step of its own (one within a second of the drag just
        # undone was merged into the step it went back to, a review)
        self._last = float("-inf")
        self._last_gesture = None
        return copy.deepcopy(self._scenes[-1])

    @property
    def can_undo(self) -> bool:
        return len(self._scenes) > 1
