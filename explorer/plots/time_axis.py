"""A logarithmic time axis for the histories, switched in place on the same figures.

A creep history over years changes fastest in its first days: on a linear axis the
first tenth of the plot holds most of the change. The figures are kept (their data and
their shared range), only their scale, ticker and range change. On the log axis the range
is set from the positive times drawn (t = 0, the loading, has no place there): BokehJS
refits an automatic range only when data arrive, so a range under a scale just swapped
stayed on the linear numbers (a negative start). The values at t = 0 (the settlement "at
once" a lesson speaks of) are drawn as open markers at the left edge of the log range,
their tooltip saying so. Nothing here imports Panel.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from bokeh.models import (
    BasicTicker,
    ColumnDataSource,
    HoverTool,
    LinearScale,
    LogScale,
    LogTicker,
    Range1d,
)
from bokeh.models.glyphs import Line, MultiLine

#: Axis label of the histories' time axis, linear and logarithmic.
LABELS = {False: "t [days after loading]", True: "t [days after loading, log scale]"}
#: Margin of the log range beyond the first and last positive time, as a factor.
LOG_MARGIN = 1.25
#: The markers of the values at t = 0 on the log axis sit this factor right of the range's
#: start (inside the plot, left of the first positive time: ``LOG_MARGIN`` beyond it).
LOADING_EDGE = 1.08


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


def _field(spec: Any, default: str) -> str:
    """The column a glyph's coordinate reads (``default`` where it is not a column: the
    contact width plot's lines read "width" and "lifted", the histories' "v")."""
    return spec if isinstance(spec, str) else getattr(spec, "field", None) or default


class LogTime:
    """Switches the time axis of figures that share one x range."""

    def __init__(self, figures: Sequence[Any]) -> None:
        self.figures = list(figures)
        self.linear_range = self.figures[0].x_range   # the shared automatic range
        self.log_range = Range1d(start=0.1, end=1.0)
        # the values at t = 0, which the log axis cannot place: open markers at its left
        # edge (columns "x" and "y": times_drawn reads "t" and "xs", and must not read
        # the edge as a time drawn, or each fit would move it further left)
        self.at_loading: list[ColumnDataSource] = []
        for fig in self.figures:
            source = ColumnDataSource({"x": [], "y": [], "color": []},
                                      name=f"{fig.name}_at_loading")
            marks = fig.scatter(x="x", y="y", color="color", source=source, size=9,
                                marker="circle", fill_color="white", line_width=2,
                                name=f"{fig.name}_at_loading")
            label = fig.yaxis[0].axis_label or "value"
            fig.add_tools(HoverTool(renderers=[marks], tooltips=[
                ("t", "0, at loading (drawn at the edge: a log axis has no 0)"),
                (label, "@y{0.0000}")]))
            self.at_loading.append(source)

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
        else:
            self._show_at_loading(False)
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
        self._show_at_loading(True)

    def _show_at_loading(self, shown: bool) -> None:
        """The values at t = 0 of the visible lines, at the log range's left edge
        (``shown``), or none (the linear axis draws them on the lines)."""
        edge = float(self.log_range.start) * LOADING_EDGE
        for fig, source in zip(self.figures, self.at_loading, strict=True):
            ys, colors = [], []
            # (read now: pins' and a fit's lines are made when first drawn)
            for renderer in fig.renderers if shown else ():
                if not (renderer.visible
                        and isinstance(getattr(renderer, "glyph", None), Line | MultiLine)):
                    continue
                data, glyph = renderer.data_source.data, renderer.glyph
                rows = (zip(data.get("xs", []), data.get("ys", []),
                            data.get("color", [None] * len(data.get("xs", []))),
                            strict=False)
                        if isinstance(glyph, MultiLine)
                        else [(data.get(_field(glyph.x, "t"), []),
                               data.get(_field(glyph.y, "v"), []), None)])
                for t, v, color in rows:
                    if len(t) and len(v) and float(t[0]) == 0.0 and np.isfinite(float(v[0])):
                        ys.append(float(v[0]))
                        colors.append(color if isinstance(color, str)
                                      else glyph.line_color)
            new = {"x": [edge] * len(ys), "y": ys, "color": colors}
            if dict(source.data) != new:
                source.data = new
