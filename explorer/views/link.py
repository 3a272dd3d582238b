"""The page's address follows the view on screen: scene, time, open tab, pins and the
Study tab's settings."""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING

from ..model import view_query

if TYPE_CHECKING:
    from ..app import ExplorerApp

log = logging.getLogger(__name__)

#: The page's address follows the scene on screen at most this often [ms]: rewriting it
#: at every slider step would cost a message per step, for a link nobody copies mid-drag.
LINK_EVERY_MS = 1000


class AddressLink:
    """Writes a link that reproduces the view into the page's address bar, calmly."""

    def __init__(self, app: ExplorerApp) -> None:
        self.app = app
        self._due = False
        self.linked = ""

    def schedule(self) -> None:
        """Update the address within :data:`LINK_EVERY_MS` (one update per interval)."""
        app = self.app
        if app._location is not None and app.shown() is not None and not self._due:
            self._due = True
            app._later(self.update, LINK_EVERY_MS)

    def update(self) -> None:
        """Put the view on screen into the page's address (a link that reproduces it)."""
        self._due = False
        app = self.app
        view = app.shown()
        if view is None or app._location is None or app.controller.busy:
            return  # a newer result is coming, and will ask again
        try:
            query = view_query(view.scene, app.time_index, app.sidebar.active,
                               app.pins.board.scenes(), app.study_settings())
            # the whole query at once: the values are URL-safe already (base64url, digits)
            link = "?" + "&".join(f"{k}={v}" for k, v in query.items() if v)
            if link != self.linked:
                app.results._address.value = link
                self.linked = link
        except Exception:  # the link is a convenience; the page must not fail for it
            log.exception("could not update the link")
