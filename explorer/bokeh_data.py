"""Plot data sent to the page: float32 arrays, and only when the numbers changed."""

from __future__ import annotations

import numpy as np
from bokeh.models import ColumnDataSource


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
