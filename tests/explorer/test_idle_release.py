"""An idle server gives its caches' memory back (explorer/solving/idle_release.py).

Once the last session has closed and none has opened for the time given, the server's
result cache and its solver stages are emptied, every worker empties its own, and the
presets are warmed again; a session opening before then keeps everything as it is.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator

import numpy as np
import pytest

from core import solve
from core.cache import cache_report
from explorer.solving import RESULTS, SolverProcesses, idle_release
from explorer.solving.worker_side import solve_view

pytestmark = pytest.mark.timeout(120)

#: The idle time of these tests [s]: long against a thread's start, short for a test.
AFTER_S = 0.2


def held_bytes() -> int:
    return sum(stage["bytes"] for stage in cache_report().values())


@pytest.fixture
def released() -> Iterator[list[str]]:
    """Releases enabled after :data:`AFTER_S`; the list records each warm-up after one."""
    warmed: list[str] = []
    count = len(idle_release.RELEASES)
    idle_release.enable(AFTER_S, rewarm=lambda: warmed.append("warm"))
    yield warmed
    idle_release.disable()
    while idle_release.open_sessions():
        idle_release.session_closed()
    idle_release.disable()  # the close above may have set a timer
    del idle_release.RELEASES[count:]


def fill(small_preset) -> None:
    scene = small_preset(force_kN=410.0)
    RESULTS.get_or_compute("idle-release-test", lambda: solve(scene))
    assert held_bytes() > 0


def test_the_caches_are_emptied_once_the_last_session_has_been_closed_a_while(
        released, small_preset, wait_until) -> None:
    fill(small_preset)
    count = len(idle_release.RELEASES)
    idle_release.session_opened()
    idle_release.session_opened()
    idle_release.session_closed()
    assert not wait_until(lambda: len(idle_release.RELEASES) > count, timeout=3 * AFTER_S,
                          every=0.02)  # one session is still open
    assert held_bytes() > 0 and released == []
    idle_release.session_closed()
    assert wait_until(lambda: len(idle_release.RELEASES) > count, timeout=30, every=0.02)
    assert released == ["warm"]
    assert len(RESULTS) == 0 and held_bytes() == 0
    assert idle_release.RELEASES[-1]["bytes"] > 0


def test_a_session_opening_in_time_keeps_the_caches(released, small_preset,
                                                     wait_until) -> None:
    fill(small_preset)
    count = len(idle_release.RELEASES)
    idle_release.session_opened()
    idle_release.session_closed()
    idle_release.session_opened()  # before AFTER_S has passed
    assert not wait_until(lambda: len(idle_release.RELEASES) > count, timeout=3 * AFTER_S,
                          every=0.02)
    assert len(RESULTS) > 0 and released == []


def test_without_enable_the_sessions_are_only_counted(small_preset, wait_until) -> None:
    fill(small_preset)
    count = len(idle_release.RELEASES)
    idle_release.session_opened()
    assert idle_release.open_sessions() == 1
    idle_release.session_closed()
    assert idle_release.open_sessions() == 0
    assert not wait_until(lambda: len(idle_release.RELEASES) > count, timeout=0.5, every=0.05)
    assert len(RESULTS) > 0


def test_the_time_must_be_positive() -> None:
    with pytest.raises(ValueError, match="after_s"):
        idle_release.enable(0.0)


def test_renewed_workers_are_new_processes_that_solve_as_before(small_preset) -> None:
    scene = small_preset(force_kN=420.0)
    pool = SolverProcesses(2, 64 * 2**20)
    try:
        before = [pool.run(k, solve_view, scene) for k in range(2)]
        old = pool.pids()
        # a lane busy with a request is renewed once that request is answered
        slow = threading.Thread(target=pool.run, args=(0, time.sleep, 0.5))
        slow.start()
        time.sleep(0.1)
        assert pool.renew() == 2
        slow.join()
        new = pool.pids()
        assert len(new) == 2 and not set(new) & set(old)
        after = [pool.run(k, solve_view, scene) for k in range(2)]
        for a, b in zip(before, after, strict=True):
            assert np.array_equal(a.pressure, b.pressure)
    finally:
        pool.shutdown()
    assert pool.renew() == 0  # a pool shut down renews nothing


@pytest.mark.soak
def test_a_served_explorer_left_idle_empties_its_caches_and_still_serves(wait_until) -> None:
    """``python -m explorer --release-after-idle 2``: a page asked for and left (its
    session discarded after the 1 s linger), then the release, said in the server's output,
    its worker renewed; the next page is served as before."""
    import re
    import urllib.request

    from tests.support.serving import ExplorerProcess

    opener = urllib.request.build_opener(urllib.request.ProxyHandler({}))
    with ExplorerProcess(args=["--solver-processes", "1", "--session-linger", "1",
                               "--release-after-idle", "2"], host="127.0.0.1",
                         ready_timeout=300) as server:
        with opener.open(server.url + "/app", timeout=120) as page:
            assert page.status == 200
        said = re.compile(r"No page open for 2 s: emptied the caches \([\d.]+ MiB\) and "
                          r"renewed 1 solver process\(es\)")
        assert wait_until(lambda: said.search(server.output()), timeout=120, every=0.2), (
            server.output()[-3000:])
        with opener.open(server.url + "/app", timeout=120) as page:
            assert page.status == 200
        output = server.output()
        assert "Traceback" not in output and "ERROR" not in output, output[-5000:]
