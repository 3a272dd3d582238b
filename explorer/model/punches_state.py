"""Several punches on one foundation, as the explorer holds them: the ``punches`` form of
a scene (core/SCENES.md, "Several punches").

Each punch is a :class:`PunchEntryState`: its centre [m] and, as for the single punch of
a scene, a :class:`~explorer.model.scene_parts.PunchState` (half-width and base shape)
and a :class:`~explorer.model.loading_state.LoadingState` (its two given loads). The
screen offers up to :data:`SCREEN_PUNCHES` of them; the core takes more, and a file with
more is refused by name when it is loaded. Nothing here imports Panel.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import param

from core.scene import has_punches, punches_from_dict, scene_from_dict

from .loading_state import LoadingState
from .scene_parts import PunchState

__all__ = ["SCREEN_PUNCHES", "PunchEntryState", "next_center", "validated_scene"]

#: Punches the page edits at most (add/remove): four strips already fill a drawing
#: 1000 px wide with zones a few pixels apart, and each costs a solve block.
SCREEN_PUNCHES = 4

#: Clear gap left between a punch added on screen and the rightmost one [m per m of
#: half-width]: one half-width, so that the two interact visibly yet do not touch.
ADDED_GAP = 1.0


class PunchEntryState(param.Parameterized):
    """One punch of several: its centre, its punch (half-width, shape) and its loads."""

    center = param.Number(default=0.0, softbounds=(-10.0, 10.0),
                          doc="Centre of the punch along the surface [m] (global x).")

    def __init__(self, **params: Any) -> None:
        super().__init__(**params)
        self.punch = PunchState(name=f"{self.name}.punch")
        self.loading = LoadingState(name=f"{self.name}.loading")

    @property
    def watched(self) -> list[param.Parameterized]:
        """Every parameterized part whose change alters the scene."""
        return [self, self.punch, self.loading, *self.loading.histories.values()]

    def to_dict(self) -> dict[str, Any]:
        """The punch as an entry of the scene's ``punches`` (SI units)."""
        return {"center": self.center, **self.punch.to_dict(), "loading": self.loading.to_dict()}

    def load(self, spec: Mapping[str, Any]) -> None:
        """Fill the punch from an entry of a scene's ``punches`` (assumed valid)."""
        self.punch.load({"half_width": spec["half_width"], "shape": spec.get("shape", 0.0)})
        self.loading.load(dict(spec["loading"]))
        self.center = float(spec["center"])

    def copy_from(self, other: PunchEntryState, center: float) -> None:
        """Make this punch a copy of ``other`` at ``center`` [m]."""
        self.load({**other.to_dict(), "center": center})


def next_center(entries: list[PunchEntryState]) -> float:
    """Where a punch added on screen goes [m]: right of the rightmost punch, as wide as
    it, with a clear gap of :data:`ADDED_GAP` half-widths."""
    right = max(entries, key=lambda e: e.center + e.punch.half_width)
    a = right.punch.half_width
    return right.center + (2.0 + ADDED_GAP) * a


def validated_scene(d: Mapping[str, Any]) -> Any:
    """A scene dict of either form checked by the core: a :class:`core.Scene` (one punch)
    or a :class:`core.scene.PunchesScene` (``punches``); ValueError naming the field."""
    return punches_from_dict(d) if has_punches(d) else scene_from_dict(d)
