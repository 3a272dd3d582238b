"""Running a study of the Study tab off the page's event loop, cancellably.

Where it runs: in a process of its own, one per study, started from a fork server that
has ``core`` already imported (a start costs a fork, not the 1-2 s of importing numpy,
scipy and the solver). The study runs there with ``core.sweep(..., client="serial")``:
batches in order, so points sharing a geometry reuse the solver's prepared stages as on
a Dask worker. Why not Dask: a cluster started per click costs seconds and a process per
core, and the server's machine is shared by every session; why not the explorer's
solver processes: a study would hold a session's solver lane for minutes (its slider
steps would wait), and stopping one means killing that worker and its warm caches.

A thread of the server only waits: it reads the progress the process sends (after every
batch), hands it to the page through ``dispatch`` and ends the process when the study is
cancelled (the process is terminated: the work really stops), ran longer than
:data:`STUDY_TIMEOUT_S`, or the session closed. The server's studies share its study core
in turns (:mod:`explorer.solving.fair_share`): a few have a process at once and run one
at a time, a turn each, the others paused; more wait, first come first served (and can
be cancelled while they wait). A study's process is bounded in memory
(:data:`explorer.solving.memory_bound.STUDY_MEMORY_BYTES`, its solver caches by
:data:`STUDY_CACHE_BYTES`).

Nothing here imports Panel.
"""

from __future__ import annotations

import logging
import math
import os
import queue
import signal
import threading
import time
from collections.abc import Callable
from typing import Any

import param

from core import set_stage_cache_budget
from core.study import sweep
from core.work import bound_memory

from ..model import PlannedStudy, StudyResult
from .background import BackgroundRun
from .fair_share import SHARE, StudyShare, resume
from .memory_bound import STUDY_MEMORY_BYTES, out_of_memory
from .priority import lower_process_priority
from .process_start import process_context

log = logging.getLogger(__name__)

#: A study of the page is stopped after running this long [s] (its paused turns not
#: counted): :data:`explorer.model.study.MAX_POINTS` points at the slowest valid scene's
#: 0.7 s per point are ~280 s of CPU, and a loaded machine stretches that.
STUDY_TIMEOUT_S = 600.0
#: The solver's stage caches in a study's process [bytes] (``core.set_stage_cache_budget``):
#: a study's points share one geometry per batch at most, so the caches need hold little.
STUDY_CACHE_BYTES = 256 * 1024**2
#: Batches per study: the progress bar moves (and a cancelled study is noticed) once per
#: batch; a batch also costs a small file write.
PROGRESS_STEPS = 50
#: Least time between two progress updates sent to the page [s].
PROGRESS_EVERY_S = 0.1
# -- what runs in the study's process ------------------------------------------------------
def _run_study(planned: PlannedStudy, batch_points: int, out: Any, server_pid: int) -> None:
    """Run the study and put ``("progress", done, total)`` after every batch, then
    ``("done", arrays)`` or ``("error", message)`` on ``out``."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl+C is the server's to handle
    lower_process_priority()  # the pages' slider solves come first
    bound_memory(STUDY_MEMORY_BYTES)
    set_stage_cache_budget(STUDY_CACHE_BYTES)

    def progress(done: int, total: int) -> bool:
        out.put(("progress", done, total))
        try:
            os.kill(server_pid, 0)  # stop when the server is gone
        except OSError:
            return False
        return True

    try:
        start, cpu = time.perf_counter(), time.process_time()
        ds = sweep(planned.study, client="serial", batch_points=batch_points,
                   progress=progress)
        arrays = {name: ds[name].values for name in ("flags", "error", "error_estimate")}
        # a punch's output of several is named like punches_1_tilt, its path in "output"
        arrays |= {ds[name].attrs.get("output", name): ds[name].values
                   for name in ds.data_vars
                   if ds[name].attrs.get("output", name) in planned.study.outputs}
        arrays["time"] = ds.time.values
        arrays["seconds"] = time.perf_counter() - start
        arrays["cpu_seconds"] = time.process_time() - cpu
        out.put(("done", arrays))
    except MemoryError:
        out.put(("error", out_of_memory("the study", STUDY_MEMORY_BYTES,
                                        "use fewer points or output times (or run it with "
                                        "coated-punch sweep)")))
    except Exception as exc:  # noqa: BLE001 - reported to the page, never raised there
        out.put(("error", f"{type(exc).__name__}: {' '.join(str(exc).split())}"[:500]))


# -- the server's side ---------------------------------------------------------------------
class StudyRun(BackgroundRun):
    """The study of one session: its state, its progress and its result.

    ``dispatch`` runs a callback on the session's event loop (the app's); without one the
    updates are applied from the waiting thread (tests, scripts).
    """

    status = param.Selector(default="idle", objects=["idle", "waiting", "running", "done",
                                                     "cancelled", "failed"])
    done = param.Integer(default=0, doc="Points finished.")
    total = param.Integer(default=0, doc="Points of the study.")
    message = param.String(default="", doc="What the run did, or why it stopped.")
    result = param.Parameter(default=None, doc="The last StudyResult.")

    WAIT_S = STUDY_TIMEOUT_S + 30

    def __init__(self, dispatch: Callable[[Callable[[], None]], None] | None = None,
                 share: StudyShare | None = None, **params: Any) -> None:
        """``share``: the studies this one takes turns with (default: the server's)."""
        super().__init__(dispatch, **params)
        self._share = SHARE if share is None else share
        self._cancel = threading.Event()
        self.process: Any = None

    def start(self, planned: PlannedStudy) -> None:
        """Run ``planned`` in the background (one study per session at a time)."""
        if self.running:
            raise RuntimeError("a study is already running; cancel it first")
        self._cancel = threading.Event()
        self.param.update(status="waiting", done=0, total=planned.study.n_points,
                          message="starting")
        self._launch(self._work, (planned, self._cancel), "study")

    def cancel(self) -> None:
        """Stop the running study now (its process is terminated)."""
        self._cancel.set()

    def _work(self, planned: PlannedStudy, cancel: threading.Event) -> None:
        ticket = object()  # this run's place in the server's turns

        def waiting(ahead: int) -> None:
            self._set(message=f"waiting: {ahead} {'study' if ahead == 1 else 'studies'} "
                              "(of this or other pages) ahead, the server runs "
                              f"{self._share.processes} in turns")

        if not self._share.enter(ticket, cancel.is_set, waiting):
            self._set(status="cancelled", message="cancelled before it started")
            return
        try:
            self._run(planned, cancel, ticket)
        except Exception as exc:  # noqa: BLE001 - the page says so; the server goes on
            log.exception("study failed")
            self._set(status="failed", message=f"the study could not run: {exc}")
        finally:
            self._share.leave(ticket)

    def _run(self, planned: PlannedStudy, cancel: threading.Event, ticket: object) -> None:
        n = planned.study.n_points
        ctx = process_context()
        out = ctx.Queue()
        batch = max(1, math.ceil(n / PROGRESS_STEPS))
        process = ctx.Process(target=_run_study, args=(planned, batch, out, os.getpid()),
                              name="study", daemon=True)
        self.process = process
        started = time.monotonic()
        process.start()
        self._share.attach(ticket, process.pid)
        self._set(status="running", message=f"running: 0 of {n} points")
        sent = 0.0
        outcome: tuple[str, Any] | None = None
        # the running time (paused turns left out) is what the timeout bounds
        ran, last, paused, done = 0.0, started, False, 0
        try:
            while outcome is None:
                now = time.monotonic()
                if not paused:
                    ran += now - last
                last = now
                if self._share.runs(ticket) == paused:
                    paused = not paused
                    others = self._share.sharing() - 1
                    self._set(message=(
                        f"paused while {others} other {'study' if others == 1 else 'studies'}"
                        f" take{'s' if others == 1 else ''} a turn: {done} of {n} points"
                        if paused else f"running: {done} of {n} points"))
                if cancel.is_set():
                    outcome = ("cancelled", None)
                    break
                if ran > STUDY_TIMEOUT_S:
                    outcome = ("failed", f"the study ran longer than {STUDY_TIMEOUT_S:.0f} "
                               "s and was stopped; use fewer points")
                    break
                try:
                    item = out.get(timeout=0.1)
                except queue.Empty:
                    if not process.is_alive() and out.empty():
                        outcome = ("failed", "the study's process stopped (out of memory?)")
                    continue
                if item[0] == "progress":
                    now, done = time.monotonic(), int(item[1])
                    if now - sent >= PROGRESS_EVERY_S or item[1] >= item[2]:
                        sent = now
                        self._set(done=int(item[1]),
                                  message=f"running: {item[1]} of {item[2]} points")
                elif item[0] == "done":
                    outcome = ("done", item[1])
                else:
                    outcome = ("failed", f"the study failed: {item[1]}")
        finally:
            _stop(process)
            out.close()
            out.join_thread()
        kind, payload = outcome
        if kind == "done":
            result = StudyResult.from_arrays(planned, payload)
            failed, flagged = int(result.failed.sum()), int(result.flagged.sum())
            # the CPU time says what the study cost when the machine is busy
            cpu = float(payload.get("cpu_seconds", float("nan")))
            self._set(status="done", done=n, result=result,
                      message=f"{n} points in {time.monotonic() - started:.1f} s "
                              f"({cpu:.1f} s of CPU), {failed} failed, {flagged} flagged")
        elif kind == "cancelled":
            self._set(status="cancelled", message="cancelled: the study was stopped")
        else:
            self._set(status="failed", message=payload)


def _stop(process: Any) -> None:
    """End ``process`` if it still runs: terminate, then kill (a paused process is
    resumed first: it takes no signal but a kill while stopped)."""
    if process.is_alive():
        try:
            resume(process.pid)
        except OSError:
            pass
        process.terminate()
        process.join(2.0)
    if process.is_alive():
        process.kill()
    process.join(2.0)
