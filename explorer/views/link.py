"""The page's address follows the view on screen: scene, time, open tab, pins, the
Study tab's settings and the Fit tab's readings and fields."""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Any

import panel as pn

from ..model import DesignLimits, Screen, scene_with_limits, study_settings, view_query
from ..solving import SolveController
from .loop import PageLoop

log = logging.getLogger(__name__)

#: The page's address follows the scene on screen at most this often [ms]: rewriting it
#: at every slider step would cost a message per step, for a link nobody copies mid-drag.
LINK_EVERY_MS = 1000


class AddressLink:
    """Writes a link that reproduces the view into the page's address bar, calmly."""

    def __init__(self, screen: Screen, controller: SolveController, loop: PageLoop,
                 location: Any, view_parts: Callable[[], tuple[int, list[Any], Any, Any]],
                 limits: DesignLimits | None = None) -> None:
        """``screen``: the result and time on screen; ``controller``: a link waits while a
        newer result is coming; ``location``: the page's address (None: not served, no
        link); ``view_parts``: the open tab, the pinned scenes, the Study tab's settings
        and the Fit tab's, asked when the link is written; ``limits``: the session's
        design limits, which the link's scene carries (as a saved scene file does)."""
        self.screen = screen
        self.limits = limits
        if limits is not None:
            limits.param.watch(lambda *_: self.schedule(),
                               [n for n in limits.param if n != "name"])
        self.controller = controller
        self.loop = loop
        self.location = location
        self.view_parts = view_parts
        self._due = False
        self.linked = ""
        self._study: dict[str, Any] | None = None  # the last good Study settings
        # The address bar is written by the page itself when this hidden box changes:
        # Panel's location model delayed an update until the next one (its push waits
        # for the document's first idle signal, which a replaced view never sees).
        self.address = pn.widgets.TextInput(value="", visible=False)
        self.address.jscallback(value="if (cb_obj.value) { window.history.replaceState("
                                      "null, '', cb_obj.value) }")

    def schedule(self) -> None:
        """Update the address within :data:`LINK_EVERY_MS` (one update per interval)."""
        if self.location is not None and self.screen.shown() is not None and not self._due:
            self._due = True
            self.loop.later(self.update, LINK_EVERY_MS)

    def update(self) -> None:
        """Put the view on screen into the page's address (a link that reproduces it)."""
        self._due = False
        view = self.screen.shown()
        if view is None or self.location is None or self.controller.busy:
            return  # a newer result is coming, and will ask again
        try:
            tab, pins, study, fit = self.view_parts()
            if study is not None:
                try:
                    study_settings(study)
                    self._study = study
                except ValueError:
                    # a study setting being typed (points 1000, an empty box): the Study
                    # tab names it; the link keeps the last good settings and the scene
                    study = self._study
            scene = (view.scene if self.limits is None
                     else scene_with_limits(view.scene, self.limits))
            query = view_query(scene, self.screen.time_index, tab, pins, study, fit)
            # the whole query at once: the values are URL-safe already (base64url, digits)
            link = "?" + "&".join(f"{k}={v}" for k, v in query.items() if v)
            if link != self.linked:
                self.address.value = link
                self.linked = link
        except Exception:  # the link is a convenience; the page must not fail for it
            log.exception("could not update the link")
