"""Short garbage-collector pauses in a server holding many pages.

A session's page is ~46,000 Python objects (Bokeh models, their properties, the widgets'
``param`` objects) that live as long as the session. A full collection of the oldest
generation walks every live object: with 20 sessions the server's event loop stopped for
0.5-1.0 s at each one, several times a minute, and every page waited (measured with a
``gc.callbacks`` timer during benchmarks/load_test.py).

Once a page is complete (all its tabs built), :func:`page_built` moves the objects that
exist then out of the collector's reach (``gc.freeze``). Objects made later are collected
as before, and reference counting frees non-cyclic garbage whatever its generation; only
cyclic garbage among the frozen objects waits. When a session ends,
:func:`session_ended` gives everything back to the collector (``gc.unfreeze``), so the
closed page's cycles are freed by the next full collection. Used by served sessions only,
on the server's event loop.
"""

from __future__ import annotations

import gc
from typing import Any


def page_built() -> None:
    """A page is complete: collect the young garbage of its building, then freeze."""
    gc.collect(1)  # garbage made while building goes now, not into the frozen set
    gc.freeze()


def session_ended(session_context: Any) -> None:
    """A session has ended: let the collector see every object again (Bokeh's
    session-destroyed callback; ``session_context`` is not needed)."""
    gc.unfreeze()
