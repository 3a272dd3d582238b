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
cancelled (the process is terminated: the work really stops), took longer than
:data:`STUDY_TIMEOUT_S`, or the session closed. At most :data:`MAX_RUNNING_STUDIES` run
at once in a server; a study started meanwhile waits (and can be cancelled while it
waits).

Nothing here imports Panel.
"""

from __future__ import annotations

import logging
import math
import multiprocessing
import os
import queue
import signal
import threading
import time
from collections.abc import Callable
from typing import Any

import param

from core.study import sweep

from ..model import PlannedStudy, StudyResult

log = logging.getLogger(__name__)

#: Studies running at once in one server: each takes a core while it runs, and the
#: machine also serves every page's slider solves.
MAX_RUNNING_STUDIES = 1
#: A study of the page is stopped after this long [s]: :data:`explorer.model.study.MAX_POINTS`
#: points at the slowest valid scene's 0.7 s per point are ~280 s of CPU, and a loaded
#: machine stretches that.
STUDY_TIMEOUT_S = 600.0
#: Batches per study: the progress bar moves (and a cancelled study is noticed) once per
#: batch; a batch also costs a small file write.
PROGRESS_STEPS = 50
#: Least time between two progress updates sent to the page [s].
PROGRESS_EVERY_S = 0.1
#: Modules the fork server imports once, so that a study's process starts warm: the
#: solver's modules and scipy's parts it uses cost ~1 s of CPU to import (measured), which
#: every study would pay again.
_PRELOAD = ["core.study", "core.scene", "core.solver", "core.engines.nystrom",
            "core.engines.projection", "core.contact", "core.creep", "core.time", "scipy.linalg",
            "scipy.interpolate", "scipy.optimize", "scipy.special", "scipy.sparse",
            "scipy.fft", "xarray", "explorer.solving.study_runner"]

_SLOTS = threading.BoundedSemaphore(MAX_RUNNING_STUDIES)
_CONTEXT: Any = None
_CONTEXT_LOCK = threading.Lock()


def _context() -> Any:
    """The multiprocessing context studies start from (a fork server, started once)."""
    global _CONTEXT
    with _CONTEXT_LOCK:
        if _CONTEXT is None:
            if "forkserver" in multiprocessing.get_all_start_methods():
                ctx = multiprocessing.get_context("forkserver")
                ctx.set_forkserver_preload(_PRELOAD)
            else:  # Windows: a fresh interpreter per study (a slower start)
                ctx = multiprocessing.get_context("spawn")
            _CONTEXT = ctx
        return _CONTEXT


# -- what runs in the study's process ------------------------------------------------------
def _run_study(planned: PlannedStudy, batch_points: int, out: Any, server_pid: int) -> None:
    """Run the study and put ``("progress", done, total)`` after every batch, then
    ``("done", arrays)`` or ``("error", message)`` on ``out``."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl+C is the server's to handle

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
        arrays = {name: ds[name].values for name in ("flags", "error")}
        arrays |= {name: ds[name].values for name in ds.data_vars
                   if name in planned.study.outputs}
        arrays["time"] = ds.time.values
        arrays["seconds"] = time.perf_counter() - start
        arrays["cpu_seconds"] = time.process_time() - cpu
        out.put(("done", arrays))
    except Exception as exc:  # noqa: BLE001 - reported to the page, never raised there
        out.put(("error", f"{type(exc).__name__}: {' '.join(str(exc).split())}"[:500]))


# -- the server's side ---------------------------------------------------------------------
class StudyRun(param.Parameterized):
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

    def __init__(self, dispatch: Callable[[Callable[[], None]], None] | None = None,
                 **params: Any) -> None:
        super().__init__(**params)
        self._dispatch = dispatch or (lambda callback: callback())
        self._cancel = threading.Event()
        self._thread: threading.Thread | None = None
        self.process: Any = None

    @property
    def running(self) -> bool:
        """Whether a study is waiting or running."""
        return self._thread is not None and self._thread.is_alive()

    def start(self, planned: PlannedStudy) -> None:
        """Run ``planned`` in the background (one study per session at a time)."""
        if self.running:
            raise RuntimeError("a study is already running; cancel it first")
        self._cancel = threading.Event()
        self.param.update(status="waiting", done=0, total=planned.study.n_points,
                          message="starting")
        self._thread = threading.Thread(target=self._work, args=(planned, self._cancel),
                                        name="study", daemon=True)
        self._thread.start()

    def cancel(self) -> None:
        """Stop the running study now (its process is terminated)."""
        self._cancel.set()

    def wait(self, timeout: float = STUDY_TIMEOUT_S + 30) -> bool:
        """Wait for the run to end; False if it is still running after ``timeout`` [s]."""
        thread = self._thread
        if thread is not None:
            thread.join(timeout)
        return not self.running

    def _set(self, **values: Any) -> None:
        self._dispatch(lambda: self.param.update(**values))

    def _work(self, planned: PlannedStudy, cancel: threading.Event) -> None:
        if not _SLOTS.acquire(blocking=False):
            self._set(message="waiting for another study (of this or another page) to "
                              "finish")
            while not _SLOTS.acquire(timeout=0.2):
                if cancel.is_set():
                    self._set(status="cancelled", message="cancelled before it started")
                    return
        try:
            self._run(planned, cancel)
        except Exception as exc:  # noqa: BLE001 - the page says so; the server goes on
            log.exception("study failed")
            self._set(status="failed", message=f"the study could not run: {exc}")
        finally:
            _SLOTS.release()

    def _run(self, planned: PlannedStudy, cancel: threading.Event) -> None:
        n = planned.study.n_points
        ctx = _context()
        out = ctx.Queue()
        batch = max(1, math.ceil(n / PROGRESS_STEPS))
        process = ctx.Process(target=_run_study, args=(planned, batch, out, os.getpid()),
                              name="study", daemon=True)
        self.process = process
        started = time.monotonic()
        process.start()
        self._set(status="running", message=f"running: 0 of {n} points")
        sent = 0.0
        outcome: tuple[str, Any] | None = None
        try:
            while outcome is None:
                if cancel.is_set():
                    outcome = ("cancelled", None)
                    break
                if time.monotonic() - started > STUDY_TIMEOUT_S:
                    outcome = ("failed", f"the study took longer than {STUDY_TIMEOUT_S:.0f} "
                               "s and was stopped; use fewer points")
                    break
                try:
                    item = out.get(timeout=0.1)
                except queue.Empty:
                    if not process.is_alive() and out.empty():
                        outcome = ("failed", "the study's process stopped (out of memory?)")
                    continue
                if item[0] == "progress":
                    now = time.monotonic()
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
    """End ``process`` if it still runs: terminate, then kill."""
    if process.is_alive():
        process.terminate()
        process.join(2.0)
    if process.is_alive():
        process.kill()
    process.join(2.0)
