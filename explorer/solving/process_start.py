"""How the server starts its processes (solver workers and studies): forked from a fork
server that imported the solver's modules once.

A process started by the spawn method is a fresh interpreter that imports ``core``,
NumPy and SciPy again: ~1-1.5 s of CPU for each solver worker and each study, paid again
for a worker replaced after a crash or a stuck solve. The fork server is itself a fresh
interpreter (started on first use, not a fork of the server, so no thread or lock of the
server is copied in whatever state it is); it imports :data:`PRELOAD` once, and each
process forks from it warm, sharing those pages until it writes them. Where there is no
fork server (Windows), processes are spawned as before.

A forked process's parent is the fork server, not the server: the parent sentinel
multiprocessing gives it (``multiprocessing.parent_process()``) is still the server's
end of its pipe, which closes when the server ends, however it ends.
"""

from __future__ import annotations

import multiprocessing
import threading
from typing import Any

__all__ = ["PRELOAD", "process_context"]

#: Modules the fork server imports before it forks a process: the solver's, the parts of
#: SciPy it uses, and what a solver worker and a study's process run.
PRELOAD = ["core.study", "core.scene", "core.solver", "core.engines.nystrom",
           "core.engines.projection", "core.contact", "core.creep", "core.time",
           "scipy.linalg", "scipy.interpolate", "scipy.optimize", "scipy.special",
           "scipy.sparse", "scipy.fft", "xarray", "explorer.solving.worker_side",
           "explorer.solving.study_runner"]

_CONTEXT: Any = None
_LOCK = threading.Lock()


def process_context() -> Any:
    """The multiprocessing context the server's processes start from (the fork server's,
    its modules set once for the server's life; else the spawn method's)."""
    global _CONTEXT
    with _LOCK:
        if _CONTEXT is None:
            if "forkserver" in multiprocessing.get_all_start_methods():
                context = multiprocessing.get_context("forkserver")
                context.set_forkserver_preload(PRELOAD)
            else:
                context = multiprocessing.get_context("spawn")
            _CONTEXT = context
        return _CONTEXT
