"""Giving memory back once nobody has used the server for a while.

A served explorer keeps what it solved for the next request: its process-wide cache of
results (:data:`~explorer.solving.result_cache.RESULTS`) and, in each solver worker, the
solver's stage caches; a worker also keeps what its work loaded (the printable report's
and the FE check's libraries) and heap its allocator does not give back. While pages are
open that makes slider steps, preset switches and reports cheap; once every page has
closed it only holds memory. Measured with ``benchmarks/load_test.py --heavy`` (20
sessions and three heavy pages; ``benchmarks/results/load_test.md``): 75 s after they
had left, the server's own process stood 101 MiB and its workers 106 MiB above their
level before (+35 % in all, run Z); emptying the caches alone (19.7 MiB in the server,
13.3 MiB in the workers) left +25 % (run AA).

:func:`session_opened` and :func:`session_closed` count the server's sessions. Once the
last has closed and none has opened for a while (``python -m explorer
--release-after-idle``, default 60 s), :func:`release` runs on a thread of its own (never
on the server's event loop): it empties the server's caches, hands its freed heap back to
the system (``malloc_trim``), replaces every solver worker with a new one forked from the
warm fork server (:meth:`~explorer.solving.workers.SolverProcesses.renew`), and solves the
presets the server warmed up at its start again, so that the next visitor finds the first
page as quick as the first visitor did. A session opening meanwhile cancels a release not
yet started; one opening during a release finds colder caches, nothing else.

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
_after_s: float | None = None
_rewarm: Callable[[], None] | None = None
_on_release: Callable[[dict[str, float]], None] | None = None
#: What each release did, newest last (bounded): ``time`` (``time.monotonic``), ``bytes``
#: held by the server's caches before, ``workers`` renewed, ``seconds`` it took (the
#: warm-up after it included).
RELEASES: list[dict[str, float]] = []
_KEEP = 20


def enable(after_s: float, rewarm: Callable[[], None] | None = None,
           on_release: Callable[[dict[str, float]], None] | None = None) -> None:
    """Release the caches ``after_s`` seconds after the last session has closed, then call
    ``rewarm`` (the server's warm-up of its presets) and ``on_release`` with what the
    release did (:func:`release`), each if given."""
    global _after_s, _rewarm, _on_release
    if not after_s > 0.0:
        raise ValueError(f"after_s: must be a number of seconds above 0, got {after_s!r}")
    with _lock:
        _after_s, _rewarm, _on_release = float(after_s), rewarm, on_release


def disable() -> None:
    """Stop releasing (a release already running finishes)."""
    global _after_s, _rewarm, _on_release
    with _lock:
        _after_s, _rewarm, _on_release = None, None, None
        _cancel()


def open_sessions() -> int:
    """How many sessions are open (opened and not yet closed)."""
    return _open


def session_opened() -> None:
    """A session has started: no release while it is open."""
    global _open
    with _lock:
        _open += 1
        _cancel()


def session_closed(_session_context: Any = None) -> None:
    """A session has ended (an ``on_session_destroyed`` callback): once none is open, a
    release is due the time given to :func:`enable` later (if enabled)."""
    global _open, _timer
    with _lock:
        _open = max(_open - 1, 0)
        if _open or _after_s is None:
            return
        _cancel()
        _timer = threading.Timer(_after_s, _release_if_idle)
        _timer.name = "release-after-idle"
        _timer.daemon = True
        _timer.start()


def _cancel() -> None:
    global _timer
    if _timer is not None:
        _timer.cancel()
        _timer = None


def _release_if_idle() -> None:
    with _lock:
        if _open or _after_s is None:
            return
        rewarm, on_release = _rewarm, _on_release
    try:
        done = release(rewarm)
        if on_release is not None:
            on_release(done)
    except Exception:  # noqa: BLE001 - the server goes on: a release is an economy
        logging.getLogger(__name__).exception("releasing the caches of an idle server failed")


def release(rewarm: Callable[[], None] | None = None) -> dict[str, float]:
    """Empty the server's caches, give the freed memory back to the system, renew every
    solver worker, then call ``rewarm``; returns what it did (also kept in
    :data:`RELEASES`)."""
    start = time.monotonic()
    held = sum(stage["bytes"] for stage in cache_report().values())
    clear_caches()  # the server's results and the solver stages it ran itself
    processes = worker_processes()
    renewed = processes.renew() if processes is not None else 0
    # (no collection here: the server's are explorer/fixes/gc_policy.py's, and the caches'
    # values are freed by their reference counts)
    release_freed_memory()
    if rewarm is not None:
        rewarm()
    done = {"time": start, "bytes": float(held), "workers": float(renewed),
            "seconds": time.monotonic() - start}
    with _lock:
        RELEASES.append(done)
        del RELEASES[:-_KEEP]
    return done
