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


def _reset() -> None:
    idle_release.disable()
    while idle_release.open_sessions():
        idle_release.session_closed(None)
    idle_release.disable()  # (a close while enabled would have set a timer)


@pytest.fixture(autouse=True)
def no_release_left() -> Iterator[None]:
    """Every test starts and ends with releases off and no session counted: a timer left
    running would empty the caches of tests that count their evaluations."""
    _reset()
    yield
    _reset()


class Released:
    """What the releases of a test did: their reports (``done``) and warm-ups."""

    def __init__(self) -> None:
        self.done: list[dict[str, float]] = []
        self.warmed = 0


@pytest.fixture
def released() -> Released:
    """Releases enabled after :data:`AFTER_S`, each recorded."""
    record = Released()

    def warm() -> None:
        record.warmed += 1

    idle_release.enable(AFTER_S, rewarm=warm, on_release=record.done.append)
    return record


def fill(small_preset) -> None:
    scene = small_preset(force_kN=410.0)
    RESULTS.get_or_compute("idle-release-test", lambda: solve(scene))
    assert held_bytes() > 0


def test_the_caches_are_emptied_once_the_last_session_has_been_closed_a_while(
        released, small_preset, wait_until) -> None:
    fill(small_preset)
    idle_release.session_opened()
    idle_release.session_opened()
    idle_release.session_closed(None)
    assert not wait_until(lambda: released.done, timeout=3 * AFTER_S,
                          every=0.02)  # one session is still open
    assert held_bytes() > 0 and released.warmed == 0
    idle_release.session_closed(None)
    assert wait_until(lambda: released.done, timeout=30, every=0.02)
    assert released.warmed == 1
    assert len(RESULTS) == 0 and held_bytes() == 0
    assert released.done[-1]["bytes"] > 0 and released.done[-1]["warmed"] == 1.0


def test_a_session_opening_in_time_keeps_the_caches(released, small_preset,
                                                     wait_until) -> None:
    fill(small_preset)
    idle_release.session_opened()
    idle_release.session_closed(None)
    idle_release.session_opened()  # before AFTER_S has passed
    assert not wait_until(lambda: released.done, timeout=3 * AFTER_S, every=0.02)
    assert len(RESULTS) > 0 and released.warmed == 0


def test_without_enable_the_sessions_are_only_counted(small_preset, wait_until) -> None:
    fill(small_preset)
    idle_release.session_opened()
    assert idle_release.open_sessions() == 1
    idle_release.session_closed(None)
    assert idle_release.open_sessions() == 0
    assert not wait_until(lambda: len(RESULTS) == 0, timeout=0.5, every=0.05)


def test_a_release_stops_before_the_warm_up_once_a_session_opens(released,
                                                                   small_preset) -> None:
    fill(small_preset)
    done = idle_release.release(rewarm=lambda: setattr(released, "warmed", 1),
                                go_on=lambda: False)
    assert done["warmed"] == 0.0 and released.warmed == 0
    assert held_bytes() == 0  # the server's own caches are emptied first, whatever follows


def test_a_timer_superseded_by_a_later_session_does_nothing(released, small_preset,
                                                            wait_until) -> None:
    """A timer already running when a session opens and closes again (``Timer.cancel``
    cannot stop it) must not release: only the newest timer does, once."""
    fill(small_preset)
    idle_release.session_opened()
    idle_release.session_closed(None)
    stale = idle_release._generation
    idle_release.session_opened()
    idle_release.session_closed(None)
    idle_release._release_if_idle(stale)  # as the first timer would, late
    assert not released.done and len(RESULTS) > 0
    assert wait_until(lambda: released.done, timeout=30, every=0.02)
    time.sleep(3 * AFTER_S)
    assert len(released.done) == 1 and released.warmed == 1


def test_garbage_frozen_by_the_last_collection_is_freed_by_the_release(wait_until) -> None:
    """The collection for ended sessions (explorer/fixes/gc_policy.py) freezes what is
    alive then; a reference cycle that dies after it stays frozen, out of the collector's
    reach, until a collection gives it back (with the heavy pages of the load test and a
    release 10 s after they closed: ~130 MiB more in use 40 s after). The release runs
    the server's collection, which frees it."""
    import gc
    import weakref

    from explorer.fixes import gc_policy

    class Node:
        pass

    holder = [Node()]
    holder[0].me = holder[0]  # a cycle: reference counting alone never frees it
    alive = weakref.ref(holder[0])
    done: list[dict[str, float]] = []
    try:
        gc_policy.collect_ended_sessions()  # the node is alive: frozen with the rest
        holder.clear()
        gc.collect()
        assert alive() is not None  # dead, but frozen
        idle_release.enable(AFTER_S, on_release=done.append,
                            collect=gc_policy.collect_ended_sessions)
        idle_release.session_opened()
        idle_release.session_closed(None)
        assert wait_until(lambda: done, timeout=30, every=0.02)
        assert alive() is None and done[-1]["collected"] >= 1
    finally:
        gc.unfreeze()  # the rest of the test session collects as usual


def test_a_failed_collection_leaves_the_rest_of_the_release(small_preset) -> None:
    """A collection that fails (the event loop stopping under it) is logged; the release
    still empties the caches and warms up (and renews the workers, where there are any)."""
    fill(small_preset)
    warmed: list[int] = []

    def fails() -> int:
        raise TimeoutError("the loop did not answer")

    done = idle_release.release(rewarm=lambda: warmed.append(1), collect=fails)
    assert done["collected"] == 0.0 and done["warmed"] == 1.0 and warmed == [1]
    assert held_bytes() == 0


def test_the_servers_collection_runs_on_its_event_loop() -> None:
    """The release's thread hands the collection to the event loop (finalisers of what it
    frees expect the loop's thread) and gets its result, or its exception, back."""
    import asyncio
    import concurrent.futures
    from unittest import mock

    from tornado.ioloop import IOLoop

    from explorer.__main__ import _on_event_loop

    started = threading.Event()
    holder: dict[str, object] = {}

    def serve() -> None:
        asyncio.set_event_loop(asyncio.new_event_loop())
        holder["loop"] = IOLoop.current()
        holder["thread"] = threading.get_ident()
        IOLoop.current().add_callback(started.set)
        IOLoop.current().start()

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    assert started.wait(30)
    io_loop = holder["loop"]
    try:
        assert _on_event_loop(io_loop, threading.get_ident) == holder["thread"]

        def fails() -> None:
            raise RuntimeError("from the loop")

        with pytest.raises(RuntimeError, match="from the loop"):
            _on_event_loop(io_loop, fails)
    finally:
        io_loop.add_callback(io_loop.stop)
        thread.join(30)
        io_loop.close()
    # a loop that no longer runs: the waiting thread gives up, and the call is dropped
    ran: list[int] = []
    with pytest.raises(concurrent.futures.TimeoutError), \
            mock.patch("explorer.__main__.ON_LOOP_TIMEOUT_S", 0.2):
        _on_event_loop(io_loop, lambda: ran.append(1))
    assert ran == []


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
        answered: list[float] = []
        slow = threading.Thread(target=lambda: answered.append(
            (pool.run(0, time.sleep, 0.5), time.monotonic())[1]))
        slow.start()
        time.sleep(0.1)
        assert pool.renew() == 2
        renewed_at = time.monotonic()
        slow.join()
        assert answered and answered[0] <= renewed_at
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
        said = re.compile(r"No page open for 2 s: emptied the caches \([\d.]+ MiB\), "
                          r"collected \d+ objects and renewed 1 solver process\(es\)")
        assert wait_until(lambda: said.search(server.output()), timeout=120, every=0.2), (
            server.output()[-3000:])
        with opener.open(server.url + "/app", timeout=120) as page:
            assert page.status == 200
        output = server.output()
        assert "Traceback" not in output and "ERROR" not in output, output[-5000:]
