"""A slider move's way through the server, from the marks of explorer/solving/trace.py.

``benchmarks/explorer_latency.py`` splits each move's latency into these steps; a test
checks the pairing on a trace written by hand.
"""

from __future__ import annotations

import json
from pathlib import Path

#: The server's marks of one move (explorer/solving/trace.py), in the order they happen.
STEPS = ("ws_in", "widget_event", "widget_value", "revision", "sent", "worker_start",
         "worker_end", "received", "delivered", "drawn", "ws_out")


def server_steps(trace: Path, since: float, until: float,
                 cpu: list[float] | None = None) -> list[dict[str, float]]:
    """The server's marks of each move between ``since`` and ``until`` [s, monotonic]:
    for every ``revision`` the websocket message before it and the first of each later
    step after the one before; a move lacking a step (a result from the cache) is left
    out. Returns per move the step times [ms] after ``ws_in`` (and appends to ``cpu`` the
    server process's CPU time [ms] from ``ws_in`` to ``ws_out`` of each move, where the
    marks carry it)."""
    events = [json.loads(line) for line in trace.read_text().splitlines() if line]
    events = [e for e in events if since <= e["t"] <= until]
    moves = []
    for i, rev in enumerate(events):
        if rev["event"] != "revision":
            continue
        ws_in_cpu = [e.get("cpu") for e in events[:i] if e["event"] == "ws_in"]
        ws_in = [e["t"] for e in events[:i] if e["event"] == "ws_in"]
        widget = [e["t"] for e in events[:i] if e["event"] == "widget_event"]
        value = [e["t"] for e in events[:i] if e["event"] == "widget_value"]
        if not ws_in or not widget or not value:
            continue
        times = {"ws_in": ws_in[-1], "widget_event": widget[-1], "widget_value": value[-1],
                 "revision": rev["t"]}
        at = i
        for step in STEPS[4:]:
            later = next((k for k in range(at + 1, len(events))
                          if events[k]["event"] == step), None)
            if step.startswith("worker"):  # stamped by the worker, written on receipt;
                # the worker may start before the server's mark of the sending is made
                later = next((k for k in range(len(events))
                              if events[k]["event"] == step
                              and events[k]["t"] >= times["revision"]), None)
            if later is None:
                break
            times[step] = events[later]["t"]
            if not step.startswith("worker"):
                at = later
        if len(times) == len(STEPS):
            moves.append({step: 1e3 * (times[step] - times["ws_in"]) for step in STEPS})
            out_cpu = events[at].get("cpu")
            if cpu is not None and out_cpu is not None and ws_in_cpu[-1] is not None:
                cpu.append(1e3 * (out_cpu - ws_in_cpu[-1]))
    return moves
