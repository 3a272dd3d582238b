"""Pages closed abruptly: no tracebacks in the server's log, one debug line instead.

Bokeh (checked with 3.9) pings every page's websocket now and then; a ping that finds the
socket closed detaches the connection from its session at once (``client_lost``). The
websocket's own close, and any message of that page still being read, come after and
reach for the detached session: ``assert self._session is not None`` in
``bokeh/server/connection.py`` raised, and tornado logged the traceback ("Uncaught
exception GET /app/ws", "error handling message"). A tab closed by a student, or a
browser test closing its page, met it whenever the close fell near a ping.

:func:`install` makes the websocket handler treat a connection whose session is already
detached as closed: its close and its late messages are logged at debug level, once.
Writes that fail on a closed socket (Bokeh's "Failed sending message as connection was
closed", tornado's closed-stream errors of a dropped page) become debug lines as well:
a closed tab is not an error of the server.

:func:`page_releaser` gives back what Panel keeps of a page after its session ends.
Panel (1.9) registers the links of a widget (the editable sliders link their number box
and slider) in ``panel.links.Callback.registry``, a dictionary weak in its keys whose
values hold the key itself: an entry never goes, and through the slider's watchers it
kept the whole page alive, every page ever opened (~6 MiB each; rounds of 50 dropped
sessions grew the server by ~300 MiB, none of it returned). The registry is also walked
at every page's first render, so it slowed the server down as it grew.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable
from typing import Any

log = logging.getLogger(__name__)

_INSTALLED = False

#: Exceptions that only say the other end has gone.
_CLOSED = ("WebSocketClosedError", "StreamClosedError", "ConnectionResetError",
           "BrokenPipeError")


def _detached(handler: Any) -> bool:
    connection = getattr(handler, "connection", None)
    return connection is not None and getattr(connection, "_session", True) is None


class _ClosedPageFilter(logging.Filter):
    """Turns records about a page that has gone into one debug line of this module."""

    def filter(self, record: logging.LogRecord) -> bool:
        closed = False
        if record.exc_info and record.exc_info[0] is not None:
            closed = record.exc_info[0].__name__ in _CLOSED
        elif record.name == "bokeh.server.views.ws":
            closed = "connection was closed" in record.getMessage()
        elif record.name == "asyncio":
            closed = any(name in record.getMessage() for name in _CLOSED)
        if closed:
            log.debug("a page went away: %s", record.getMessage().splitlines()[0][:200])
        return not closed


def release_links(roots: Iterable[Any]) -> int:
    """Drop the link registrations of ``roots`` and everything inside them (Panel
    viewables of a page whose session has ended); returns the entries dropped."""
    from panel.links import Callback

    registry = Callback.registry
    dropped = 0
    for root in roots:
        for obj in root.select():
            if registry.pop(obj, None) is not None:
                dropped += 1
    return dropped


def page_releaser(roots: Callable[[], Iterable[Any]]) -> Callable[[Any], None]:
    """A session-destroyed callback for a page: ``roots()`` lists the page's viewables
    (also those not shown yet); their link registrations are dropped."""

    def release(session_context: Any) -> None:
        try:
            log.debug("session ended: %d link registrations dropped",
                      release_links(roots()))
        except Exception:  # the page goes anyway; what it kept is only memory
            log.exception("could not release the links of a closed page")

    return release


def install() -> bool:
    """Install the guard once per process (the served explorer calls it before serving).

    Returns False, with a warning, if Bokeh's websocket handler has changed shape (the
    guard is then not installed)."""
    global _INSTALLED
    if _INSTALLED:
        return True
    from bokeh.server.views import ws

    handler = getattr(ws, "WSHandler", None)
    if handler is None or not all(hasattr(handler, name) for name in ("on_close", "_handle")):
        log.warning("Bokeh's websocket handler has changed; closed pages are not guarded")
        return False
    on_close, handle = handler.on_close, handler._handle

    def guarded_on_close(self: Any) -> None:
        if _detached(self):
            log.debug("page closed (its loss was noticed by a ping first)")
            return
        on_close(self)

    async def guarded_handle(self: Any, message: Any) -> Any:
        if _detached(self):
            log.debug("message %s of a closed page dropped", getattr(message, "msgtype", "?"))
            return None
        return await handle(self, message)

    guarded_on_close.__wrapped__ = on_close  # type: ignore[attr-defined]
    guarded_handle.__wrapped__ = handle  # type: ignore[attr-defined]
    handler.on_close = guarded_on_close
    handler._handle = guarded_handle
    quiet = _ClosedPageFilter()
    for name in ("bokeh.server.views.ws", "tornado.application", "tornado.general",
                 "asyncio"):
        logging.getLogger(name).addFilter(quiet)
    _INSTALLED = True
    return True
