"""Stopping a served explorer: SIGTERM (a service manager, a test harness) or SIGINT
(Ctrl+C) ends ``python -m explorer`` cleanly, with exit code 0 and no traceback.

The server once raised KeyboardInterrupt from a Python signal handler; now and then that
exception was raised inside a weakref callback, where Python prints it ("Exception
ignored in ...") and drops it, and the server kept serving until it was killed. The
signals are now handled by the server's event loop (``explorer/__main__.py``,
``_serve``). The race was rare (1 run in 5 of the whole suite), so each case here stops
a server that has served pages, several times.
"""

from __future__ import annotations

import signal
import subprocess
import urllib.request

import pytest

from tests.support.serving import ExplorerProcess

pytestmark = [pytest.mark.soak, pytest.mark.timeout(600)]

#: Servers stopped per signal.
ROUNDS = 2


def served_pages(url: str, count: int) -> None:
    """Ask for the page ``count`` times, so that sessions exist when the server stops."""
    # a proxy from the environment must not be asked for a loopback address
    opener = urllib.request.build_opener(urllib.request.ProxyHandler({}))
    for _ in range(count):
        with opener.open(url + "/app", timeout=120) as response:
            assert response.status == 200


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_a_served_explorer_stops_cleanly_on_a_signal(sig: int) -> None:
    for _ in range(ROUNDS):
        server = ExplorerProcess(args=["--warm-up", "none", "--solver-processes", "1"],
                                 ready_timeout=300)
        with server:
            served_pages(server.url, 2)
            server.proc.send_signal(sig)
            try:
                # a failure bound (the server stops within seconds), not a measurement
                code = server.proc.wait(timeout=60)
            except subprocess.TimeoutExpired:
                code = None
        output = server.output()
        assert code == 0, f"exit code {code}; output:\n{output}"
        assert "Traceback" not in output and "Exception ignored" not in output, output
