"""Solving in worker processes, so that the server's event loop keeps a core of its own.

Python runs one thread of a process at a time. Served with solver threads, a solve of
10-60 ms holds that lock for most of its time, and every page's messages wait behind it:
with 20 sessions the server ran at ~70 % of one core and the slowest 5 % of slider steps
took 4x as long as for a single session (benchmarks/results/load_test.md, run J).

A :class:`SolverProcesses` runs *lanes*: each lane is one worker process (forked from
the fork server of :mod:`explorer.solving.process_start`, warm: a fork of the server
itself would copy its threads and locks in whatever state they are). A worker does one
request at a time. A session keeps to its lane, so the solver's
stage caches in that process (kernel operator, basis) serve its next slider step; a
request that has waited :data:`SPILL_AFTER_S` for its lane takes any idle one, so a slow
solve of one session delays the others by that much at most.

A worker returns a :class:`~explorer.model.results.ResultView`, which pickles in well under a
millisecond (~250 kB). The core's solution object stays in the worker; the downloads solve
the shown scene again (:func:`download_text`): the solver is deterministic, so the file
holds the numbers on screen, and with the stage caches warm that costs 5-11 ms.

What runs in a worker is in :mod:`explorer.solving.worker_side`. Nothing here imports Panel; the
workers import only ``core`` and :mod:`explorer.model.results`.
"""

from __future__ import annotations

import collections
import contextlib
import logging
import multiprocessing
import multiprocessing.connection
import threading
import time
from collections.abc import Callable, Iterator
from concurrent.futures import Future
from typing import Any

from .priority import at_background_priority
from .process_start import process_context
from .trace import TRACE_FILE, mark
from .worker_side import (
    DOWNLOADS,
    download_text,
    preview_view,
    serve,
    solution_text,
    solve_view,
    worker_info,
)

__all__ = ["BACKGROUND_TIMEOUT_S", "DOWNLOADS", "REQUEST_TIMEOUT_S", "SPILL_AFTER_S", "SentRequest",
           "SolverProcesses", "WorkerFailed", "download_text", "solution_text",
           "preview_view", "solve_view", "worker_info"]

log = logging.getLogger(__name__)

#: A request waits this long for its session's lane [s] before it takes any idle one.
#: Its own lane holds the stage caches of its session's scene (a force step costs ~10 ms
#: there, a solve from cold caches 50-300 ms elsewhere); past this the lane is taken to
#: be held up by a slow solve, which then delays the others by no more than this.
SPILL_AFTER_S = 0.25

#: The served explorer's time limit per solve [s] (listed with the scene limits in
#: core/SCENES.md). A request has its worker to itself, so this is the solve's own time.
#: The slowest of 10,000 generated valid scenes solved in 0.7 s
#: (tests/scene/test_property_inputs.py); past the limit the
#: scene is taken to be beyond what the explorer is for (or the worker to be stuck): the
#: worker is stopped and replaced, and the session told.
REQUEST_TIMEOUT_S = 60.0
#: The time limit of background work in a worker [s] (:meth:`SolverProcesses.
#: run_background`: an FE coating check, a fit of up to ``core.limits.MAX_FIT_SOLVES``
#: solves), as long as a study's (``explorer.solving.study_runner.STUDY_TIMEOUT_S``): at
#: the lower priority a saturated machine stretches such work several times.
BACKGROUND_TIMEOUT_S = 600.0


class WorkerFailed(RuntimeError):
    """A worker process died or got stuck; the message says which and what to do."""


# -- what runs in a worker ---------------------------------------------------------------
class _WorkerDied(Exception):
    """The lane's worker process ended (before or during a request)."""


# -- the server's side -------------------------------------------------------------------
class SentRequest:
    """A request given to a worker by :meth:`SolverProcesses.send_now`, its value not
    yet collected."""

    def __init__(self, lane: _Lane, fn: Any, args: tuple[Any, ...]) -> None:
        self.lane, self.fn, self.args = lane, fn, args
        # which request of which worker it is (for :meth:`SolverProcesses.cancel`)
        self.process, self.number = lane.process, lane.sent


class _Lane:
    """One worker process, whether it is working, and the requests waiting for it."""

    def __init__(self, index: int, stage_cache_bytes: int) -> None:
        self.index = index
        self.stage_cache_bytes = stage_cache_bytes
        self.busy = False                         # a request is in the worker
        self.waiting: collections.deque[object] = collections.deque()  # requests, in order
        self.process, self.connection = self._new_worker()

    def _new_worker(self) -> tuple[Any, multiprocessing.connection.Connection]:
        context = process_context()
        ours, theirs = context.Pipe(duplex=True)
        # the number of the request whose answer is no longer wanted (requests are
        # numbered 1, 2, ... in the order sent, by both sides of the pipe)
        self.cancel = context.RawValue("q", 0)
        self.sent = 0
        process = context.Process(target=serve,
                                  args=(theirs, self.stage_cache_bytes, self.cancel),
                                  name=f"solver-{self.index}", daemon=True)
        process.start()
        theirs.close()  # the worker's end lives in the worker: its death closes the pipe
        return process, ours

    def call(self, fn: Any, args: tuple[Any, ...], timeout: float) -> Any:
        """``fn(*args)`` in the worker; raises :class:`_WorkerDied` if the worker is dead
        (before or during the request), TimeoutError past ``timeout`` [s], and ``fn``'s
        own exception. Only the one thread holding the lane calls this."""
        self.send(fn, args)
        return self.receive(timeout)

    def send(self, fn: Any, args: tuple[Any, ...]) -> None:
        """Give ``fn(*args)`` to the worker (:class:`_WorkerDied` if it is dead)."""
        process, connection = self.process, self.connection
        if not process.is_alive():
            raise _WorkerDied("before")
        try:
            connection.send((fn, args))
        except (EOFError, OSError):  # a broken pipe, or closed by a shutdown
            raise _WorkerDied("before") from None
        self.sent += 1
        mark("sent", lane=self.index)

    def receive(self, timeout: float) -> Any:
        """The value of the request sent last (see :meth:`call`)."""
        process, connection = self.process, self.connection
        try:
            ready = multiprocessing.connection.wait([connection, process.sentinel], timeout)
        except OSError:  # the pipe closed by a shutdown
            raise _WorkerDied("during") from None
        if not ready:
            raise TimeoutError
        if connection not in ready:  # only the sentinel: the worker ended
            raise _WorkerDied("during")
        try:
            kind, value, (start, end) = connection.recv()
        except (EOFError, OSError):
            raise _WorkerDied("during") from None
        if TRACE_FILE is not None:
            mark("worker_start", start, lane=self.index)
            mark("worker_end", end, lane=self.index)
            mark("received", lane=self.index)
        if kind == "error":
            raise value
        return value

    def restart(self, gently: bool = False) -> None:
        """Stop the worker (whatever it is doing) and start a new one; ``gently``: an
        idle worker (renewed, not stuck) gets a second to end by itself first."""
        old, old_connection = self.process, self.connection
        self.process, self.connection = self._new_worker()
        old_connection.close()  # an idle worker reads the end of the pipe and returns
        if gently:
            old.join(1.0)
        if old.is_alive():
            old.kill()  # a working or stuck one would never read it
        old.join(5)

    def stop(self) -> None:
        """Stop the worker: an idle one at once, a working one killed after 5 s."""
        self.connection.close()
        self.process.join(5)
        if self.process.is_alive():
            self.process.kill()
            self.process.join(5)


class SolverProcesses:
    """``lanes`` worker processes solving for all sessions of a server.

    ``stage_cache_bytes`` [bytes] bounds the solver's stage caches of each worker (the
    machine's budget divided among the lanes). Workers start at the first request, or at
    :meth:`start`.
    """

    def __init__(self, lanes: int, stage_cache_bytes: int) -> None:
        if not (isinstance(lanes, int) and lanes >= 1):
            raise ValueError(f"lanes: must be a positive integer, got {lanes!r}")
        self._lock = threading.Lock()
        self._cond = threading.Condition(self._lock)
        self._lanes = [_Lane(i, stage_cache_bytes) for i in range(lanes)]
        self._next = 0
        self._closed = False

    @property
    def lanes(self) -> int:
        """Number of worker processes."""
        return len(self._lanes)

    def assign(self) -> int:
        """A lane for a new session (round robin)."""
        with self._lock:
            index = self._next % len(self._lanes)
            self._next += 1
            return index

    def run(self, preferred: int, fn: Any, *args: Any) -> Any:
        """Call ``fn(*args)`` in a worker and return its value (blocks the calling thread).

        A worker does one request at a time. The request waits for lane ``preferred``
        (first come, first served), or, after :data:`SPILL_AFTER_S`, takes any lane that
        is idle with nobody waiting. Exceptions of ``fn`` are raised here. A worker found
        dead before the work was given to it is replaced and the work given to the new
        one. A worker that dies during the work (noticed at once: the wait watches the
        process) is replaced and the work run once more on the new one; if that one
        dies too, or the work takes longer than :data:`REQUEST_TIMEOUT_S`, the worker is
        replaced and :class:`WorkerFailed` raised.
        """
        return self._finish(self._acquire(preferred), fn, args, sent=False)

    def run_background(self, preferred: int, fn: Any, *args: Any) -> Any:
        """:meth:`run` for background work (an FE coating check, a fit): ``fn(*args)`` at
        the lower priority of :func:`explorer.solving.priority.at_background_priority`,
        bounded by :data:`BACKGROUND_TIMEOUT_S` instead of :data:`REQUEST_TIMEOUT_S`."""
        return self._finish(self._acquire(preferred), at_background_priority, (fn, *args),
                            sent=False, timeout=BACKGROUND_TIMEOUT_S)

    def send_now(self, preferred: int, fn: Any, *args: Any) -> SentRequest | None:
        """Give ``fn(*args)`` to lane ``preferred`` at once, from the calling thread, if
        that lane is idle with nobody waiting; None otherwise (then use :meth:`run`).

        A slider step is written to the worker by the event loop that read it, so the
        worker starts while the loop finishes the step's other work; waiting for a
        thread to wake and take the lock first cost 5-8 ms a step on a loaded machine.
        Every request sent must be collected with :meth:`result` (which frees the lane).
        """
        with self._cond:
            lane = self._lanes[preferred % len(self._lanes)]
            if self._closed or lane.busy or lane.waiting:
                return None
            lane.busy = True
        try:
            lane.send(fn, args)
        except _WorkerDied:  # replaced by the request that follows on the usual way
            with self._cond:
                lane.busy = False
                self._cond.notify_all()
            return None
        return SentRequest(lane, fn, args)

    def cancel(self, sent: SentRequest) -> None:
        """Tell the worker that the answer of ``sent`` is no longer wanted: the solve stops
        at its next check of its work (``core.work.check_work``, every time step of a
        creeping base and every step of lift-off under creep) and :meth:`result` raises
        ``core.work.SolveCancelled``. A request already answered (the worker then works
        for someone else, or is a new one) is left alone."""
        lane = sent.lane
        if lane.process is sent.process:
            lane.cancel.value = sent.number

    def result(self, sent: SentRequest) -> Any:
        """The value of a request given by :meth:`send_now`, with :meth:`run`'s handling
        of a worker that dies or gets stuck meanwhile."""
        return self._finish(sent.lane, sent.fn, sent.args, sent=True)

    def _finish(self, lane: _Lane, fn: Any, args: tuple[Any, ...], sent: bool,
                timeout: float | None = None) -> Any:
        # ``lane`` is held by this request (busy); ``sent``: fn(*args) is in its worker;
        # ``timeout`` [s]: REQUEST_TIMEOUT_S when None (read now: tests shorten it)
        if timeout is None:
            timeout = REQUEST_TIMEOUT_S
        try:
            retried, starts = False, 0
            while True:
                with self._lock:
                    if self._closed:
                        raise WorkerFailed("the server is stopping")
                try:
                    if sent:
                        sent = False
                        return lane.receive(timeout)
                    return lane.call(fn, args, timeout)
                except _WorkerDied as died:
                    self._replace(lane)
                    if str(died) == "before":  # died while idle: nothing was lost
                        starts += 1
                        if starts > 2:
                            raise WorkerFailed("the solver process could not be "
                                               "started") from None
                        continue
                    if not retried:
                        # killed from outside (or out of memory): once more, not forever
                        retried = True
                        log.warning("solver process %d stopped during a request; running "
                                    "it again on a new one", lane.index)
                        continue
                    raise WorkerFailed("the solver process stopped during this solve "
                                       "twice (out of memory?); a new one was started, "
                                       "please try again") from None
                except TimeoutError:
                    self._replace(lane)
                    raise WorkerFailed(f"the solve took longer than {timeout:.0f} "
                                       "s and was stopped") from None
        finally:
            with self._cond:
                lane.busy = False
                self._cond.notify_all()

    def _acquire(self, preferred: int) -> _Lane:
        own = self._lanes[preferred % len(self._lanes)]
        ticket = object()
        spill_at = time.monotonic() + SPILL_AFTER_S
        with self._cond:
            own.waiting.append(ticket)
            try:
                while True:
                    if self._closed:
                        raise WorkerFailed("the server is stopping")
                    if not own.busy and own.waiting[0] is ticket:
                        own.busy = True
                        return own
                    now = time.monotonic()
                    if now >= spill_at:
                        for lane in self._lanes:
                            if not lane.busy and not lane.waiting:
                                lane.busy = True
                                return lane
                    self._cond.wait(timeout=None if now >= spill_at else spill_at - now)
            finally:
                own.waiting.remove(ticket)
                self._cond.notify_all()  # the next in the queue may go now

    def _replace(self, lane: _Lane) -> None:
        with self._lock:
            if not self._closed:
                log.warning("restarting solver process %d", lane.index)
                lane.restart()

    def run_everywhere(self, fn: Any, *args: Any) -> list[Any]:
        """Call ``fn(*args)`` in every worker (to start them, or to warm their caches with
        a scene) and return the values, lane by lane. Each lane is taken in turn, as a
        request would take it; the workers work at once."""
        results: list[Future[Any]] = []
        for lane in self._lanes:
            done: Future[Any] = Future()
            thread = threading.Thread(target=self._run_into, args=(lane.index, fn, args, done),
                                      daemon=True)
            thread.start()
            results.append(done)
        return [f.result() for f in results]

    def _run_into(self, index: int, fn: Any, args: tuple[Any, ...], done: Future[Any]) -> None:
        own = self._lanes[index]
        with self._holding(own):
            try:
                done.set_result(own.call(fn, args, REQUEST_TIMEOUT_S))
            except BaseException as exc:
                done.set_exception(exc)

    @contextlib.contextmanager
    def _holding(self, lane: _Lane, give_up: Callable[[], bool] | None = None
                 ) -> Iterator[bool]:
        """This lane and no other, whatever waits, once it is idle: yields True while it is
        held. With ``give_up`` (asked while waiting), yields False without the lane once the
        pool is shut down or ``give_up()`` is true."""
        with self._cond:
            while lane.busy and not self._closed and not (give_up is not None and give_up()):
                self._cond.wait(None if give_up is None else 1.0)
            held = give_up is None or not (self._closed or give_up())
            if held:
                lane.busy = True
        if not held:
            yield False
            return
        try:
            yield True
        finally:
            with self._cond:
                lane.busy = False
                self._cond.notify_all()

    def renew(self, stop: Callable[[], bool] = lambda: False) -> int:
        """Replace every worker with a new one, each once it is idle; returns how many
        (0 once :meth:`shutdown` began).

        A worker keeps what it loaded and allocated while it worked (the report's and the
        FE check's libraries, heap the allocator does not give back): a new one, forked
        from the warm fork server, holds none of it. Requests wait for their lane while
        it is renewed, as for a request before them. ``stop()`` is asked before each lane
        and while waiting for a busy one: once true, the lanes left keep their workers."""
        renewed = 0
        for lane in self._lanes:
            with self._holding(lane, give_up=stop) as held:
                if not held:
                    break
                lane.restart(gently=True)
                renewed += 1
            if self._closed:  # the shutdown stopped the old worker, not this new one
                lane.stop()
                break
        return renewed

    def start(self) -> list[dict[str, int]]:
        """Start every worker now rather than at the first request; returns
        :func:`worker_info` of each."""
        return self.run_everywhere(worker_info)

    def pids(self) -> list[int]:
        """Process ids of the running workers."""
        with self._lock:
            return [lane.process.pid for lane in self._lanes
                    if lane.process.pid is not None and lane.process.is_alive()]

    def shutdown(self) -> None:
        """Stop every worker (requests still waiting get :class:`WorkerFailed`)."""
        with self._cond:
            self._closed = True
            self._cond.notify_all()
        for lane in self._lanes:
            lane.stop()
