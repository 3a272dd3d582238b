"""Background work gives the CPU to slider solves first.

A study (a process of its own), a coating check and a fit (a worker's request each) run
for seconds to minutes at full speed; on a 2-core server they took a core from every
page's slider solves, whose answers then came late (benchmarks/results/load_test.md).
They now run at the operating system's lower priority (niceness
:data:`BACKGROUND_NICENESS` over the server's): where a slider solve and background work
want the same core, the scheduler gives the slider ~90 % of it; on an idle core the
background work runs at full speed.

Linux sets a niceness per thread, which is what a worker needs: it cannot take back a
lower priority once given (without privileges), so a check or a fit runs on a thread of
its own at the lower priority while the worker's main thread waits, and the worker's next
request runs at the server's priority again. Elsewhere they run as they did.

Nothing here imports Panel.
"""

from __future__ import annotations

import os
import sys
import threading
from typing import Any

__all__ = ["BACKGROUND_NICENESS", "at_background_priority", "lower_process_priority",
           "thread_niceness"]

#: How much nicer than the server background work runs (Linux: a weight of ~1/10 of a
#: default thread's where both want one core; 19 is the nicest).
BACKGROUND_NICENESS = 10

#: Whether this system has a niceness per thread (Linux).
PER_THREAD = sys.platform.startswith("linux") and hasattr(os, "setpriority")


def thread_niceness() -> int:
    """The calling thread's niceness (Linux; the process's elsewhere, 0 without one)."""
    if PER_THREAD:
        return os.getpriority(os.PRIO_PROCESS, threading.get_native_id())
    if hasattr(os, "getpriority"):
        return os.getpriority(os.PRIO_PROCESS, 0)
    return 0


def lower_process_priority() -> None:
    """Make the calling process (a study's, which does nothing else) nicer by
    :data:`BACKGROUND_NICENESS`; a system without niceness is left as it is."""
    if hasattr(os, "nice"):
        try:
            os.nice(BACKGROUND_NICENESS)
        except OSError:  # a container may refuse: the work runs all the same
            pass


def at_background_priority(fn: Any, *args: Any) -> Any:
    """``fn(*args)`` on a thread of its own at :data:`BACKGROUND_NICENESS` over the
    caller's (Linux), its value returned and its exception raised here; elsewhere
    ``fn(*args)`` as it is. For a worker process, whose later requests must run at the
    server's priority again."""
    if not PER_THREAD:
        return fn(*args)
    outcome: dict[str, Any] = {}

    def run() -> None:
        try:
            os.setpriority(os.PRIO_PROCESS, threading.get_native_id(),
                           thread_niceness() + BACKGROUND_NICENESS)
        except OSError:
            pass
        try:
            outcome["value"] = fn(*args)
        except BaseException as exc:  # noqa: BLE001 - raised again in the caller
            outcome["error"] = exc

    worker = threading.Thread(target=run, name="background-priority", daemon=True)
    worker.start()
    worker.join()
    if "error" in outcome:
        raise outcome["error"]
    return outcome["value"]
