"""Solving off the page's thread: a change of the state becomes a ``core.solve``, and its
answer comes back to the page.

Nothing here imports Panel or Bokeh when imported (the solver workers import it too).

- ``controller``: :class:`SolveController`, one per session: requests, coalescing, stale
  results, error messages; where solves run (threads or worker processes).
- ``workers``: :class:`SolverProcesses`, the worker processes of a served explorer, and
  ``worker_side``, what runs inside them.
- ``answer_wait``: a worker's answer awaited on the server's event loop.
- ``result_cache``: the process-wide cache of prepared results.
- ``warm_up``: presets solved before the first visitor comes; ``idle_release``: the
  caches emptied once no session has been open for a while (and the presets warmed again).
- ``fit_runner``: :class:`FitRun`, a fit of the Fit tab on a thread of its own;
  ``background``: the lifecycle it shares with :class:`StudyRun`.
- ``study_runner``: :class:`StudyRun`, a design study in a process of its own;
  ``fair_share``: the turns the server's studies take (:class:`StudyShare`).
- ``memory_bound``: the address-space bounds of the worker and study processes.
- ``priority``: studies, coating checks and fits at a lower CPU priority than slider solves.
- ``process_start``: the fork server the worker and study processes start from, warm.
- ``trace``: timestamps of a slider move's way through the server (latency benchmark).
"""

from . import idle_release
from .controller import (
    RESULTS,
    SolveController,
    approx_bytes,
    describe_field,
    format_error,
    run_in_background,
    shared_pool,
    use_worker_processes,
    worker_processes,
)
from .fit_runner import FitRun
from .study_runner import StudyRun
from .trace import install_websocket_marks, mark
from .warm_up import warm_up
from .workers import SolverProcesses, WorkerFailed

__all__ = ["RESULTS", "FitRun", "SolveController", "SolverProcesses", "StudyRun", "WorkerFailed",
           "approx_bytes", "describe_field", "format_error", "idle_release",
           "install_websocket_marks", "mark",
           "run_in_background", "shared_pool", "use_worker_processes", "warm_up",
           "worker_processes"]
