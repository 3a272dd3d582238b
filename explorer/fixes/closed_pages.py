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

:func:`start_busy_cleanup` keeps the first busy page out of Panel's busy-counter task.
Panel (1.9) starts one task for the whole process, at the first event that marks a page
busy, to drop stale entries of ``pn.state``'s busy counter every 10 s. ``asyncio`` gives
a task a copy of the context it was created in, and that context holds Panel's current
document (the ``curdoc`` context variable): the page whose event started the task, with
its ~46,000 objects, lived as long as the server. Each collection after a session ended
then found a closed page still held, so ``gc_policy`` looked again (a full collection,
0.25-0.3 s on the event loop) 10, 20, 40, 60... s later for five minutes, and logged a
warning at the end. Started before any page is busy, in an empty context, the task holds
no page.
"""

from __future__ import annotations

import asyncio
import contextvars
import importlib
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


def start_busy_cleanup() -> bool:
    """Start Panel's busy-counter cleanup task in an empty context, so that it keeps no
    page alive (module notes). Call it on the server's event loop before a page can be
    busy (each new session does; once started, later calls do nothing).

    Returns whether it started the task here: False when it already runs, outside an
    event loop, or when Panel's busy counter has changed shape (then nothing is done).
    """
    panel_state = importlib.import_module("panel.io.state")  # the module: panel.io.state
    # is also the name of its instance
    holder = getattr(panel_state, "_state", None)
    schedule = getattr(panel_state.state, "_schedule_busy_cleanup", None)
    if holder is None or schedule is None or not hasattr(holder, "_busy_cleanup_scheduled"):
        return False
    if holder._busy_cleanup_scheduled:
        return False
    try:
        asyncio.get_running_loop()
    except RuntimeError:  # no loop to run the task on
        return False
    contextvars.Context().run(schedule)
    return bool(holder._busy_cleanup_scheduled)


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
