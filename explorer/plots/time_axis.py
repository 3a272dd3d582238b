"""A logarithmic time axis for the histories, switched in place on the same figures.

A creep history over years changes fastest in its first days: on a linear axis the
first tenth of the plot holds most of the change. The figures are kept (their data and
their shared range), only their scale, ticker and range change. On the log axis the range
is set from the positive times drawn (t = 0, the loading, has no place there): BokehJS
refits an automatic range only when data arrive, so a range under a scale just swapped
stayed on the linear numbers (a negative start). Nothing here imports Panel.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from bokeh.models import BasicTicker, LinearScale, LogScale, LogTicker, Range1d

#: Axis label of the histories' time axis, linear and logarithmic.
LABELS = {False: "t [days after loading]", True: "t [days after loading, log scale]"}
#: Margin of the log range beyond the first and last positive time, as a factor.
LOG_MARGIN = 1.25


def is_log(fig: Any) -> bool:
    """Whether ``fig`` draws its x axis on a log scale."""
    return isinstance(fig.x_scale, LogScale)


def times_drawn(figures: Sequence[Any]) -> np.ndarray:
    """The finite times [day] the visible renderers of ``figures`` draw: their ``t``
    column, and the ``xs`` lists of multi-lines (a line per punch of several)."""
    found = [np.empty(0)]
    for fig in figures:
        for renderer in fig.renderers:
            source = getattr(renderer, "data_source", None)
            if source is None or not renderer.visible:
                continue
            for column in (source.data.get("t", []), *source.data.get("xs", [])):
                found.append(np.asarray(column, dtype=float).ravel())
    t = np.concatenate(found)
    return t[np.isfinite(t)]


class LogTime:
    """Switches the time axis of figures that share one x range."""

    def __init__(self, figures: Sequence[Any]) -> None:
        self.figures = list(figures)
        self.linear_range = self.figures[0].x_range   # the shared automatic range
        self.log_range = Range1d(start=0.1, end=1.0)

    @property
    def on(self) -> bool:
        """Whether the axis is logarithmic now."""
        return is_log(self.figures[0])

    def set(self, log: bool) -> None:
        """Draw the time axis logarithmic (``log``) or linear."""
        if log == self.on:
            return
        if log:
            self.fit()
        for fig in self.figures:
            fig.x_scale = LogScale() if log else LinearScale()
            fig.x_range = self.log_range if log else self.linear_range
            for axis in fig.xaxis:
                axis.ticker = LogTicker() if log else BasicTicker()
                axis.axis_label = LABELS[log]

    def fit(self) -> None:
        """Fit the log range to the positive times drawn (call after new data)."""
        t = times_drawn(self.figures)
        t = t[t > 0]
        if not t.size:
            return  # nothing positive drawn: keep the range
        lo, hi = float(t.min()), float(t.max())
        if not hi > lo:
            lo = hi / 10.0
        self.log_range.update(start=lo / LOG_MARGIN, end=hi * LOG_MARGIN)
