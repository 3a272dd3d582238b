"""The server's marks of a slider move (explorer/solving/trace.py) and how the latency
benchmark pairs them up (tests/support/trace_steps.py, for benchmarks/explorer_latency.py)."""

from __future__ import annotations

import json

import explorer.solving.trace as trace
from tests.support.trace_steps import STEPS, server_steps


def test_marks_are_off_unless_a_file_is_named(monkeypatch, tmp_path) -> None:
    monkeypatch.setattr(trace, "TRACE_FILE", None)
    trace.mark("ws_in")  # nothing to write to, nothing written
    path = tmp_path / "trace.jsonl"
    monkeypatch.setattr(trace, "TRACE_FILE", str(path))
    trace.mark("revision", 12.5, rid=3)
    line = json.loads(path.read_text())
    assert line.pop("cpu") > 0  # the process's CPU time so far [s]
    assert line == {"event": "revision", "t": 12.5, "rid": 3}


def test_a_move_is_paired_from_its_websocket_message_to_its_patch(tmp_path) -> None:
    # one move, 1 ms a step; the worker started before the sending was marked (it is
    # marked once written), and its marks are written when its answer is read
    order = ["ws_in", "widget_event", "widget_value", "revision", "sent", "received", "delivered",
             "drawn", "ws_out"]
    at = {"ws_in": 0, "widget_event": 1, "widget_value": 1.5, "revision": 2, "sent": 4,
          "received": 6, "delivered": 7, "drawn": 8, "ws_out": 9}
    lines = []
    for event in order:
        lines.append({"event": event, "t": 100 + at[event] / 1e3})
        if event == "received":
            lines[-1:-1] = [{"event": "worker_start", "t": 100.003},
                            {"event": "worker_end", "t": 100.005}]
    path = tmp_path / "trace.jsonl"
    path.write_text("".join(json.dumps(line) + "\n" for line in lines))
    (move,) = server_steps(path, 99.0, 101.0)
    assert list(move) == list(STEPS)
    expected = {**at, "worker_start": 3, "worker_end": 5}
    assert all(abs(move[s] - expected[s]) < 1e-6 for s in STEPS), move
    assert server_steps(path, 101.0, 102.0) == []  # outside the window
