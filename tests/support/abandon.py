"""Visitors who leave abruptly: sessions of the served explorer opened and dropped.

A classroom that reloads pages, or anyone who scripts it, opens sessions and drops them
at any point of their start. Each visit here ends one of four ways (:data:`WAYS`), the
connection reset (no closing handshake, as when a laptop lid shuts or a process dies):

- ``get``: the page is asked for (``GET /app``) and the connection dropped as soon as
  its first bytes arrive: the server built a session that no websocket ever joins;
- ``ack``: the page's websocket is opened and dropped after the server's first message;
- ``pull``: the document is asked for and the connection dropped before the answer;
- ``loaded``: the document is pulled, the page reports itself ready (as BokehJS does once
  rendered, so the page fills its tabs and solves) and the connection is dropped a moment
  later, at a random point of that work.

Used by ``benchmarks/load_test.py --mode abandon`` and by
tests/explorer/test_abandoned_sessions.py.
Loopback only; the number of visits is bounded by the caller. Speaks the Bokeh websocket
protocol directly (tornado's client), so a visit costs the client almost nothing.
"""

from __future__ import annotations

import asyncio
import json
import random
import socket
import struct
from collections import Counter
from typing import Any

from explorer.fixes.gc_policy import (
    COLLECT_AFTER_S,
    COLLECT_AT_MOST_EVERY_S,
    LATE_COLLECT_AFTER_S,
)

WAYS = ("get", "ack", "pull", "loaded")
#: Added to the time the server needs to discard a round's sessions [s] (a loaded
#: machine runs its timers late).
DISCARD_MARGIN_S = 3.0


def discard_wait_s(session_linger: float) -> float:
    """How long after its connection is lost a session is surely discarded and collected
    [s]: Bokeh keeps it ``session_linger`` s, looks for such sessions every
    ``session_linger`` s (``python -m explorer`` sets both from --session-linger), the
    full collection that frees its page comes ``COLLECT_AFTER_S`` later, or
    ``COLLECT_AT_MOST_EVERY_S`` after the one before (a round soon after another), and
    one more for pages let go late ``LATE_COLLECT_AFTER_S`` after that."""
    return (2 * session_linger + max(COLLECT_AFTER_S, COLLECT_AT_MOST_EVERY_S)
            + LATE_COLLECT_AFTER_S + DISCARD_MARGIN_S)


def _linger_zero(sock: Any) -> None:
    """Make the close of ``sock`` a reset (SO_LINGER 0), not the orderly close of a page."""
    if sock is None:
        return
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
    except OSError:
        pass


async def _get_dropped(host: str, port: int, path: str) -> None:
    reader, writer = await asyncio.open_connection(host, port)
    writer.write(f"GET {path} HTTP/1.1\r\nHost: {host}:{port}\r\n\r\n".encode("ascii"))
    await writer.drain()
    await asyncio.wait_for(reader.read(1), timeout=120)
    _linger_zero(writer.get_extra_info("socket"))
    writer.transport.abort()


async def _websocket_dropped(host: str, port: int, path: str, way: str,
                             rng: random.Random) -> None:
    from bokeh.protocol import Protocol
    from bokeh.util.token import generate_jwt_token, generate_session_id
    from tornado.httpclient import HTTPRequest
    from tornado.websocket import websocket_connect

    token = generate_jwt_token(generate_session_id())
    # tornado's own 20 s connect/request limits ran out on a loaded 2-core machine while
    # the server built other pages; the outer 120 s bound is the one meant
    request = HTTPRequest(f"ws://{host}:{port}{path}/ws", connect_timeout=120,
                          request_timeout=120)
    conn = await asyncio.wait_for(
        websocket_connect(request, subprotocols=["bokeh", token],
                          max_message_size=512 * 2**20), timeout=120)
    try:
        await _read_message(conn)  # ACK
        if way != "ack":
            await _send(conn, Protocol().create("PULL-DOC-REQ"))
            if way == "loaded":
                await _read_message(conn)  # the document
                await _send(conn, _document_ready(Protocol()))
                await asyncio.sleep(rng.uniform(0.0, 1.5))
    finally:
        stream = conn.protocol.stream if conn.protocol is not None else None
        if stream is not None:
            _linger_zero(stream.socket)
            stream.close()


def _document_ready(protocol: Any) -> Any:
    from bokeh.document import Document
    from bokeh.document.events import MessageSentEvent
    from bokeh.events import DocumentReady

    return protocol.create("PATCH-DOC", [MessageSentEvent(Document(), "bokeh_event",
                                                          DocumentReady())])


async def _send(conn: Any, message: Any) -> None:
    for part in (message.header_json, message.metadata_json, message.content_json):
        await conn.write_message(part)


async def _read_message(conn: Any) -> None:
    """Read one Bokeh message (header, metadata, content and its buffers)."""
    header = await asyncio.wait_for(conn.read_message(), timeout=120)
    if header is None:
        raise ConnectionError("the server closed the connection")
    parts = 2 + 2 * int(json.loads(header).get("num_buffers", 0))
    for _ in range(parts):
        if await asyncio.wait_for(conn.read_message(), timeout=120) is None:
            raise ConnectionError("the server closed the connection")


async def _visit(host: str, port: int, path: str, way: str, rng: random.Random) -> None:
    if way == "get":
        await _get_dropped(host, port, path)
    else:
        await _websocket_dropped(host, port, path, way, rng)


async def _abandon(host: str, port: int, path: str, count: int, seed: int,
                   at_once: int) -> Counter[str]:
    rng = random.Random(seed)
    ways = [WAYS[i % len(WAYS)] for i in range(count)]
    rng.shuffle(ways)
    outcome: Counter[str] = Counter()
    gate = asyncio.Semaphore(at_once)

    async def one(way: str) -> None:
        async with gate:
            try:
                await _visit(host, port, path, way, rng)
                outcome[way] += 1
            except Exception as exc:  # counted: a refused visit is a finding, not a crash
                outcome[f"failed: {type(exc).__name__}: {str(exc)[:80]}"] += 1

    await asyncio.gather(*(one(way) for way in ways))
    return outcome


def abandon_sessions(url: str, count: int, *, seed: int = 0, at_once: int = 10,
                     path: str = "/app") -> dict[str, int]:
    """Open ``count`` sessions of the explorer at ``url`` (``http://127.0.0.1:PORT``) and
    drop each abruptly, the ways of :data:`WAYS` in equal shares, ``at_once`` at a time.

    Returns how many visits ended each way (and ``"failed: Error"`` counts of visits the
    server refused or never answered within 120 s).
    """
    if not url.startswith("http://"):
        raise ValueError(f"url: expected http://host:port, got {url!r}")
    host, _, port = url[len("http://"):].rstrip("/").partition(":")
    return dict(asyncio.run(_abandon(host, int(port), path, count, seed, at_once)))
