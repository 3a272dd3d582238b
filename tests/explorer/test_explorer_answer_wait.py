"""A worker's answer awaited on the server's event loop (explorer/solving/answer_wait.py).

A load step written to the worker by the event loop is read back by that loop when the
answer is in the pipe, with no thread in between; a worker that ends while the loop
waits, and a caller with no event loop, go the thread's way as before.
"""

from __future__ import annotations

import asyncio
import os
import signal
import time
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest

import explorer.solving.controller as controller_module
from core import budget, solve
from explorer.model import ExplorerState, prepare_view
from explorer.solving import RESULTS, SolveController, SolverProcesses
from explorer.solving.answer_wait import when_answered

pytestmark = pytest.mark.timeout(300)


@pytest.fixture(scope="module")
def processes() -> Iterator[SolverProcesses]:
    pool = SolverProcesses(1, budget.STAGE_CACHE_BYTES // 4)
    pool.start()
    yield pool
    pool.shutdown()


async def _until(check: Any, timeout: float = 120.0) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if check():
            return True
        await asyncio.sleep(0.005)
    return False


def test_a_load_step_is_read_back_by_the_event_loop(processes, monkeypatch) -> None:
    monkeypatch.setattr(controller_module, "_PROCESSES", processes)
    RESULTS.clear()
    state = ExplorerState()
    state.param.update(time_count=5, tol=1e-5)
    delivered: list[Any] = []

    def dispatch(callback: Any) -> None:  # as the page's: on the loop, next round
        delivered.append(callback)
        asyncio.get_running_loop().call_soon(callback)

    session = SolveController(state, dispatch=dispatch, auto=False)
    waits: list[Any] = []
    work = session._work
    monkeypatch.setattr(session, "_work", lambda *args: waits.append(args) or work(*args))

    async def steps() -> None:
        session.request()
        assert await _until(lambda: session.solves == 1)
        first = session.view
        # a step while the first is solved waits, then goes out from the loop as well
        history = state.loading.histories["force"]
        history.value = history.value * 1.1
        session.request()
        history.value = history.value * 1.1
        session.request()
        assert await _until(lambda: session.solves >= 2 and not session.busy
                            and not session._running)
        assert session.view is not first

    asyncio.run(steps())
    assert session.error == "", session.error
    assert waits == []  # no thread waited for a worker
    here = prepare_view(solve(session.view.scene), session.view.scene)
    np.testing.assert_allclose(session.view.values["settlement"], here.values["settlement"],
                               rtol=1e-13, atol=0)  # the same solve, bit for bit alone
    assert session.view.scene == state.to_scene()  # the newest step is on screen
    assert not processes._lanes[0].busy
    # the results are kept for other sessions (by a thread of the pool)
    deadline = time.monotonic() + 30
    while RESULTS.get(controller_module.result_key(state.to_scene())) is None:
        assert time.monotonic() < deadline
        time.sleep(0.01)


def test_a_worker_that_ends_while_the_loop_waits_goes_the_threads_way() -> None:
    pool = SolverProcesses(1, 64 * 2**20)
    try:
        pid = pool.start()[0]["pid"]
        outcome: list[str] = []

        async def wait() -> float:
            sent = pool.send_now(0, time.sleep, 30.0)
            assert sent is not None
            assert when_answered(sent, lambda: outcome.append("answer"),
                                 lambda: outcome.append("other"))
            killed = time.monotonic()
            os.kill(pid, signal.SIGKILL)
            assert await _until(lambda: outcome, 60)
            return time.monotonic() - killed

        asyncio.run(wait())
        # the thread's way (SolverProcesses.result) replaces the worker and runs the
        # request again: tests/explorer/test_workers.py
        assert outcome == ["other"]
    finally:
        pool.shutdown()


def test_without_an_event_loop_the_thread_waits(processes) -> None:
    sent = processes.send_now(0, os.getpid)
    assert sent is not None
    assert not when_answered(sent, lambda: None, lambda: None)
    assert processes.result(sent) > 0 and not processes._lanes[0].busy


def test_a_large_answer_is_read_by_a_thread_not_the_event_loop(processes) -> None:
    """An answer larger than the pipe holds (a result of 2000 output times is 3.5 MB) was
    read on the event loop, which then waited in that read for the worker to write the
    rest (over 0.5 s on a saturated server). One over ``LOOP_READ_AT_MOST`` goes the
    thread's way; a small one is still read on the loop, and the size is read from the
    pipe without taking it."""
    from explorer.solving import answer_wait

    big = answer_wait.LOOP_READ_AT_MOST + 1
    for size, way in ((16, "answer"), (big, "other")):
        outcome: list[str] = []

        async def wait(size: int = size, outcome: list[str] = outcome) -> Any:
            sent = processes.send_now(0, os.urandom, size)
            assert sent is not None
            assert when_answered(sent, lambda: outcome.append("answer"),
                                 lambda: outcome.append("other"))
            assert await _until(lambda: bool(outcome), 60)
            return sent

        sent = asyncio.run(wait())
        assert outcome == [way], size
        answer = processes.result(sent)  # whole, either way
        assert isinstance(answer, bytes) and len(answer) == size
        assert not processes._lanes[0].busy
