"""The studies of a server share its study core in turns, whoever started first.

A study runs in a process of its own (:mod:`explorer.solving.study_runner`). Run one at
a time to the end, a long study of one page held every other page's study back for as
long as it liked (up to its 600 s limit). Here at most :data:`MAX_STUDY_PROCESSES`
studies have a process at once (others wait, first come first served) and of those one
runs at a time, each for a turn of :data:`TURN_S`, in a ring; the others are paused
(``SIGSTOP``, their memory kept, no CPU used) until their turn comes back. Every page's
study thus advances at 1/k of the core while k studies are alive, and a short study no
longer waits behind a long one. Where processes cannot be paused (no ``SIGSTOP``:
Windows), one study has a process at a time, in the order they were started.

Nothing here imports Panel.
"""

from __future__ import annotations

import os
import signal
import threading
import time
from collections.abc import Callable, Hashable

#: Studies with a process at once in one server (one runs, the others paused): a paused
#: study keeps its memory (a study process holds ~0.2-0.5 GiB, its stage caches bounded
#: by :data:`explorer.solving.study_runner.STUDY_CACHE_BYTES`).
MAX_STUDY_PROCESSES = 3
#: Studies running at once (the others paused): each takes a core, and the machine also
#: serves every page's slider solves.
MAX_RUNNING_STUDIES = 1
#: How long a study runs before the next one's turn [s]: long against a pause and a
#: resume (two signals, microseconds) and against a study's batch of points, short
#: against a person waiting for a study of a few seconds.
TURN_S = 1.0

#: How long a pause waits at most for its process to have stopped [s]: ``SIGSTOP`` takes
#: effect when the process is next scheduled, which for a study's process (nicer than the
#: server, :mod:`explorer.solving.priority`) on a busy machine can come after the next
#: study was resumed; both then ran for a moment. The wait grows with the machine's load,
#: ~25 ms per busy process on 2 cores (niced busy process stopped 200 times beside 2, 6
#: and 20 busy ones: longest 0.05, 0.15 and 0.51 s); 0.2 s was too short under a test
#: suite beside a CPU hog. The bound only guards against a process that never reports
#: stopped: the wait is on a study's own thread, never on the server's event loop. A
#: process that does not report its state (no ``/proc``) or has ended is not waited for.
PAUSE_WAIT_S = 5.0

#: Whether this system can pause a process (``SIGSTOP`` / ``SIGCONT``).
CAN_PAUSE = hasattr(signal, "SIGSTOP") and hasattr(signal, "SIGCONT")


class StudyShare:
    """Which studies may have a process, and which of them runs now.

    ``processes``: studies with a process at once; ``running``: of those, how many run
    at once; ``turn_s`` [s]: the length of a turn; ``clock``: the time [s] (tests give
    their own). Keys are any hashable per study. A study's process is attached by its
    pid (:meth:`attach`); the share pauses and resumes the processes itself, both
    signals of a change of turn at once, so that two studies never run together.
    """

    def __init__(self, processes: int = MAX_STUDY_PROCESSES, running: int = MAX_RUNNING_STUDIES,
                 turn_s: float = TURN_S, pausable: bool = CAN_PAUSE,
                 clock: Callable[[], float] = time.monotonic) -> None:
        if processes < 1 or running < 1:
            raise ValueError("processes and running: at least 1 each")
        self.processes = processes if pausable else 1
        self.running = min(running, self.processes)
        self.turn_s = float(turn_s)
        self.pausable = pausable
        self._clock = clock
        self._cond = threading.Condition()
        self._queue: list[Hashable] = []  # waiting for a process, first come first
        self._ring: list[Hashable] = []  # with a process; the first `running` run
        self._pids: dict[Hashable, int] = {}
        self._turn_started = clock()

    def enter(self, key: Hashable, cancelled: Callable[[], bool],
              waiting: Callable[[int], None] | None = None, poll_s: float = 0.2) -> bool:
        """Wait until ``key`` may start its process; False (and out of the queue) when
        ``cancelled()`` turns true first. ``waiting(n)`` is told the studies ahead of
        it whenever that number changes."""
        with self._cond:
            self._queue.append(key)
            told = None
            try:
                while True:
                    ahead = self._queue.index(key)
                    if ahead == 0 and len(self._ring) < self.processes:
                        self._queue.pop(0)
                        self._ring.append(key)
                        if len(self._ring) <= self.running:
                            self._turn_started = self._clock()
                        self._cond.notify_all()
                        return True
                    if cancelled():
                        self._queue.remove(key)
                        self._cond.notify_all()
                        return False
                    if waiting is not None and ahead + len(self._ring) != told:
                        told = ahead + len(self._ring)
                        waiting(told)
                    self._cond.wait(poll_s)
            except BaseException:
                if key in self._queue:
                    self._queue.remove(key)
                raise

    def attach(self, key: Hashable, pid: int) -> None:
        """``key``'s study has started process ``pid``: it is paused at once unless it
        is its turn."""
        with self._cond:
            if key not in self._ring:
                raise ValueError("attach: the study has not entered")
            self._pids[key] = pid
            if self._ring.index(key) >= self.running:
                self._signal(key, pause)

    def leave(self, key: Hashable) -> None:
        """``key``'s study has ended: its process is gone (the next in the ring runs)."""
        with self._cond:
            self._pids.pop(key, None)
            if key in self._ring:
                index = self._ring.index(key)
                self._ring.remove(key)
                if index < self.running:
                    self._turn_started = self._clock()
                    self._apply()
            if key in self._queue:
                self._queue.remove(key)
            self._cond.notify_all()

    def runs(self, key: Hashable) -> bool:
        """Whether ``key``'s study runs now (else it is paused); at the end of a turn
        the ring moves on by one (any study's thread asking moves it)."""
        with self._cond:
            if key not in self._ring:
                return False
            if (len(self._ring) > self.running
                    and self._clock() - self._turn_started >= self.turn_s):
                self._ring.append(self._ring.pop(0))
                self._turn_started = self._clock()
                self._apply()
            return self._ring.index(key) < self.running

    def _apply(self) -> None:
        # pauses first: at no moment do more than `running` processes run
        for key in self._ring[self.running:]:
            self._signal(key, pause)
        for key in self._ring[:self.running]:
            self._signal(key, resume)

    def _signal(self, key: Hashable, action: Callable[[int], None]) -> None:
        pid = self._pids.get(key)
        if pid is None or not self.pausable:
            return
        try:
            action(pid)
        except OSError:  # the process has just ended; its thread will leave
            pass

    def sharing(self) -> int:
        """How many studies have a process now."""
        with self._cond:
            return len(self._ring)


#: The server's share of studies (one per process of the server).
SHARE = StudyShare()


def pause(pid: int) -> None:
    """Stop process ``pid`` where it is (``SIGSTOP``), and wait until it has stopped
    (at most :data:`PAUSE_WAIT_S`)."""
    os.kill(pid, signal.SIGSTOP)
    deadline = time.monotonic() + PAUSE_WAIT_S
    while not _stopped(pid) and time.monotonic() < deadline:
        time.sleep(0.001)


def _stopped(pid: int) -> bool:
    """Whether process ``pid`` is stopped, or gone, or cannot say (no ``/proc``)."""
    return process_state(pid) in (None, "T", "t", "Z", "X")


def process_state(pid: int) -> str | None:
    """The state letter of process ``pid`` in ``/proc`` ("R" running, "S" sleeping, "T"
    stopped, ...), or None when it is gone or the system does not say."""
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii", errors="replace") as stat:
            # the state follows the command name, which may hold spaces and ")"
            return stat.read().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return None


def resume(pid: int) -> None:
    """Let a paused process ``pid`` go on (``SIGCONT``; harmless on a running one)."""
    os.kill(pid, signal.SIGCONT)
