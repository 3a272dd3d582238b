"""The session's document and its event loop: where the views run callbacks later, and
where outcomes computed on other threads are brought back to the page."""

from __future__ import annotations

import logging
import threading
from collections import deque
from collections.abc import Callable
from typing import Any

from panel.io.state import set_curdoc

log = logging.getLogger(__name__)


class PageLoop:
    """The Bokeh document of one session (None in a script), and callbacks on its loop."""

    def __init__(self, doc: Any) -> None:
        self.doc = doc
        # callbacks dispatched from other threads, run in the order they were dispatched
        self._queued: deque[Callable[[], None]] = deque()
        self._lock = threading.Lock()
        self._draining = False

    @property
    def served(self) -> bool:
        """Whether this session is a served page (not a notebook or a script)."""
        return bool(self.doc is not None and self.doc.session_context)

    @property
    def connected(self) -> bool:
        """Whether a browser is connected to this session now (True outside a server).

        A closed page's session is kept for the server's ``--session-linger`` (for the
        page to reconnect), and its timers still run meanwhile."""
        # Bokeh's session context offers its session only through this attribute
        context = getattr(self.doc, "session_context", None)
        session = getattr(context, "_session", None)
        return session is None or session.connection_count > 0

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
        """Run ``callback`` (from a solver thread) on this session's event loop, after
        every callback dispatched before it, or at once where there is none (a notebook,
        a script).

        The callbacks wait in one queue that a single callback on the loop empties: each
        scheduled on its own, a study's last progress line once ran after its result
        (the page read "Done: running: 3 of 3 points")."""
        if not self.served:
            callback()
            return
        with self._lock:
            self._queued.append(callback)
            if self._draining:
                return
            self._draining = True
        self.later(self._drain, 0)

    def _drain(self) -> None:
        while True:
            with self._lock:
                if not self._queued:
                    self._draining = False
                    return
                callback = self._queued.popleft()
            try:
                callback()
            except Exception:  # the others still run, the page goes on
                log.exception("a callback from another thread failed")
