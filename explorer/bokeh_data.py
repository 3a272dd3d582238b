"""Plot data sent to the page: float32 arrays, and only when the numbers changed."""

from __future__ import annotations

import numpy as np
from bokeh.models import ColumnDataSource

#: Bokeh's render level of what moves with the load or the time but not with the data
#: (the load's arrow and label, time cursors, the points at the time shown): the page
#: draws this level on a canvas layer of its own, so moving them repaints that layer
#: only, not the glyphs, axes and legends of the figure (measured: a load step
#: repainted the whole scene drawing, ~45 ms of the page's CPU, for the load's label).
MOVING = "overlay"


def f32(values: object) -> np.ndarray:
    """Plot data as float32: half the bytes to the page, and 7 significant digits, more
    than a screen resolves (the files keep the full numbers)."""
    return np.asarray(values, dtype=np.float32)


def _same(old: object, new: object) -> bool:
    try:
        return bool(np.array_equal(np.asarray(old, dtype=float), np.asarray(new, dtype=float),
                                   equal_nan=True))
    except (TypeError, ValueError):  # text columns, ragged lists: assume changed
        return False


def set_data(source: ColumnDataSource, data: dict) -> bool:
    """Give ``source`` new ``data`` unless it holds the same numbers already; True if set.

    Bokeh sends every assignment to the page, which redraws the glyphs behind it. A load
    step leaves the drawing, the pinned curves and the given histories as they were:
    resending them cost the server and the browser work for nothing.
    """
    old = source.data
    if old.keys() == data.keys() and all(_same(old[k], v) for k, v in data.items()):
        return False
    source.data = data
    return True
