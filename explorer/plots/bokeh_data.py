"""Plot data sent to the page: float32 arrays, and only when the numbers changed."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

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


def broken_at(times: object, values: object, jumps: Sequence[float] = ()
              ) -> tuple[np.ndarray, np.ndarray]:
    """A history's ``times`` and ``values`` (float32, :func:`f32`) with a NaN point
    between the two output times either side of each of ``jumps`` [day] (a given load's
    jump: :func:`explorer.model.load_jumps`), where a line breaks: drawn straight across,
    the jump of the history read as a slope between the output times."""
    t, v = f32(times), f32(values)
    if not len(jumps) or t.size < 2:
        return t, v
    # (on the times as solved: a jump at an output time breaks the line before it)
    cut = np.unique(np.searchsorted(np.asarray(times, dtype=float),
                                    np.asarray(jumps, dtype=float)))
    cut = cut[(cut > 0) & (cut < t.size)]
    return np.insert(t, cut, np.nan), np.insert(v, cut, np.nan)


def _same(old: object, new: object) -> bool:
    if (isinstance(old, list | tuple) and isinstance(new, list | tuple)
            and any(isinstance(v, list | tuple | np.ndarray | str) for v in (*old, *new))):
        # a column of lines (a multi-line's) or of text: row by row
        return len(old) == len(new) and all(
            a == b if isinstance(a, str) or isinstance(b, str) else _same(a, b)
            for a, b in zip(old, new, strict=True))
    try:
        return bool(np.array_equal(np.asarray(old, dtype=float), np.asarray(new, dtype=float),
                                   equal_nan=True))
    except (TypeError, ValueError):  # anything else: assume changed
        return False


def set_data(source: ColumnDataSource, data: dict) -> bool:
    """Give ``source`` new ``data`` unless it holds the same numbers already; True if set.

    Bokeh sends every assignment to the page, which redraws the glyphs behind it. A load
    step leaves the drawing, the pinned curves and the given histories as they were:
    resending them cost the server and the browser work for nothing.
    """
    old = source.data
    if old.keys() == data.keys():
        changed = {k: v for k, v in data.items() if not _same(old[k], v)}
        if not changed:
            return False
        if len(changed) < len(data) and _one_length(old, changed):
            # Only the columns that changed go to the page (one message and one buffer
            # per column: the pressure plot's x and the histories' times stay as they
            # are on a slider step).
            source.data.update(changed)
            return True
    source.data = data
    return True


def _one_length(old: dict, changed: dict) -> bool:
    """Whether the ``changed`` columns are as long as the columns of ``old`` they leave
    as they are (a source's columns must keep one length)."""
    lengths = {len(v) for k, v in old.items() if k not in changed}
    lengths |= {len(v) for v in changed.values()}
    return len(lengths) <= 1


#: A value axis keeps its range while the data lie inside it and fill at least this
#: share of it: a load step of a few percent then changes the curve, not the axis (an
#: axis whose ticks change makes the page lay the figure out again, and an automatic
#: range refitted in the page was painted twice and sent back to the server).
KEEP_SHARE = 0.5
#: Room left on each side of the data when a range is set anew [share of the data span].
MARGIN_SHARE = 0.1
#: Data of (nearly) one value are drawn over at least this share of their size (a
#: constant force of 500 kN/m over 450-550), or over -1 to 1 when that value is zero.
FLAT_SHARE = 0.2


def data_bounds(*arrays: object) -> tuple[float, float] | None:
    """Smallest and largest finite value of ``arrays`` (None when there is none)."""
    parts = [np.asarray(a, dtype=float).ravel() for a in arrays]
    values = np.concatenate(parts) if parts else np.zeros(0)
    values = values[np.isfinite(values)]
    if not values.size:
        return None
    return float(values.min()), float(values.max())


def steady_range(rng: Any, *arrays: object) -> bool:
    """Fit the value range ``rng`` (a Bokeh ``Range1d``) to ``arrays`` unless it fits
    them already (see :data:`KEEP_SHARE`); True if it was set. The reset tool returns
    to the range set last."""
    bounds = data_bounds(*arrays)
    if bounds is None:
        return False
    lo, hi = bounds
    size = max(abs(lo), abs(hi))
    flat = FLAT_SHARE * size if size > 0 else 2.0
    if hi - lo < flat:
        mid = 0.5 * (lo + hi)
        lo, hi = mid - 0.5 * flat, mid + 0.5 * flat
    start, end = rng.start, rng.end
    if (start is not None and end is not None and end > start and start <= lo
            and hi <= end and hi - lo >= KEEP_SHARE * (end - start)):
        return False
    pad = MARGIN_SHARE * (hi - lo)
    start, end = lo - pad, hi + pad
    rng.update(start=start, end=end, reset_start=start, reset_end=end)
    return True


def legend_above(fig: Any, font_size: str | None = None) -> Any:
    """Move the legend of ``fig`` above its plot, in a compact horizontal row; returns it."""
    legend = fig.legend[0]
    legend.orientation = "horizontal"
    legend.margin = 0
    legend.padding = 2
    if font_size is not None:
        legend.label_text_font_size = font_size
    fig.add_layout(legend, "above")
    return legend


def legend_below(fig: Any, font_size: str = "10px") -> Any:
    """Move the legend of ``fig`` below its plot, a compact column; returns it."""
    legend = legend_inside(fig, "bottom_left", font_size)
    legend.margin = 0
    fig.add_layout(legend, "below")
    return legend


def legend_inside(fig: Any, location: str, font_size: str = "10px") -> Any:
    """Make the legend of ``fig`` a compact, half-transparent box at ``location`` inside
    its plot; returns it."""
    legend = fig.legend[0]
    legend.location = location
    legend.label_text_font_size = font_size
    legend.background_fill_alpha = 0.7
    legend.padding = 2
    legend.spacing = 0
    return legend


#: Entries of a legend above a plot laid out in one row up to this many, else in two
#: columns: at 1024 px the q(x) plot is ~320 px wide and four entries in one row
#: reached ~250 px past its left edge, over the sidebar.
ONE_ROW_ENTRIES = 2


def legend_rows(legend: Any) -> int:
    """The rows of a legend laid out by :func:`wrap_legend`."""
    shown = sum(1 for item in legend.items if item.visible)
    return 1 if shown <= ONE_ROW_ENTRIES else -(-shown // 2)


def wrap_legend(legend: Any) -> None:
    """One row of the entries shown when few, else two columns (see ONE_ROW_ENTRIES)."""
    columns = "auto" if legend_rows(legend) == 1 else 2
    if legend.ncols != columns:
        legend.ncols = columns
