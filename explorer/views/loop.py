"""The session's document and its event loop: where the views run callbacks later, and
where outcomes computed on other threads are brought back to the page."""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Any

from panel.io.state import set_curdoc

log = logging.getLogger(__name__)


class PageLoop:
    """The Bokeh document of one session (None in a script), and callbacks on its loop."""

    def __init__(self, doc: Any) -> None:
        self.doc = doc

    @property
    def served(self) -> bool:
        """Whether this session is a served page (not a notebook or a script)."""
        return bool(self.doc is not None and self.doc.session_context)

    def later(self, callback: Callable[[], None], delay_ms: float) -> None:
        """Run ``callback`` on this session's event loop after ``delay_ms`` [ms]."""
        doc = self.doc
        if doc is None or not doc.session_context:
            return

        def run() -> None:
            with set_curdoc(doc):
                callback()

        try:
            if delay_ms > 0:
                doc.add_timeout_callback(run, delay_ms)
            else:
                doc.add_next_tick_callback(run)
        except Exception:  # the session was closed meanwhile (a result, a timer)
            log.debug("callback dropped: session gone")

    def dispatch(self, callback: Callable[[], None]) -> None:
        """Run ``callback`` (from a solver thread) on this session's event loop, or at
        once where there is none (a notebook, a script)."""
        if self.served:
            self.later(callback, 0)
        else:
            callback()
