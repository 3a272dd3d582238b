"""Giving memory back once nobody has used the server for a while.

A served explorer keeps what it solved for the next request: its process-wide cache of
results (:data:`~explorer.solving.result_cache.RESULTS`) and, in each solver worker, the
solver's stage caches; a worker also keeps what its work loaded (the printable report's
and the FE check's libraries) and heap its allocator does not give back. While pages are
open that makes slider steps, preset switches and reports cheap; once every page has
closed it only holds memory. Measured with ``benchmarks/load_test.py --heavy`` (20
sessions and three heavy pages; ``benchmarks/results/load_test.md``): after they had left,
the server's own process stood 101 MiB and its workers 106 MiB above their level before
(+35 % in all, run Z); emptying every cache (19.7 MiB in the server, 13.3 MiB in the
workers) left +25 % (run AA); emptying the server's and renewing the workers, +15 %, the
workers back at their level (run AB, read 120 s after the crowd).

:func:`session_opened` and :func:`session_closed` count the server's sessions. Once the
last has closed and none has opened for a while (``python -m explorer
--release-after-idle``, default 60 s), :func:`release` runs on a thread of its own (never
on the server's event loop): it empties the server's caches, has the server's full
collection run (on the event loop: every object frozen by ``explorer/fixes/gc_policy.py``
given back to the collector, see :func:`release`), hands its freed heap back to
the system (``malloc_trim``), replaces every solver worker with a new one forked from the
warm fork server (:meth:`~explorer.solving.workers.SolverProcesses.renew`, each once its
lane is idle), and solves the presets the server warmed up at its start again, so that
the next visitor finds the first page as quick as the first visitor did. A session opening
before the time cancels the release; one opening during a release stops it before its
next worker and its warm-up (the session finds the caches emptied, its first solves cold).

Enabled by :func:`enable` (``python -m explorer`` does); without it the sessions are only
counted. Nothing here imports Panel.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from typing import Any

from core import release_freed_memory
from core.cache import cache_report, clear_caches

from .controller import worker_processes

_lock = threading.Lock()
_open = 0
_timer: threading.Timer | None = None
# A timer's release runs only if it is still the newest (a session opening or closing
# since makes another; Timer.cancel() cannot stop a timer already running), and never
# beside another release.
_generation = 0
_releasing = False
_after_s: float | None = None
_rewarm: Callable[[], None] | None = None
_on_release: Callable[[dict[str, float]], None] | None = None
_collect: Callable[[], int] | None = None


def enable(after_s: float, rewarm: Callable[[], None] | None = None,
           on_release: Callable[[dict[str, float]], None] | None = None,
           collect: Callable[[], int] | None = None) -> None:
    """Release the caches ``after_s`` seconds after the last session has closed, then call
    ``rewarm`` (the server's warm-up of its presets) and ``on_release`` with what the
    release did (:func:`release`), each if given; ``collect``: the server's full
    collection (returns the objects collected; see :func:`release`)."""
    global _after_s, _rewarm, _on_release, _collect
    if not after_s > 0.0:
        raise ValueError(f"after_s: must be a number of seconds above 0, got {after_s!r}")
    with _lock:
        _after_s, _rewarm, _on_release, _collect = float(after_s), rewarm, on_release, collect


def disable() -> None:
    """Stop releasing: no release is due any more, and one running stops before its next
    worker and does not warm up (the server calls it before stopping its workers)."""
    global _after_s, _rewarm, _on_release, _collect
    with _lock:
        _after_s, _rewarm, _on_release, _collect = None, None, None, None
        _cancel()


def open_sessions() -> int:
    """How many sessions are open (opened and not yet closed)."""
    return _open


def session_opened() -> None:
    """A session has started: no release while it is open (one running stops before its
    next worker and does not warm up)."""
    global _open
    with _lock:
        _open += 1
        _cancel()


def session_closed(session_context: Any) -> None:
    """A session has ended (an ``on_session_destroyed`` callback): once none is open, a
    release is due the time given to :func:`enable` later (if enabled)."""
    global _open, _timer
    with _lock:
        _open = max(_open - 1, 0)
        if _open or _after_s is None:
            return
        _cancel()
        _timer = threading.Timer(_after_s, _release_if_idle, args=(_generation,))
        _timer.name = "release-after-idle"
        _timer.daemon = True
        _timer.start()


def _cancel() -> None:
    global _timer, _generation
    _generation += 1
    if _timer is not None:
        _timer.cancel()
        _timer = None


def _wanted() -> bool:
    """Whether a release may go on: enabled, and no session open."""
    return _after_s is not None and not _open


def _release_if_idle(generation: int) -> None:
    global _releasing
    with _lock:
        if generation != _generation or _releasing or not _wanted():
            return
        _releasing = True
        rewarm, on_release, collect = _rewarm, _on_release, _collect
    try:
        done = release(rewarm, go_on=_wanted, collect=collect)
        if on_release is not None:
            on_release(done)
    except Exception:  # noqa: BLE001 - the server goes on: a release is an economy
        logging.getLogger(__name__).exception("releasing the caches of an idle server failed")
    finally:
        with _lock:
            _releasing = False


def release(rewarm: Callable[[], None] | None = None,
            go_on: Callable[[], bool] = lambda: True,
            collect: Callable[[], int] | None = None) -> dict[str, float]:
    """Empty the server's caches, run ``collect`` (if given), give the freed memory back
    to the system, renew the solver workers, then call ``rewarm``; returns what it did:
    ``time`` (``time.monotonic``), ``bytes`` held by the server's caches before,
    ``collected`` objects, ``workers`` renewed, ``warmed`` (1 if ``rewarm`` ran),
    ``seconds`` (``rewarm`` included). ``go_on()`` is asked before ``collect``, each
    worker and ``rewarm``: once it is false (a session opened, the server stopping) the
    rest is left as it is.

    ``collect`` is the server's full collection with every frozen object given back to
    the collector first (``explorer.fixes.gc_policy.collect_ended_sessions``, run on the
    event loop): the objects alive at the last collection for ended sessions were frozen
    again by it, and those among them that die later in reference cycles stay frozen.
    Measured with only the heavy pages of ``benchmarks/load_test.py --heavy`` and a
    release 10 s after they closed: without it ~130 MiB more in use 40 s after they
    closed, nearly every object frozen; with it the release collected 212,323 objects,
    and the heap in use was back at its start +4 MiB."""
    start = time.monotonic()
    held = sum(stage["bytes"] for stage in cache_report().values())
    clear_caches()  # the server's results and the solver stages it ran itself
    collected = 0
    if collect is not None and go_on():
        try:
            collected = collect()
        except Exception:  # noqa: BLE001 - the rest of the release still gives memory back
            logging.getLogger(__name__).exception("the idle server's collection failed")
    release_freed_memory()
    processes = worker_processes()
    renewed = processes.renew(stop=lambda: not go_on()) if processes is not None else 0
    warmed = rewarm is not None and go_on()
    if warmed:
        rewarm()
        # the warm-up's passing allocations leave pages of the heap in use again
        release_freed_memory()
    return {"time": start, "bytes": float(held), "collected": float(collected),
            "workers": float(renewed),
            "warmed": float(warmed), "seconds": time.monotonic() - start}
