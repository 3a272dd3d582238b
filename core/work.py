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
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar

from core import limits

#: (deadline in this thread's CPU time [s], the bound it came from [s]), or None.
_BOUND: ContextVar[tuple[float, float] | None] = ContextVar("solve_work_bound", default=None)
#: Whether the answer of the solve in this context is no longer wanted, or None.
_CANCELLED: ContextVar[Callable[[], bool] | None] = ContextVar("solve_cancelled", default=None)


class SolveCancelled(RuntimeError):
    """A solve stopped because its answer is no longer wanted (:func:`cancellable`)."""


class WorkLimitExceeded(RuntimeError):
    """A solve spent its CPU-time bound; ``seconds`` is the bound [s], ``doing`` what the
    solve was doing when it was stopped (words for a message)."""

    def __init__(self, seconds: float, doing: str) -> None:
        super().__init__(f"the solve was stopped after {seconds:g} s of CPU time (the bound "
                         "of one solve, core.limits.MAX_SOLVE_CPU_SECONDS by default) while "
                         f"{doing}")
        self.seconds = seconds
        self.doing = doing


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


def check_work(doing: str) -> None:
    """Raise :class:`WorkLimitExceeded` if the bound of the solve in this thread is spent,
    :class:`SolveCancelled` if its answer is no longer wanted; ``doing``: what the loop
    calling it does (e.g. "following lift-off under creep")."""
    bound = _BOUND.get()
    if bound is not None and time.thread_time() > bound[0]:
        raise WorkLimitExceeded(bound[1], doing)
    cancelled = _CANCELLED.get()
    if cancelled is not None and cancelled():
        raise SolveCancelled(f"the solve was cancelled while {doing}")
