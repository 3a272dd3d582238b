"""Timestamps of a slider move's way through the server, for the latency benchmark.

Off unless the environment variable ``EXPLORER_TRACE`` names a file: then every mark is
appended to it as one JSON line ``{"event": ..., "t": seconds, "cpu": seconds, ...}``
(``cpu``: the CPU time of the process that wrote it, all its threads). The clock is
``time.monotonic`` (Linux's CLOCK_MONOTONIC, the same in every process), so the worker
processes' marks line up with the server's.

The marks of one load move, in order: ``ws_in`` (a websocket message from the page read
by the server), ``widget_event`` (Panel takes up the widget's change on the event
loop), ``widget_value`` (the widget's new value reaches its binding to the state),
``revision`` (the widget's change reached the scene state), ``sent`` (the
request written to the worker's pipe), ``worker_start`` / ``worker_end`` (the solve in
the worker), ``received`` (the result read back), ``delivered`` (the result handed to the
page's views on the event loop), ``drawn`` (the figures updated) and ``ws_out`` (a
message to the page written). ``benchmarks/explorer_latency.py`` pairs them up.
"""

from __future__ import annotations

import json
import os
import threading
import time
from typing import Any

#: The file the marks go to (None: tracing is off and :func:`mark` costs one test).
TRACE_FILE: str | None = os.environ.get("EXPLORER_TRACE") or None

_LOCK = threading.Lock()


def mark(event: str, t: float | None = None, **fields: Any) -> None:
    """Note that ``event`` happened now (or at ``t`` [s], ``time.monotonic`` clock)."""
    if TRACE_FILE is None:
        return
    # with the CPU time of this process so far [s]: the server's own work of a move, which
    # the machine's load does not stretch as it stretches the wall clock
    line = json.dumps({"event": event, "t": time.monotonic() if t is None else t,
                       "cpu": time.process_time(), **fields})
    with _LOCK, open(TRACE_FILE, "a", encoding="utf-8") as fh:
        fh.write(line + "\n")


def install_websocket_marks() -> None:
    """Mark every websocket message in and out of the Bokeh server (when tracing).

    Panel writes document patches itself (``panel.io.document.dispatch_tornado``: the
    patch made, serialised and its parts queued on the socket); ``ws_out`` marks its end.
    """
    if TRACE_FILE is None:
        return
    import panel.io.document as panel_document
    from bokeh.server.views.ws import WSHandler
    from panel.reactive import Syncable

    if getattr(WSHandler, "_explorer_traced", False):
        return
    on_message, dispatch = WSHandler.on_message, panel_document.dispatch_tornado
    change = Syncable._change_coroutine

    async def traced_change(self: Any, *args: Any, **kwargs: Any) -> None:
        mark("widget_event")
        return await change(self, *args, **kwargs)

    async def traced_on_message(self: Any, fragment: str | bytes) -> None:
        mark("ws_in", size=len(fragment))
        return await on_message(self, fragment)

    def traced_dispatch(*args: Any, **kwargs: Any) -> Any:
        futures = dispatch(*args, **kwargs)
        mark("ws_out")
        return futures

    WSHandler.on_message = traced_on_message
    Syncable._change_coroutine = traced_change
    panel_document.dispatch_tornado = traced_dispatch
    WSHandler._explorer_traced = True
