"""What runs in a solver worker process (started by :mod:`explorer.solving.workers`).

A worker's main loop (:func:`serve`) takes one request ``(fn, args)`` at a time from its
pipe and answers ``("ok", value, (start, end))`` or ``("error", exception, (start,
end))``; the functions the server asks for are here: :func:`solve_view`, :func:`preview_view`,
:func:`download_text` (the downloads, the printable report among them),
:func:`worker_info`. Nothing here imports Panel: the workers import only ``core`` and
:mod:`explorer.results` (a report loads HoloViews, Bokeh and Matplotlib in the worker
that builds it, when it does).
"""

from __future__ import annotations

import multiprocessing
import multiprocessing.connection
import os
import signal
import threading
import time
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import core.report
from core import release_freed_memory, set_stage_cache_budget, solve, stage_cache_bytes
from core.scene import elastic_at_loading
from core.work import bound_memory, cancellable

from ..model import FitOutcome, ResultView, prepare_view, run_fit
from .memory_bound import (
    RELEASE_AFTER_S,
    WORKER_MEMORY_BYTES,
    out_of_memory,
)

if TYPE_CHECKING:
    from core.back_analysis import Calibration

#: What :func:`download_text` can produce: the histories as CSV, q(x, t) as CSV, and the
#: whole solution as JSON (the methods of ``core.SceneSolution`` of the same names), and
#: the printable report as HTML (text) or PDF (bytes) (the functions of ``core.report``).
DOWNLOADS = ("to_csv", "pressure_csv", "to_json", "report_html", "report_pdf")
#: The printable reports among :data:`DOWNLOADS`.
REPORTS = ("report_html", "report_pdf")


def _watch_parent() -> None:
    # Killed without a chance to stop its workers (SIGKILL, a crash), the server would
    # leave them behind, waiting for work forever.
    parent = multiprocessing.parent_process()
    if parent is None:
        return
    multiprocessing.connection.wait([parent.sentinel])
    os._exit(0)


def _start_worker(stage_cache_bytes: int) -> None:
    # Ctrl+C in the terminal reaches the whole process group: the server stops its
    # workers itself, and a worker's traceback would only clutter the terminal.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    bound_memory(WORKER_MEMORY_BYTES)
    set_stage_cache_budget(stage_cache_bytes)
    threading.Thread(target=_watch_parent, name="watch-parent", daemon=True).start()


def solve_view(scene: dict[str, Any]) -> ResultView:
    """Solve ``scene`` (a scene dict) and prepare what the explorer draws.

    Runs in a worker. An invalid scene raises the core's ValueError, which names the field.
    """
    return prepare_view(solve(scene), scene)


def preview_view(scene: dict[str, Any], solve_scene: Any = solve) -> ResultView:
    """The preview of ``scene`` (a scene dict) shown while a slider waits for its release:
    the scene with its base elastic at loading (:func:`core.scene.elastic_at_loading`:
    at t = 0 the scene's answer up to the coating model, without creep later), solved
    (by ``solve_scene``, default :func:`core.solve`) and prepared as :func:`solve_view`
    does. Runs in a worker; an invalid scene raises the core's ValueError."""
    elastic = elastic_at_loading(scene)
    return prepare_view(solve_scene(elastic), elastic)


def download_text(scene: dict[str, Any], kind: str, info: dict[str, Any] | None = None,
                  shown_time: float | None = None,
                  check: dict[str, Any] | None = None,
                  calibration: Calibration | None = None) -> str | bytes:
    """The file ``kind`` (one of :data:`DOWNLOADS`) of the solution of ``scene``: the
    histories as CSV (time [day], settlement [m], tilt [rad], force [N/m], moment [N]),
    q(x, t) as CSV [Pa], the whole solution as JSON, or the printable report (HTML text,
    PDF bytes) checked against the scene's ``limits``.

    ``info``: the solve report of the result on screen (``ResultView.info``), written into
    the JSON and the report in place of the new solve's (whose timings and cache hits
    differ; its numbers do not). ``shown_time`` [day after loading]: the time on screen,
    whose contact the report describes. ``check``: the FE check of the coating model
    (:func:`core.scene.check_scene`), whose measurement the report gives when it was made
    for ``scene``. ``calibration``: the back-analysis whose fitted scene ``scene`` is,
    reported in a section of its own.
    """
    return solution_text(solve(scene), kind, info, shown_time, check, calibration)


def solution_text(solution: Any, kind: str, info: dict[str, Any] | None = None,
                  shown_time: float | None = None,
                  check: dict[str, Any] | None = None,
                  calibration: Calibration | None = None) -> str | bytes:
    """``solution.to_csv()``, ``.pressure_csv()``, the JSON of everything with the version
    and solver settings (:meth:`core.scene.SceneSolution.to_json`) or the report
    (:func:`core.report.report_html`, :func:`core.report.report_pdf` at ``shown_time``)
    (``kind``), with the solve report ``info`` in the JSON and the report if given (see
    :func:`download_text`)."""
    if kind not in DOWNLOADS:
        raise ValueError(f"kind: unknown download {kind!r}; known: {', '.join(DOWNLOADS)}")
    if info is not None and kind in ("to_json", *REPORTS):
        solution.info = {k: v for k, v in info.items() if k != "reused"}
    if kind == "to_json":
        # the version and the solver settings beside the scene, as the command line writes
        return solution.to_json()
    if kind in REPORTS:
        # the command line's report; HoloViews, Bokeh and Matplotlib load with the first
        return getattr(core.report, kind)(solution, shown_time, check=check,
                                          calibration=calibration)
    return getattr(solution, kind)()


def fit_outcome(scene: dict[str, Any], readings: Any, keys: list[str | None]) -> FitOutcome:
    """:func:`explorer.model.run_fit` in a worker: the outcome without the forecast's
    solution object (which stays in the worker, as a slider solve's does: the page draws
    the forecast's histories and band, which it keeps)."""
    outcome = run_fit(scene, readings, keys)
    if outcome.forecast is None:
        return outcome
    return replace(outcome, forecast=replace(outcome.forecast, solution=None))


def worker_info() -> dict[str, int]:
    """The worker's process id and the bound of its solver stage caches [bytes]."""
    return {"pid": os.getpid(), "stage_cache_bytes": stage_cache_bytes()}


def serve(connection: multiprocessing.connection.Connection, stage_cache_bytes: int,
          cancel: Any = None) -> None:
    # A worker's main loop: one request (fn, args) in, one ("ok", value) or ("error",
    # exception) out, on its own pipe. No executor between the server and the worker: a
    # ProcessPoolExecutor hands each request and each result over through two more threads
    # of the server (its queue feeder and its manager), and on a busy machine every
    # hand-over waits for a core.
    # ``cancel`` (a shared integer): the number of the request (1, 2, ... in the order
    # received) whose answer the server no longer wants; the solve stops at its next
    # check (core.work.cancellable).
    _start_worker(stage_cache_bytes)
    received = 0
    while True:
        try:
            fn, args = connection.recv()
        except (EOFError, OSError):  # the server closed the pipe (or is gone)
            return
        received += 1
        start = time.monotonic()
        try:
            with cancellable(lambda number=received: cancel is not None
                             and cancel.value == number):
                value = fn(*args)
            reply: tuple[str, Any, tuple[float, float]] = ("ok", value, (start, 0.0))
        except MemoryError:  # the bound of this worker, said in words
            reply = ("error", MemoryError(out_of_memory(
                "this solve", WORKER_MEMORY_BYTES, "fewer output times (times.count) or a "
                "looser solver.tol need less")), (start, 0.0))
        except BaseException as exc:  # the server raises it in the caller
            reply = ("error", exc, (start, 0.0))
        reply = (reply[0], reply[1], (start, time.monotonic()))  # when it worked [s]
        try:
            connection.send(reply)
        except (BrokenPipeError, EOFError, OSError):
            return
        except Exception as exc:  # a value or exception that does not pickle
            connection.send(("error", RuntimeError(f"{type(exc).__name__}: {exc}"),
                             reply[2]))
        if reply[2][1] - start >= RELEASE_AFTER_S and not connection.poll():
            release_freed_memory()
