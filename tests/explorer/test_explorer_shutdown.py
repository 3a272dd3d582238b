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

import os
import signal
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest

from tests.support.serving import ExplorerProcess

pytestmark = [pytest.mark.soak, pytest.mark.timeout(600)]

ROOT = Path(__file__).resolve().parents[2]

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


def _alive(pid: int) -> bool:
    """Whether process ``pid`` runs (a zombie, ended but not collected, does not)."""
    try:
        with open(f"/proc/{pid}/stat") as stat:
            return stat.read().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False


def _children(pid: int) -> list[int]:
    found = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as stat:
                    if int(stat.read().rsplit(")", 1)[1].split()[1]) == pid:
                        found.append(int(entry))
            except (FileNotFoundError, ProcessLookupError, IndexError, ValueError):
                pass
    return found


#: A test run that starts a server and is then killed: it prints the server's process id
#: and waits. ``sys.path`` gets the checkout, as under pytest.
_RUN = """
import sys, time
sys.path.insert(0, {root!r})
from tests.support.serving import ExplorerProcess
server = ExplorerProcess(args=["--warm-up", "none", "--solver-processes", "1"],
                         ready_timeout=300).start()
print(server.pid, flush=True)
time.sleep(600)
"""


@pytest.mark.skipif(not os.path.isdir("/proc"), reason="reads processes from /proc")
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGKILL], ids=["SIGTERM", "SIGKILL"])
def test_a_killed_test_run_takes_its_servers_with_it(sig: int) -> None:
    """A test run killed before its clean-up (SIGTERM to pytest, a CI timeout) left its
    servers running, re-parented to init (two found alive 15 min later, using CPU beside
    the next run). The servers the tests start (tests.support.serving) are told
    ``--exit-with-parent``: the server and its solver processes end too."""
    run = subprocess.Popen([sys.executable, "-c", _RUN.format(root=str(ROOT))],
                           stdout=subprocess.PIPE, text=True)
    try:
        line = run.stdout.readline()
        assert line.strip().isdigit(), f"the run printed {line!r}"
        server = int(line)
        family = [server, *_children(server)]
        assert len(family) >= 2, "the server and its solver process"
        run.send_signal(sig)
        run.wait(timeout=60)
        # a failure bound (the server looks at its parent every second), not a measurement
        deadline = time.monotonic() + 60
        while any(_alive(pid) for pid in family) and time.monotonic() < deadline:
            time.sleep(0.2)
        left = [pid for pid in family if _alive(pid)]
    finally:
        run.kill()
        run.wait()
    for pid in left:
        os.kill(pid, signal.SIGKILL)
    assert not left, f"still running after their test run was killed: {left}"
