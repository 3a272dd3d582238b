"""Short garbage-collector pauses in a server holding many pages, and nothing kept after.

A session's page is ~46,000 Python objects (Bokeh models, their properties, the widgets'
``param`` objects) that live as long as the session. A full collection of the oldest
generation walks every live object: with 20 sessions the server's event loop stopped for
0.5-1.0 s at each one, several times a minute, and every page waited (measured with a
``gc.callbacks`` timer during benchmarks/load_test.py).

Once a page is complete (all its tabs built), :func:`page_built` moves the objects that
exist then out of the collector's reach (``gc.freeze``). Objects made later are collected
as before, and reference counting frees non-cyclic garbage whatever its generation; only
cyclic garbage among the frozen objects waits.

When a session ends, :func:`session_ended` asks for one full collection
:data:`COLLECT_AFTER_S` later, and no sooner than :data:`COLLECT_AT_MOST_EVERY_S` after
the last (the sessions ending meanwhile share it); that collection gives everything back
to the collector (``gc.unfreeze``), frees the closed pages' cycles, hands the freed
memory back to the system (``malloc_trim``) and freezes the pages still open again. Until
it has run the pages frozen before stay frozen (the collector's own full collections,
set off by the pages built meanwhile, would otherwise walk them all), and no page is
frozen: a freeze then would also freeze the closed pages' garbage (with visitors who
leave abruptly and no collection after, rounds of 50 dropped sessions grew the server by
~350 MiB each, none of it returned). A page whose session has already ended when it
completes is not frozen either. A page can still be
held for a moment after its session's collection (a solve of the page coming back from
a worker): frozen with the live pages, it would wait for the next session to end. Where
one is, one more collection :data:`LATE_COLLECT_AFTER_S` after the first frees it
(measured with benchmarks/load_test.py --mode abandon: without it, two rounds of 25 in
eight left the server 60-85 MiB above its level until the next round ended); where none
is, none runs (a full collection walks every live page, 0.5-1 s with 20 pages open).
On a loaded server a page can be held longer than that (its last solve queued behind
others): :func:`watch_page` follows each page whose session has ended, and while one of
them is still alive after a collection, one more comes later, each wait twice the last
(from :data:`LATE_COLLECT_AFTER_S` up to :data:`LOOK_AT_MOST_EVERY_S`: a full collection walks
every live page, so a page held long costs a few pauses, not one every 10 s), for at
most :data:`HELD_AT_MOST_S` after its session ended (then a warning names how many are
still held: a page that outlives that is kept by something other than its work). The
sessions that end meanwhile get their own collection, and the late one after it where a
page is still held.

Panel (1.9) runs a full collection of its own 5 s after each page's document is
destroyed (``panel.io.document._garbage_collect``), one more per batch of ended
sessions beside this policy's and not bound by :data:`COLLECT_AT_MOST_EVERY_S` (while a
session's end unfroze every page, it walked them all: benchmarks/load_test.py --heavy
found the event loop in it in 14 py-spy dumps of the probe's long waits).
:func:`install` leaves those collections to this policy.

While a page is being built (:func:`pause_for_page`, from the start of the session's
page to the end of the request that asked for it) the collector does not run: building
a page makes ~100,000 objects, and the collections they set off walked the objects not
yet frozen again and again (in-process, 8 pages kept unfrozen: a full collection every
other page, 0.5-0.75 s each, on top of ~1.6 s of building). The young objects are
collected when the event loop takes its next turn, or :data:`PAUSE_AT_MOST_S` later at
the latest.

Used by served sessions only, on the server's event loop.
"""

from __future__ import annotations

import asyncio
import gc
import importlib
import logging
import math
import time
import weakref
from collections.abc import Callable
from typing import Any

from core import release_freed_memory

log = logging.getLogger(__name__)

#: Delay from the end of a session to the full collection that frees its page [s]. Bokeh
#: discards the sessions of closed pages in batches (every 17 s by default): one
#: collection serves a whole batch, and a class closing its tabs costs one pause.
COLLECT_AFTER_S = 2.0
#: The shortest time between two collections for ended sessions [s]. Each walks every
#: live page: 0.5-1.0 s on the event loop with 20 pages open, 1-3 s on a saturated
#: server, where pages reloaded every few seconds ended sessions in every one of Bokeh's
#: batches (benchmarks/load_test.py --heavy: such collections were the most frequent
#: place of the event loop in the liveness probe's long waits, 28-32 py-spy dumps a run).
#: Sessions ending sooner after the last wait for this, and their pages' memory (~3-6
#: MiB a page) is given back that much later.
COLLECT_AT_MOST_EVERY_S = 30.0
#: Delay from that collection to one more, for pages let go just after it [s]; the first
#: of the doubling waits while a page of an ended session is still held.
LATE_COLLECT_AFTER_S = 10.0
#: The longest wait between two looks for a page still held [s].
LOOK_AT_MOST_EVERY_S = 60.0
#: How long after its session ended a page still held is looked for [s]: a page's work
#: ends well within this even on a saturated server (a solve is bounded by
#: ``core.limits.MAX_SOLVE_CPU_SECONDS`` of CPU, a page's build takes 1-2 s of CPU; both
#: wait for the cores on a loaded machine).
HELD_AT_MOST_S = 300.0

#: Longest the collector stays paused for a page being built [s] (the build takes 1-2 s
#: of CPU; the pause normally ends with the request, much sooner).
PAUSE_AT_MOST_S = 10.0

_INSTALLED = False
_collect_due = False
#: When the last collection for ended sessions ran (``time.monotonic``).
_last_collection = -math.inf
_paused = False
#: The pending look (at most one) and the wait before the next.
_look: asyncio.TimerHandle | None = None
_look_after_s = LATE_COLLECT_AFTER_S
#: The pages of ended sessions not yet seen freed, with when their session ended
#: (``time.monotonic``).
_held: list[tuple[weakref.ref, float]] = []


def install() -> bool:
    """Leave the collections for ended sessions to this policy: Panel's own full
    collection after a page's document is destroyed does nothing (module notes). Once
    per process; returns False, with a warning, if Panel's has changed shape (it then
    runs as before)."""
    global _INSTALLED
    if _INSTALLED:
        return True
    document = importlib.import_module("panel.io.document")
    if not callable(getattr(document, "_garbage_collect", None)):
        log.warning("Panel's collection after a destroyed document has changed; it runs "
                    "beside the explorer's")
        return False
    document._garbage_collect = _left_to_policy
    _INSTALLED = True
    return True


def _left_to_policy() -> None:
    """Panel's collection after a destroyed document: :func:`session_ended` has asked
    for the one that frees the page."""


def page_built(session_context: Any = None) -> bool:
    """A page is complete: collect the young garbage of its building, then freeze.

    ``session_context``: the page's Bokeh session context; a page whose session has
    already ended is not frozen. Nothing is frozen while a collection for ended sessions
    is due (it freezes the live pages when it has run). Returns whether it froze.
    """
    if _collect_due or getattr(session_context, "destroyed", False):
        return False
    gc.collect(1)  # garbage made while building goes now, not into the frozen set
    gc.freeze()
    return True


def pause_for_page() -> bool:
    """Pause the collector while a page is built on the event loop: it runs again when
    the loop takes its next turn (after the request that builds the page), or after
    :data:`PAUSE_AT_MOST_S` at the latest. Outside an event loop (a script, a notebook)
    nothing is paused. Returns whether it paused."""
    global _paused
    try:
        loop = asyncio.get_running_loop()
    except RuntimeError:
        return False
    if not gc.isenabled() and not _paused:
        return False  # switched off by someone else: theirs to switch on
    _paused = True
    gc.disable()
    loop.call_soon(_resume)
    loop.call_later(PAUSE_AT_MOST_S, _resume)
    return True


def _resume() -> None:
    global _paused
    if _paused:
        _paused = False
        gc.enable()


def session_ended(session_context: Any) -> None:
    """A session has ended: ask for a full collection soon (Bokeh's session-destroyed
    callback; ``session_context`` unused)."""
    global _collect_due
    if _collect_due:
        return
    try:
        loop = asyncio.get_running_loop()
    except RuntimeError:  # not on an event loop (a script, a test): collect now
        collect_ended_sessions()
        return
    since = time.monotonic() - _last_collection
    loop.call_later(max(COLLECT_AFTER_S, COLLECT_AT_MOST_EVERY_S - since),
                    _collect_and_look_again)
    _collect_due = True


def watch_page(page: Any) -> Callable[[Any], None]:
    """The session-destroyed callback that follows ``page`` (weakly) once its session
    has ended, until a collection has freed it (module notes)."""
    ref = weakref.ref(page)

    def ended(session_context: Any) -> None:
        _held.append((ref, time.monotonic()))

    return ended


def held_pages() -> int:
    """How many pages of ended sessions are still alive (those seen freed are dropped)."""
    _held[:] = [(ref, since) for ref, since in _held if ref() is not None]
    return len(_held)


def _collect_and_look_again() -> None:
    """The collection for ended sessions, and, while a page of an ended session is
    still alive after it, one more :data:`LATE_COLLECT_AFTER_S` later (it replaces a
    longer wait pending for an older page: that page is looked for again then too)."""
    global _look, _look_after_s
    collect_ended_sessions()
    _look_after_s = LATE_COLLECT_AFTER_S
    if held_pages():
        _look_again()
    elif _look is not None:  # the pages it was for have gone
        _look.cancel()
        _look = None


def _look_again() -> None:
    """Schedule the next look (instead of the one pending, if any)."""
    global _look, _look_after_s
    try:
        loop = asyncio.get_running_loop()
    except RuntimeError:
        return
    if _look is not None:
        _look.cancel()
    _look = loop.call_later(_look_after_s, _late_collection)
    _look_after_s = min(2.0 * _look_after_s, LOOK_AT_MOST_EVERY_S)


def _late_collection() -> None:
    global _look
    _look = None
    if _collect_due:  # the collection due runs first and schedules the next look
        return
    if not held_pages():  # the pages it was for have gone (by reference counting)
        return
    collect_ended_sessions()
    if not held_pages():
        return
    now = time.monotonic()
    young = [(ref, since) for ref, since in _held if now - since < HELD_AT_MOST_S]
    if len(young) < len(_held):
        log.warning("%d page(s) of sessions that ended over %g s ago are still held",
                    len(_held) - len(young), HELD_AT_MOST_S)
        _held[:] = young
    if _held:
        _look_again()


def collect_ended_sessions() -> int:
    """Free the pages of ended sessions now: a full collection, the freed memory given
    back to the system, the live pages frozen again. Returns the objects collected."""
    global _collect_due, _last_collection
    _collect_due = False
    gc.unfreeze()
    found = gc.collect()
    _last_collection = time.monotonic()
    release_freed_memory()
    gc.freeze()
    log.debug("collected %d objects of ended sessions", found)
    return found
