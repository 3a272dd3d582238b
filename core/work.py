"""The bound on the work of one solve: the CPU time it may take, checked as it goes.

Most work is bounded before it starts (``core.limits``: the sizes of grids, tables and
time steps). Some cannot be predicted: lift-off under creep follows its contact zones
step by step, each step with its own active-set sweeps. Its loops call :func:`check_work`,
which stops the solve once the bound set by :func:`work_bound` (around a whole solve) is
spent: :class:`WorkLimitExceeded`, which the scene level words as a ``ValueError`` naming
the field to change. It is not a ``ValueError`` itself: the solver's fallbacks (full
contact where the unilateral solver refuses a scene) must not take it for a refusal.

The bound is this thread's CPU time (``time.thread_time``), so a busy machine does not
stop a solve that a quiet one would finish; it lives in a context variable, so threads
solving at the same time have their own.

The same loops stop a solve whose answer is no longer wanted (:func:`cancellable`: a
newer request of the same user superseded it): :class:`SolveCancelled`, which no level
of the solver words or catches.

A solve runs its dense linear algebra on one BLAS thread (:func:`one_blas_thread`): its
matrices are small, and more BLAS threads only fight for the cores.
"""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Any, TypeVar

from core import limits

T = TypeVar("T")

#: Variables by which a user sets the BLAS libraries' threads: where one is set, solves
#: keep that setting (:func:`one_blas_thread`).
BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS",
                         "BLIS_NUM_THREADS")

#: (deadline in this thread's CPU time [s], the bound it came from [s]), or None.
_BOUND: ContextVar[tuple[float, float] | None] = ContextVar("solve_work_bound", default=None)
#: Whether the answer of the solve in this context is no longer wanted, or None.
_CANCELLED: ContextVar[Callable[[], bool] | None] = ContextVar("solve_cancelled", default=None)


#: The address space each core of the machine adds to a memory bound [bytes]: the
#: numerical libraries start a thread per core, and each maps its stack (8 MiB), a malloc
#: arena (up to 64 MiB) and a BLAS buffer (~32 MiB) whether it uses them or not, so a fixed
#: bound would refuse a process's start on a machine with many cores.
PER_CORE_BYTES = 128 * 2**20


def address_space_bound(work_bytes: int) -> int:
    """The address-space bound [bytes] of a process whose work may take ``work_bytes``
    [bytes] on this machine (:data:`PER_CORE_BYTES` added per core)."""
    return work_bytes + (os.cpu_count() or 1) * PER_CORE_BYTES


def bound_memory(work_bytes: int) -> int | None:
    """Bound this process's address space to :func:`address_space_bound` of
    ``work_bytes`` [bytes] (never above a bound set from outside): past it an allocation
    raises ``MemoryError`` in this process alone. Returns the bound [bytes], or None where
    the system has no such bound (Windows)."""
    try:
        import resource
    except ImportError:
        return None
    limit = address_space_bound(work_bytes)
    _, hard = resource.getrlimit(resource.RLIMIT_AS)
    if hard != resource.RLIM_INFINITY:
        limit = min(limit, hard)
    resource.setrlimit(resource.RLIMIT_AS, (limit, hard))
    return limit


class SolveCancelled(RuntimeError):
    """A solve stopped because its answer is no longer wanted (:func:`cancellable`)."""


class WorkLimitExceeded(RuntimeError):
    """A solve spent its CPU-time bound; ``seconds`` is the bound [s], ``doing`` what the
    solve was doing when it was stopped (words for a message), ``zones`` how many contact
    zones it was following then (0: none, or not counted)."""

    def __init__(self, seconds: float, doing: str, zones: int = 0) -> None:
        super().__init__(f"the solve was stopped after {seconds:g} s of CPU time (the bound "
                         "of one solve, core.limits.MAX_SOLVE_CPU_SECONDS by default) while "
                         f"{doing}")
        self.seconds = seconds
        self.doing = doing
        self.zones = zones


@contextmanager
def work_bound(seconds: float | None = limits.MAX_SOLVE_CPU_SECONDS) -> Iterator[None]:
    """Bound the CPU time [s] of the work inside (None: no bound of its own). Inside an
    outer bound the tighter one holds."""
    now = time.thread_time()
    bound = None if seconds is None else (now + float(seconds), float(seconds))
    outer = _BOUND.get()
    if outer is not None and (bound is None or outer[0] <= bound[0]):
        bound = outer
    token = _BOUND.set(bound)
    try:
        yield
    finally:
        _BOUND.reset(token)


@contextmanager
def cancellable(cancelled: Callable[[], bool]) -> Iterator[None]:
    """Stop the work inside with :class:`SolveCancelled` at the next :func:`check_work`
    once ``cancelled()`` is true (it is asked there, so it must be cheap: ~1 us)."""
    token = _CANCELLED.set(cancelled)
    try:
        yield
    finally:
        _CANCELLED.reset(token)


def check_work(doing: str, zones: int = 0) -> None:
    """Raise :class:`WorkLimitExceeded` if the bound of the solve in this thread is spent,
    :class:`SolveCancelled` if its answer is no longer wanted; ``doing``: what the loop
    calling it does (e.g. "following lift-off under creep"), ``zones``: the contact zones
    it follows (what made it costly when they are many)."""
    bound = _BOUND.get()
    if bound is not None and time.thread_time() > bound[0]:
        raise WorkLimitExceeded(bound[1], doing, zones)
    cancelled = _CANCELLED.get()
    if cancelled is not None and cancelled():
        raise SolveCancelled(f"the solve was cancelled while {doing}")


# One BLAS thread during solves: the libraries' thread counts are process-wide, so the
# first solve to start sets them and the last to end restores them (solves may run in
# several threads at once).
_blas_lock = threading.Lock()
_blas_solves = 0
_blas_limiter: Any = None
_blas_controller: Any = None


@contextmanager
def one_blas_thread() -> Iterator[None]:
    """Run the work inside with the BLAS libraries (NumPy's and SciPy's) on one thread each,
    and give them back their thread counts once no solve runs.

    The solver's dense matrices are small (tens to a few thousand rows) and it is called
    again and again; BLAS threads on top of that mostly fight for the cores. In a Python
    session on a 2-core machine (OpenBLAS at its default of one thread per core), a new
    geometry of the presets took 0.9-2.8x the wall time and 1-5.5x the CPU time of the same
    solve on one thread, a load change 0.8-2.0x and 0.8-3.8x (two runs of ``python -m
    benchmarks.blas_threads``, ``benchmarks/results/blas_threads.md``). Where the user set
    the threads (one of :data:`BLAS_THREAD_VARIABLES`), that setting is kept. Costs ~11 us
    a solve (6 ms once, to find the libraries). ``OPENBLAS_NUM_THREADS=1`` set before NumPy
    is imported (the explorer's server and the study workers set it) does a little more:
    OpenBLAS then starts no worker threads, which on some paths keep spinning beside a
    solve even on one thread (``worn_coating``'s new geometry: CPU twice its wall time).
    """
    global _blas_solves, _blas_limiter
    if any(os.environ.get(name) for name in BLAS_THREAD_VARIABLES):
        yield
        return
    with _blas_lock:
        if _blas_solves == 0:
            try:
                _blas_limiter = _as_openblas_owner(
                    lambda: _controller().limit(limits=1, user_api="blas"))
            except Exception:  # noqa: BLE001 - a library it cannot set: solve as it is
                _blas_limiter = None
        _blas_solves += 1
    try:
        yield
    finally:
        with _blas_lock:
            _blas_solves -= 1
            if _blas_solves == 0 and _blas_limiter is not None:
                # the last solve to end may run in another thread than the first
                try:
                    _as_openblas_owner(_blas_limiter.restore_original_limits)
                finally:
                    _blas_limiter = None


def _as_openblas_owner(action: Callable[[], T]) -> T:
    """``action()`` with this thread taken, for its length, as the one that may set the size
    of OpenBLAS's shared (pthreads) thread pool; the thread that held that role before gets
    it back after.

    threadpoolctl (from 3.8) lets only one thread set that size, the first to set it; the
    settings of every other thread silently do nothing. Without this, a solve in a thread
    after a solve in the main thread (or after the user set the count there) ran on the
    user's count (two solves at once in threads read 2 threads inside). Solves do not fight
    over the size among themselves (this module's lock and count of running solves), and
    a user's own ``threadpool_limits`` keeps its role (restored after). The role lives in
    threadpoolctl's private ``OpenBLASController._SHARED_STATE``; a version without it
    (older ones have no such rule) just runs ``action``."""
    try:
        from threadpoolctl import OpenBLASController
    except ImportError:
        return action()
    state = getattr(OpenBLASController, "_SHARED_STATE", None)
    if state is None or not hasattr(state, "controlling_thread"):
        return action()
    with state.lock:
        before = state.controlling_thread
        state.controlling_thread = threading.current_thread()
    try:
        return action()
    finally:
        with state.lock:
            state.controlling_thread = before


def _controller() -> Any:
    """The BLAS libraries of this process (found once; SciPy's own OpenBLAS is loaded with
    :mod:`scipy.linalg`, which every solve imports)."""
    global _blas_controller
    if _blas_controller is None:
        import scipy.linalg  # noqa: F401
        from threadpoolctl import ThreadpoolController

        _blas_controller = ThreadpoolController()
    return _blas_controller
