"""The server's studies take turns (explorer/solving/fair_share.py): a study started while
another runs no longer waits for it to end, only one runs at any moment (the others
paused), the queue beyond the processes allowed is first come first served, a cancelled
waiting study leaves the queue, a study's process and a solver worker are bounded in
memory (explorer/solving/memory_bound.py), and studies and coating checks run at a lower
CPU priority than the pages' slider solves (explorer/solving/priority.py).

The turns themselves are checked with a clock of the test's own; the real studies with
real processes (paused by SIGSTOP, which Windows lacks)."""

from __future__ import annotations

import copy
import os
import threading
import time
from pathlib import Path

import pytest

from core.work import address_space_bound
from explorer.model import ExplorerState, presets
from explorer.model.study import Axis, plan_study
from explorer.solving import StudyRun
from explorer.solving.fair_share import CAN_PAUSE, StudyShare, process_state
from explorer.solving.memory_bound import STUDY_MEMORY_BYTES, WORKER_MEMORY_BYTES
from explorer.solving.priority import (
    BACKGROUND_NICENESS,
    PER_THREAD,
    at_background_priority,
    thread_niceness,
)
from explorer.solving.workers import SolverProcesses
from tests.browser_pages import patience


class Clock:
    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def test_turns_go_round_the_ring_and_the_queue_is_first_come() -> None:
    clock = Clock()
    share = StudyShare(processes=2, running=1, turn_s=1.0, pausable=True, clock=clock)
    never = lambda: False  # noqa: E731
    assert share.enter("a", never) and share.enter("b", never)
    assert share.runs("a") and not share.runs("b")
    clock.now = 0.5
    assert share.runs("a") and not share.runs("b")  # within a's turn
    clock.now = 1.0
    assert not share.runs("a") and share.runs("b")  # b's turn
    clock.now = 2.0
    assert share.runs("a") and not share.runs("b")
    # a third study waits for a process, then gets a's place when a ends
    entered = threading.Event()
    told: list[int] = []
    third = threading.Thread(target=lambda: share.enter("c", never, told.append, 0.01)
                             and entered.set())
    third.start()
    time.sleep(0.1)
    assert not entered.is_set() and told == [2]  # two studies ahead of it
    share.leave("a")
    third.join(5)
    assert entered.is_set() and share.sharing() == 2
    assert share.runs("b") and not share.runs("c")  # b's turn began when a left


def test_a_cancelled_waiting_study_leaves_the_queue() -> None:
    share = StudyShare(processes=1, pausable=True)
    assert share.enter("a", lambda: False)
    assert not share.enter("b", lambda: True, poll_s=0.01)  # cancelled while waiting
    share.leave("a")
    assert share.enter("c", lambda: False)  # not behind the cancelled b
    assert share.runs("c")


def test_without_pausing_one_study_has_a_process_at_a_time() -> None:
    share = StudyShare(processes=3, pausable=False)
    assert share.processes == 1 and share.running == 1


def _scene() -> dict:
    scene = copy.deepcopy(presets()["uniform_flat"])
    scene["times"] = [1.0, 30.0, 365.0]
    state = ExplorerState()
    state.load_scene(scene)
    return state.to_scene()


@pytest.mark.skipif(not CAN_PAUSE, reason="processes cannot be paused here")
def test_two_pages_studies_run_in_turns_and_both_finish() -> None:
    """The second page's study starts while the first runs (it once waited for the end),
    at no moment do both processes run, and both give their whole answer."""
    share = StudyShare(processes=2, running=1, turn_s=0.3)
    scene = _scene()
    # 40 coating moduli: each a new geometry, a few seconds of work (measured 3-6 s)
    long = plan_study(scene, [Axis("coating[0].modulus", 50.0, 5000.0, 40, "log")])
    short = plan_study(scene, [Axis("loading.force", 300.0, 600.0, 3)])
    first, second = StudyRun(share=share), StudyRun(share=share)
    first.start(long)
    deadline = time.monotonic() + 120
    while first.process is None or first.done == 0:
        assert time.monotonic() < deadline, first.message
        time.sleep(0.02)
    if hasattr(os, "getpriority"):
        # the study yields the CPU to the pages' slider solves (19: the nicest there is)
        assert os.getpriority(os.PRIO_PROCESS, first.process.pid) == min(
            os.getpriority(os.PRIO_PROCESS, 0) + BACKGROUND_NICENESS, 19)
    second.start(short)
    both_running = paused_first = 0
    both_since, longest_both = None, 0.0
    seen_second_alive_with_first = False
    while first.running or second.running:
        assert time.monotonic() < deadline + 300, (first.message, second.message)
        states = [_state(run.process) for run in (first, second)]
        if states[0] is not None and states[1] is not None:
            seen_second_alive_with_first = True
            paused_first += states[0] == "T"
        if states == ["R", "R"]:
            both_running += 1
            now = time.monotonic()
            both_since = now if both_since is None else both_since
            longest_both = max(longest_both, now - both_since)
        else:
            both_since = None
        time.sleep(0.01)
    assert first.status == second.status == "done", (first.message, second.message)
    assert seen_second_alive_with_first  # the short study did not wait for the long one
    # Both read "R" for a moment (a new study's process runs until it is paused, and
    # SIGSTOP takes effect when the process is next scheduled): a few samples of the
    # ~1000 taken on a quiet machine (at most 5 seen), 18 in a run of the whole suite,
    # never for a whole turn (scaled to the machine's load, as every wait here).
    assert longest_both < share.turn_s * patience(), (longest_both, both_running)
    assert paused_first > 0  # the long study gave the short one turns
    assert first.result.outputs["settlement"].shape[0] == 40
    assert second.result.outputs["settlement"].shape[0] == 3


def _state(process) -> str | None:
    """'R' for a running process, 'T' for a paused one, None when it is gone."""
    if process is None:
        return None
    # a study's multiprocessing.Process, or a subprocess.Popen
    alive = process.is_alive() if hasattr(process, "is_alive") else process.poll() is None
    if not alive:
        return None
    state = process_state(process.pid)
    if state is None:
        return None
    return "T" if state in ("T", "t") else "R"


def test_a_study_process_is_bounded_in_memory() -> None:
    """The study's process has an address-space limit (POSIX), so a study can no longer
    take the server's machine (one took 5.8 GiB). Checked in a fresh interpreter: a
    child forked from this test process would inherit its (large) address space."""
    import subprocess
    import sys

    pytest.importorskip("resource")
    code = (
        "import resource\n"
        "from core.work import bound_memory\n"
        "from explorer.solving.memory_bound import STUDY_MEMORY_BYTES\n"
        "limit = bound_memory(STUDY_MEMORY_BYTES)\n"
        "assert limit == resource.getrlimit(resource.RLIMIT_AS)[0]\n"
        "try:\n"
        "    bytearray(limit)\n"
        "    print(limit, 'allocated')\n"
        "except MemoryError:\n"
        "    print(limit, 'refused')\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120, cwd=Path(__file__).resolve().parents[2])
    assert done.returncode == 0, done.stderr
    limit, what = done.stdout.split()
    assert int(limit) == address_space_bound(STUDY_MEMORY_BYTES) and what == "refused"


def allocate(n: int) -> int:
    """Take ``n`` bytes (run in a solver worker)."""
    return len(bytearray(n))


def test_a_solver_worker_is_bounded_in_memory_and_says_so() -> None:
    """A request that needs more than a worker's bound fails in words the page shows,
    and the worker goes on serving."""
    pytest.importorskip("resource")
    from explorer.solving.controller import _failure_text

    processes = SolverProcesses(1, 64 * 1024**2)
    try:
        with pytest.raises(MemoryError, match="this solve needed more than") as info:
            processes.run(0, allocate, address_space_bound(WORKER_MEMORY_BYTES))
        assert "times.count" in _failure_text(info.value)
        assert processes.run(0, allocate, 1000) == 1000
    finally:
        processes.shutdown()


@pytest.mark.skipif(not PER_THREAD, reason="a niceness per thread (Linux)")
def test_a_coating_check_runs_nicer_than_the_workers_other_requests() -> None:
    """A coating check (seconds of FE work) runs in a solver worker at a lower priority
    than the slider solves of the other workers; the worker's next request runs at the
    server's priority again (an unprivileged process cannot take back a lower one)."""
    processes = SolverProcesses(1, 64 * 1024**2)
    try:
        base = processes.run(0, thread_niceness)
        assert processes.run_background(0, thread_niceness) == min(
            base + BACKGROUND_NICENESS, 19)
        assert processes.run(0, thread_niceness) == base
        with pytest.raises(MemoryError):  # its failure reaches the server as it was
            processes.run_background(0, allocate, address_space_bound(WORKER_MEMORY_BYTES))
    finally:
        processes.shutdown()


@pytest.mark.skipif(not PER_THREAD, reason="a niceness per thread (Linux)")
def test_background_priority_raises_what_its_work_raises() -> None:
    assert at_background_priority(thread_niceness) == min(
        thread_niceness() + BACKGROUND_NICENESS, 19)
    with pytest.raises(ZeroDivisionError):
        at_background_priority(divmod, 1, 0)


def test_background_work_in_a_worker_has_the_longer_time_limit(monkeypatch) -> None:
    """A check or a fit at the lower priority may take minutes on a saturated machine: it
    is bounded by BACKGROUND_TIMEOUT_S, a slider's solve by REQUEST_TIMEOUT_S."""
    from explorer.solving import workers

    processes = SolverProcesses(1, 64 * 1024**2)
    limits = []
    call = workers._Lane.call

    def spy(lane, fn, args, timeout):
        limits.append(timeout)
        return call(lane, fn, args, timeout)

    monkeypatch.setattr(workers._Lane, "call", spy)
    try:
        processes.run(0, thread_niceness)
        processes.run_background(0, thread_niceness)
    finally:
        processes.shutdown()
    assert limits == [workers.REQUEST_TIMEOUT_S, workers.BACKGROUND_TIMEOUT_S]


def test_the_coating_check_asks_its_worker_for_the_lower_priority(monkeypatch) -> None:
    from explorer.solving import controller
    from explorer.views import coating

    asked = []

    class Workers:
        def assign(self) -> int:
            return 0

        def run_background(self, lane, fn, *args):
            asked.append(fn)
            return {"ok": True}

    monkeypatch.setattr(controller, "worker_processes", Workers)
    assert coating._check(_scene()) == {"ok": True}
    assert asked == [coating.check_scene]


@pytest.mark.skipif(not CAN_PAUSE or not os.path.exists("/proc/self/stat"),
                    reason="processes cannot be paused, or do not report their state, here")
def test_a_pause_returns_once_the_process_has_stopped() -> None:
    """SIGSTOP takes effect when the process is next scheduled: a study's process, nicer
    than the server, on a busy machine could still run after the next study was resumed.
    Here two busy processes keep both cores full (beside whatever else the machine runs)
    while a niced one is paused and resumed 50 times: after each pause it reads stopped.
    The wait this needs grows with the load (~25 ms per busy process); the pause's bound
    of 5 s is ~10x the longest measured beside 20 busy processes."""
    import subprocess
    import sys

    from explorer.solving.fair_share import pause, resume

    busy = [sys.executable, "-c", "while True: pass"]
    hogs = [subprocess.Popen(busy) for _ in range(2)]
    study = subprocess.Popen(["nice", "-n", str(BACKGROUND_NICENESS), *busy])
    try:
        running = 0
        for _ in range(50):
            pause(study.pid)
            running += _state(study) != "T"
            resume(study.pid)
            time.sleep(0.005)
        assert running == 0, running
    finally:
        for process in (*hogs, study):
            process.kill()
            process.wait()
