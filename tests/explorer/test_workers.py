"""Solving in worker processes (explorer/solving/workers.py), as ``python -m explorer`` does.

A worker must give the view a solve here gives, bit for bit, and downloads that hold the
numbers on screen. A slow solve holds up other sessions by ``SPILL_AFTER_S`` at most; a
worker that dies or gets stuck is replaced and the request answered with a message; and
workers never outlive the server.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import explorer.solving.controller as controller_module
import explorer.solving.workers as workers
from core import budget, solve
from core.budget import stage_cache_bounds
from explorer.model import QUANTITIES, DesignLimits, ExplorerState, prepare_view
from explorer.solving import RESULTS, SolveController
from explorer.solving.memory_bound import RELEASE_AFTER_S
from explorer.solving.workers import (
    SolverProcesses,
    WorkerFailed,
    download_text,
    solve_view,
    worker_info,
)
from tests.browser_pages import patience
from tests.support.serving import rss_mib

pytestmark = pytest.mark.timeout(300)

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def processes() -> Iterator[SolverProcesses]:
    pool = SolverProcesses(2, budget.STAGE_CACHE_BYTES // 2)
    pool.start()
    yield pool
    pool.shutdown()


def gone(pid: int) -> bool:
    """The process has exited (a zombie not yet reaped counts as exited)."""
    try:
        with open(f"/proc/{pid}/status", encoding="ascii") as fh:
            return any(line.startswith("State:") and "Z" in line.split()[1] for line in fh)
    except OSError:
        return True


def test_a_view_solved_in_a_worker_is_the_view_solved_here(processes, small_preset) -> None:
    scene = small_preset(force_kN=400.0)
    there = processes.run(0, solve_view, scene)
    here = prepare_view(solve(scene), scene)
    # The same numbers up to round-off: a worker's process-wide quadrature tables were
    # filled by its own scenes, this process's by every test before (in the whole suite:
    # settlement 4.2e-16, q 3.2e-15 relative; bitwise equal when run alone).
    for q in QUANTITIES:
        np.testing.assert_allclose(there.values[q], here.values[q], rtol=1e-13, atol=0,
                                   err_msg=q)
    assert np.array_equal(there.x, here.x) and np.array_equal(there.times, here.times)
    scale = float(np.max(np.abs(here.pressure)))
    np.testing.assert_allclose(there.pressure, here.pressure, rtol=0, atol=1e-13 * scale)
    np.testing.assert_allclose(there.image, here.image, rtol=0,
                               atol=1e-13 * float(np.max(np.abs(here.image))))
    assert np.array_equal(there.geometry.shape, here.geometry.shape)
    assert there.flags == here.flags and there.scene == scene


def test_downloads_from_a_worker_hold_the_numbers_on_screen(processes, monkeypatch) -> None:
    monkeypatch.setattr(controller_module, "_PROCESSES", processes)
    RESULTS.clear()
    state = ExplorerState()
    state.param.update(time_count=5, tol=1e-5)
    session = SolveController(state, executor=None, auto=False)
    session.solve_now()
    view = session.view
    assert session.error == "" and view is not None
    here = solve(view.scene)
    assert session.download(view, "to_csv") == here.to_csv()
    assert session.download(view, "pressure_csv") == here.pressure_csv()
    # the numbers of a new solve, the solve report of the one on screen
    assert here.info != view.info  # timings and cache hits differ
    here.info = view.info
    # the JSON of the command line: the solution with the version and solver settings
    assert session.download(view, "to_json") == here.to_json()
    table = [line for line in session.download(view, "to_csv").splitlines()
             if not line.startswith("#")]
    rows = np.loadtxt(table[1:], delimiter=",")
    assert np.array_equal(rows[:, 1], view.values["settlement"])
    with pytest.raises(ValueError, match="kind: unknown download"):
        download_text(view.scene, "to_pickle")
    # the printable reports, the command line's, built in the worker: checked against the
    # Check tab's limits (mm here), describing the time on screen
    report = session.download(view, "report_html", DesignLimits(settlement_limit=1e-3),
                              float(view.times[0]))
    assert report.startswith("<!DOCTYPE html>") and "<td>contact at t = 0 days</td>" in report
    assert "A limit is exceeded." in report and "; limit 0.001 mm, utilisation" in report
    assert session.download(view, "report_pdf").startswith(b"%PDF-")


def test_a_request_sent_at_once_is_answered_and_frees_its_lane(processes, tmp_path,
                                                                wait_until) -> None:
    pids = [info["pid"] for info in processes.run_everywhere(worker_info)]
    sent = processes.send_now(1, os.getpid)
    assert sent is not None and processes._lanes[1].busy
    assert processes.send_now(1, os.getpid) is None  # one request per worker
    assert processes.result(sent) == pids[1]
    assert not processes._lanes[1].busy
    with held_worker(processes, 0, tmp_path, wait_until):
        assert wait_until(lambda: processes._lanes[0].busy)
        assert processes.send_now(0, os.getpid) is None  # busy: the caller waits its turn


def test_a_session_sends_a_load_step_from_its_own_thread(processes, monkeypatch) -> None:
    monkeypatch.setattr(controller_module, "_PROCESSES", processes)
    RESULTS.clear()
    state = ExplorerState()
    state.param.update(time_count=5, tol=1e-5)
    session = SolveController(state, auto=False)  # the shared thread pool waits
    sent: list[Any] = []
    send_now = processes.send_now
    monkeypatch.setattr(processes, "send_now",
                        lambda *args: sent.append(send_now(*args)) or sent[-1])
    session.request()
    assert session.wait(120) and session.error == "", session.error
    assert len(sent) == 1 and sent[0] is not None  # the worker had it before the thread
    here = prepare_view(solve(session.view.scene), session.view.scene)
    np.testing.assert_allclose(session.view.values["settlement"],
                               here.values["settlement"], rtol=1e-13, atol=0)
    assert not any(lane.busy for lane in processes._lanes)
    # the same scene again: known, so nothing is sent
    session.request()
    assert session.wait(120) and sent == sent[:1]


def test_a_solve_no_longer_wanted_is_stopped_in_its_worker(processes) -> None:
    """A request cancelled while its worker solves stops there (the scene below runs to
    the 60 s bound of a solve otherwise, refused); the worker's next request is answered."""
    from core.work import SolveCancelled
    from tests.scene.test_work_bound import _sine_tilt_on_creep

    sent = processes.send_now(0, solve_view, _sine_tilt_on_creep())
    assert sent is not None
    processes.cancel(sent)
    with pytest.raises(SolveCancelled, match="cancelled while"):
        processes.result(sent)
    assert processes.run(0, os.getpid) == processes.pids()[0]  # not cancelled: a new number
    processes.cancel(sent)  # answered already: nothing to cancel
    assert processes.run(0, os.getpid) == processes.pids()[0]


def test_a_newer_request_cancels_a_slow_solve_of_the_same_session(processes,
                                                                  monkeypatch) -> None:
    """A preset switch waited 10.6 s behind a lift-off solve of the scene before it: the
    newer request cancels a solve that has run CANCEL_AFTER_S, and its answer is shown
    with no error from the cancelled one."""
    from tests.scene.test_work_bound import _sine_tilt_on_creep

    monkeypatch.setattr(controller_module, "_PROCESSES", processes)
    RESULTS.clear()
    state = ExplorerState()
    session = SolveController(state, auto=False)
    errors: list[str] = []
    session.param.watch(lambda event: errors.append(event.new), "error")
    slow = _sine_tilt_on_creep()
    monkeypatch.setattr(state, "to_scene", lambda: slow)
    session.request()
    time.sleep(2 * controller_module.CANCEL_AFTER_S)  # it runs in its worker meanwhile
    monkeypatch.setattr(state, "to_scene", lambda: small_scene())
    session.request()
    assert session.wait(120)
    assert session.error == "" and not errors and session.view is not None
    assert session.view.scene == small_scene()


def test_a_drag_step_of_a_load_lets_the_running_solve_finish(processes,
                                                             monkeypatch) -> None:
    """A drag step of a slider that applies every step (``keep_running``) waits for the
    running solve, however long it has run: its answer is the drag's next frame (each
    step of a ~0.3 s lift-off solve cancelled the one before, and a drag drew nothing).
    Any other request still cancels it after CANCEL_AFTER_S."""
    from tests.scene.test_work_bound import _sine_tilt_on_creep

    monkeypatch.setattr(controller_module, "_PROCESSES", processes)
    RESULTS.clear()
    state = ExplorerState()
    session = SolveController(state, auto=False)
    cancelled: list[Any] = []
    cancel = processes.cancel
    monkeypatch.setattr(processes, "cancel", lambda sent: cancelled.append(sent) or cancel(sent))
    slow = _sine_tilt_on_creep()
    monkeypatch.setattr(state, "to_scene", lambda: slow)
    session.request()
    time.sleep(2 * controller_module.CANCEL_AFTER_S)  # it runs in its worker meanwhile
    monkeypatch.setattr(state, "to_scene", lambda: small_scene())
    session.request(keep_running=True)
    assert cancelled == []
    session.request()               # not a drag step (a typed value, a preset)
    assert len(cancelled) == 1
    assert session.wait(120)
    assert session.error == "" and session.view.scene == small_scene()


def test_a_release_cancels_the_solve_of_a_value_dragged_over(processes,
                                                              monkeypatch) -> None:
    """At a slider's release after a drag, the solve of a value dragged over that still runs
    gives way to the released value waiting behind it, however short its run so far (the
    stepped punch's coating modulus: its last answer came 1.3 s after the release, a lift-off
    solve of a value dragged over ahead of it). Without the release the waiting value would
    wait for the slow solve (the scene below runs to the 60 s bound of a solve)."""
    from tests.scene.test_work_bound import _sine_tilt_on_creep

    monkeypatch.setattr(controller_module, "_PROCESSES", processes)
    monkeypatch.setattr(controller_module, "CANCEL_AFTER_S", 1e9)  # the release alone
    RESULTS.clear()
    state = ExplorerState()
    session = SolveController(state, auto=False)
    errors: list[str] = []
    session.param.watch(lambda event: errors.append(event.new), "error")
    assert not session.released()  # nothing runs
    slow = _sine_tilt_on_creep()
    monkeypatch.setattr(state, "to_scene", lambda: slow)
    session.request()
    assert not session.released()  # nothing waits behind it
    monkeypatch.setattr(state, "to_scene", lambda: small_scene())
    session.request()              # the released value, waiting
    assert session.released()
    assert session.wait(30)
    assert session.error == "" and not errors and session.view is not None
    assert session.view.scene == small_scene()


def test_a_release_leaves_a_solve_of_the_value_released_alone(processes,
                                                              monkeypatch) -> None:
    """A drag back to the value whose solve runs: that solve is the one wanted."""
    monkeypatch.setattr(controller_module, "_PROCESSES", processes)
    monkeypatch.setattr(controller_module, "CANCEL_AFTER_S", 1e9)
    RESULTS.clear()
    state = ExplorerState()
    state.param.update(time_count=5, tol=1e-5)
    session = SolveController(state, auto=False)
    session.request()
    session.request()              # the same scene again, waiting behind its own solve
    assert not session.released()
    assert session.wait(120) and session.error == ""
    assert session.view.scene == state.to_scene()


def small_scene() -> dict[str, Any]:
    """The explorer's default scene (solved in ~30 ms)."""
    return ExplorerState().to_scene()


def test_a_bad_scene_from_a_worker_names_its_field(processes, monkeypatch,
                                                  small_preset) -> None:
    scene = small_preset(force_kN=400.0)
    scene["coating"][0]["thickness"] = {"kind": "constant", "value": -0.01}
    with pytest.raises(ValueError, match=r"coating\[0\]\.thickness"):
        processes.run(0, solve_view, scene)
    monkeypatch.setattr(controller_module, "_PROCESSES", processes)
    state = ExplorerState()
    state.param.update(time_count=5, tol=1e-5)
    session = SolveController(state, executor=None, auto=False)
    session.solve_now()
    good = session.view
    state.layers[0].thickness.mean = -1.0
    session.solve_now()
    assert "coating[0].thickness" in session.error and session.view is good


def test_each_worker_holds_its_share_of_the_stage_cache_budget(processes) -> None:
    share = budget.STAGE_CACHE_BYTES // 2
    infos = processes.run_everywhere(worker_info)
    assert len({info["pid"] for info in infos}) == 2 and os.getpid() not in \
        {info["pid"] for info in infos}
    for info in infos:  # each stage's bound rounds down: at most one byte per stage lost
        assert share - 16 <= info["stage_cache_bytes"] <= share


def test_the_stage_cache_budget_is_shared_in_proportion() -> None:
    default = stage_cache_bounds()
    try:
        budget.set_stage_cache_budget(budget.STAGE_CACHE_BYTES // 4)
        assert stage_cache_bounds() == {name: size // 4 for name, size in default.items()}
        for bad in (0, -1, 1.5, "1", True):
            with pytest.raises(ValueError, match="total_bytes"):
                budget.set_stage_cache_budget(bad)
    finally:
        budget.set_stage_cache_budget(budget.STAGE_CACHE_BYTES)
    assert stage_cache_bounds() == default


def release(gate: Path, wait_until: Any) -> None:
    """Let the worker waiting on the named pipe ``gate`` go: opening the pipe for writing
    succeeds once a reader has it open (a worker killed and replaced opens it again)."""
    def opened() -> bool:
        try:
            os.close(os.open(gate, os.O_WRONLY | os.O_NONBLOCK))
        except OSError:  # no reader yet
            return False
        return True

    assert wait_until(opened, timeout=60)


@contextlib.contextmanager
def held_worker(processes: SolverProcesses, lane: int, tmp_path: Path,
                wait_until: Any) -> Iterator[tuple[threading.Thread, list[Any]]]:
    """A request in ``lane``'s worker that lasts until the block ends: the worker opens a
    named pipe for reading, which returns only once this side opens it for writing. Yields
    the thread waiting for the request and the list receiving its outcome."""
    gate = tmp_path / f"gate-{lane}"
    os.mkfifo(gate)
    outcome: list[Any] = []

    def request() -> None:
        try:
            outcome.append(processes.run(lane, os.open, str(gate), os.O_RDONLY))
        except WorkerFailed as exc:
            outcome.append(exc)

    waiting = threading.Thread(target=request)
    waiting.start()
    try:
        yield waiting, outcome
    finally:
        if waiting.is_alive():
            release(gate, wait_until)
        waiting.join(60)


def test_a_slow_solve_holds_up_another_session_by_the_spill_time_only(processes, tmp_path,
                                                                       wait_until) -> None:
    pids = [info["pid"] for info in processes.run_everywhere(worker_info)]
    with held_worker(processes, 0, tmp_path, wait_until) as (slow, _):
        assert wait_until(lambda: processes._lanes[0].busy)
        # lane 0 is held until the block ends: a request for it takes the idle lane 1
        # (after SPILL_AFTER_S), while the slow one is still there
        assert processes.run(0, os.getpid) == pids[1]
        assert slow.is_alive()
        assert processes.run(1, os.getpid) == pids[1]  # an idle own lane
        assert slow.is_alive()
    assert not slow.is_alive()
    assert processes.run(0, os.getpid) == pids[0]  # back to its own lane once free


def at_the_gate(pid: int) -> bool:
    """Whether process ``pid`` waits in open(2) of a FIFO with no writer yet (the gate of
    :func:`held_worker`): the kernel's wait channel names the wait (Linux)."""
    try:
        with open(f"/proc/{pid}/wchan") as wchan:
            return wchan.read().strip() == "wait_for_partner"
    except OSError:
        return False


def killed_during_a_request(pool: SolverProcesses, kills: int, tmp_path: Path,
                            wait_until: Any) -> tuple[list[int], list[Any]]:
    """Start ``pool`` (one lane), hold a request in its worker and kill (SIGKILL) the
    worker holding it ``kills`` times (1 or 2); returns the killed workers' ids and the
    request's outcome once answered."""
    killed = [pool.start()[0]["pid"]]
    with held_worker(pool, 0, tmp_path, wait_until) as (waiting, outcome):
        assert wait_until(lambda: pool._lanes[0].busy)
        # the lane is busy before the request is written: killed once the worker holds it
        # (else it died idle, and nothing was lost: the request runs on the next worker)
        assert wait_until(lambda: at_the_gate(killed[0]), timeout=60)
        os.kill(killed[0], signal.SIGKILL)
        # the death is noticed at once and the request given to a new worker
        assert wait_until(lambda: pool.pids() not in ([], killed), timeout=60)
        if kills == 2:
            killed.append(pool.pids()[0])
            # the same for the new worker (two fresh-clone runs met a kill before the
            # request had reached the worker: answered on a third one, not refused)
            assert wait_until(lambda: at_the_gate(killed[1]), timeout=60)
            os.kill(killed[1], signal.SIGKILL)
        else:
            release(tmp_path / "gate-0", wait_until)
        waiting.join(60)
    return killed, outcome


@pytest.mark.soak
def test_a_request_whose_worker_is_killed_runs_again_on_a_new_one(tmp_path,
                                                                   wait_until) -> None:
    pool = SolverProcesses(1, 64 * 2**20)
    try:
        killed, outcome = killed_during_a_request(pool, 1, tmp_path, wait_until)
        assert len(outcome) == 1 and isinstance(outcome[0], int), outcome  # answered
        assert pool.run(0, os.getpid) not in killed
    finally:
        pool.shutdown()


@pytest.mark.soak
def test_a_request_whose_worker_dies_twice_is_answered_with_a_message(tmp_path,
                                                                      wait_until) -> None:
    pool = SolverProcesses(1, 64 * 2**20)
    try:
        (first, second), outcome = killed_during_a_request(pool, 2, tmp_path, wait_until)
        assert len(outcome) == 1 and isinstance(outcome[0], WorkerFailed), outcome
        assert "stopped during this solve twice" in str(outcome[0])
        # killed while idle: nothing was lost, the next request is served by a new worker
        third = pool.run(0, os.getpid)
        assert third not in (first, second)
        os.kill(third, signal.SIGKILL)
        assert wait_until(lambda: gone(third))
        assert pool.run(0, os.getpid) not in (first, second, third)
    finally:
        pool.shutdown()


@pytest.mark.soak
def test_a_request_sent_at_once_whose_worker_is_killed_runs_again(tmp_path,
                                                                   wait_until) -> None:
    pool = SolverProcesses(1, 64 * 2**20)
    try:
        killed = pool.start()[0]["pid"]
        gate = tmp_path / "gate-sent"
        os.mkfifo(gate)
        sent = pool.send_now(0, os.open, str(gate), os.O_RDONLY)
        assert sent is not None
        outcome: list[Any] = []
        waiting = threading.Thread(target=lambda: outcome.append(pool.result(sent)))
        waiting.start()
        os.kill(killed, signal.SIGKILL)
        # noticed at once, given to a new worker, which waits at the gate in turn
        assert wait_until(lambda: pool.pids() not in ([], [killed]), timeout=60)
        release(gate, wait_until)
        waiting.join(60)
        assert len(outcome) == 1 and isinstance(outcome[0], int), outcome  # answered
        assert not pool._lanes[0].busy
    finally:
        pool.shutdown()


@pytest.mark.soak
def test_a_stuck_worker_is_stopped_and_replaced(monkeypatch, wait_until) -> None:
    pool = SolverProcesses(1, 64 * 2**20)
    try:
        # the short limit only after the start: a worker's start (imports) took over 1 s on
        # a loaded machine and was itself stopped
        first = pool.start()[0]["pid"]
        monkeypatch.setattr(workers, "REQUEST_TIMEOUT_S", 1.0)
        with pytest.raises(WorkerFailed, match="longer than 1 s and was stopped"):
            pool.run(0, time.sleep, 60.0)
        assert wait_until(lambda: gone(first))
        monkeypatch.setattr(workers, "REQUEST_TIMEOUT_S", 60.0)  # the new worker's start
        assert pool.run(0, os.getpid) != first
    finally:
        pool.shutdown()


@pytest.mark.soak
def test_after_shutdown_requests_are_refused_and_workers_are_gone(wait_until) -> None:
    pool = SolverProcesses(2, 64 * 2**20)
    pids = [info["pid"] for info in pool.start()]
    pool.shutdown()
    assert all(wait_until(lambda pid=pid: gone(pid)) for pid in pids)
    with pytest.raises(WorkerFailed, match="stopping"):
        pool.run(0, os.getpid)


@pytest.mark.soak
@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM, signal.SIGINT])
def test_workers_do_not_outlive_the_server(sig: int, wait_until) -> None:
    # SIGINT is handled as the served explorer handles it (explorer/__main__.py): a flag
    # that ends the main loop. Python's default KeyboardInterrupt can land in a weakref
    # callback, be printed and dropped, and leave the script asleep (1 in 3 clean runs).
    script = textwrap.dedent("""
        import signal, sys, threading
        from explorer.solving.controller import use_worker_processes

        if __name__ == "__main__":
            stop = threading.Event()
            signal.signal(signal.SIGINT, lambda *args: stop.set())
            pool = use_worker_processes(2)
            print(" ".join(str(pid) for pid in pool.pids()), flush=True)
            stop.wait(120)
    """)
    env = {**os.environ, "PYTHONPATH": str(ROOT) + os.pathsep + os.environ.get(
        "PYTHONPATH", "")}
    server = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE,
                              stderr=subprocess.DEVNULL, env=env, text=True)
    try:
        pids = [int(p) for p in server.stdout.readline().split()]
        assert len(pids) == 2 and all(not gone(pid) for pid in pids)
        server.send_signal(sig)
        # stopping both workers (joined, else killed) took over 30 s once with the suite's
        # two halves and the documentation building beside it: stretched by the load
        server.wait(30 * patience())
        assert all(wait_until(lambda pid=pid: gone(pid)) for pid in pids)
    finally:
        server.kill()
        server.wait()


def test_a_worker_solves_without_importing_the_page_libraries() -> None:
    # A worker imports the solving and model packages and core (explorer/model/results.py);
    # Panel and Bokeh would cost each worker ~1 s and ~100 MB for nothing (the plotting
    # libraries load only in a worker asked for a printable report).
    script = textwrap.dedent("""
        import copy, sys
        import explorer.model, explorer.solving.workers
        from explorer.model import DEFAULT_PRESET, presets

        scene = copy.deepcopy(presets()[DEFAULT_PRESET])
        scene["times"] = {"end": 200.0, "count": 4, "spacing": "log"}
        view = explorer.solving.workers.solve_view(scene)
        print(len(view.times), sorted(m for m in ("panel", "bokeh", "holoviews", "matplotlib")
                                      if m in sys.modules))
    """)
    env = {**os.environ, "PYTHONPATH": str(ROOT) + os.pathsep + os.environ.get(
        "PYTHONPATH", "")}
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         env=env, timeout=120, check=True).stdout.split()
    assert out[0] == "4" and out[1:] == ["[]"], out


@pytest.mark.skipif("forkserver" not in multiprocessing.get_all_start_methods(),
                    reason="no fork server here: workers are spawned")
def test_a_worker_starts_warm_from_the_fork_server() -> None:
    # A spawned worker imported core, NumPy and SciPy before its first request: 1.2-2.4 s
    # of CPU for every worker and every replacement. Forked from the fork server, which
    # imported them once: measured 0.02 s; the bound is a tenth of the spawned worker's.
    import resource

    pool = SolverProcesses(1, 64 * 2**20)
    pool.start()
    try:
        # builtins, so that the worker imports nothing more (not this module) to run them
        usage = pool.run(0, resource.getrusage, resource.RUSAGE_SELF)
        parent = pool.run(0, os.getppid)
    finally:
        pool.shutdown()
    assert parent != os.getpid()  # the fork server's child
    assert usage.ru_utime + usage.ru_stime < 0.12, usage


#: What :func:`_free_most_of_a_heap` allocates and frees [MiB] in a worker.
_FREED_MIB = 150
_KEPT: list[bytes] = []


def _free_most_of_a_heap(seconds: float) -> int:
    """In a worker: fill the heap with 1 kB objects, keep the last (so the heap's top
    cannot shrink), free the rest, and last ``seconds`` [s] in all."""
    start = time.monotonic()
    blocks = [bytes(1000) + bytes([i % 256]) for i in range(_FREED_MIB * 2**20 // 1000)]
    _KEPT.append(blocks[-1])
    del blocks
    time.sleep(max(0.0, seconds - (time.monotonic() - start)))
    return os.getpid()


@pytest.mark.skipif(not sys.platform.startswith("linux"),
                    reason="reads /proc and glibc's malloc_trim: Linux only")
def test_a_worker_gives_back_the_memory_a_long_request_freed(wait_until) -> None:
    # Three FE coating checks took a worker from 180 to 345 MiB, which glibc kept for
    # reuse (the load test's memory after all pages closed, issue "Reliability"). After a
    # request of RELEASE_AFTER_S or more, the worker returns it: measured 91 -> 90 MiB
    # here, where before it stayed at 248 MiB (150 MiB freed); the bound is a quarter of
    # what was freed.
    pool = SolverProcesses(1, budget.STAGE_CACHE_BYTES)
    pool.start()
    try:
        pid = pool.pids()[0]
        before = rss_mib(pid)
        assert pool.run(0, _free_most_of_a_heap, RELEASE_AFTER_S + 0.1) == pid
        # the worker trims after it has sent the answer: a moment later
        assert wait_until(lambda: rss_mib(pid) < before + _FREED_MIB / 4, timeout=30), \
            (before, rss_mib(pid))
    finally:
        pool.shutdown()
