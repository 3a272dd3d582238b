"""The design chart of a study: a line over one parameter, a heat map over two.

A session's :class:`DesignChart` holds three figures built once (a line over a linear or a
log axis, a heat map); a new result, the output or the time shown only replace the data
of their sources and a few properties. Points the solver
flagged are marked with a red cross; failed points have no value (a gap in the line, a
grey cell). Nothing here imports Panel.
"""

from __future__ import annotations

import numpy as np
from bokeh.models import (
    BasicTicker,
    ColorBar,
    ColumnDataSource,
    FixedTicker,
    HoverTool,
    LinearColorMapper,
    Range1d,
)
from bokeh.palettes import Viridis256
from bokeh.plotting import figure

from core.scene import days_text

from ..model import StudyResult
from .bokeh_data import legend_above

#: Most tick labels along a heat map's axis.
MAX_TICKS = 7
FLAG_COLOR = "#d62728"
_TOOLS = "pan,wheel_zoom,box_zoom,reset,save"


def fmt(value: float) -> str:
    """A tick or hover number: four significant digits."""
    return f"{value:.4g}"


def chart_title(result: StudyResult, output: str, time_index: int) -> str:
    """``settlement [mm] at t = 365 days``."""
    name, unit, _ = result.planned.outputs[output]
    return f"{name} [{unit}] at t = {days_text(float(result.times[time_index]))}"


def flag_note(result: StudyResult) -> str:
    """What the marks mean, with the counts."""
    failed, flagged = int(result.failed.sum()), int(result.flagged.sum())
    kinds = sorted({f for flags in result.flags.ravel() for f in flags.split(",")
                    if f and f != "failed"})
    note = f"{flagged} flagged (red x"
    note += f": {', '.join(kinds)})" if kinds else ")"
    return note + (f", {failed} failed (no value)" if failed else "")


class DesignChart:
    """The study charts of one session, built once: a line over a linear axis, one over a
    log axis (both drawing the source named ``study_source``) and a heat map (the source
    ``study_map_source``). :meth:`draw` shows a new result on the one that fits; switching
    the output or the time replaces data in place (the figures, and the zoom, stay)."""

    def __init__(self) -> None:
        self.result: StudyResult | None = None
        self.source = ColumnDataSource({"x": [], "y": [], "flags": []}, name="study_source")
        self.flagged = ColumnDataSource({"x": [], "y": []}, name="study_flagged")
        self.map_source = ColumnDataSource({"i": [], "j": [], "x": [], "y": [], "value": [],
                                            "flags": []}, name="study_map_source")
        self.map_flagged = ColumnDataSource({"i": [], "j": []}, name="study_map_flagged")
        self.lines = {kind: self._line_figure(kind) for kind in ("linear", "log")}
        self.map = self._map_figure()
        self.shown = self.lines["linear"]

    def _line_figure(self, kind: str) -> figure:
        fig = figure(height=300, sizing_mode="stretch_width", tools=_TOOLS, x_axis_type=kind,
                     name=f"study_line_{kind}")
        fig.line("x", "y", source=self.source, line_width=2)
        fig.scatter("x", "y", source=self.source, size=6)
        fig.scatter("x", "y", source=self.flagged, marker="x", size=12, line_width=2,
                    color=FLAG_COLOR, legend_label="flagged")
        # above the plot: at its top left the legend covered the first points (a study of
        # the eccentricity from 0)
        legend_above(fig, "11px")
        fig.add_tools(HoverTool(tooltips=[("x", "@x"), ("value", "@y"), ("flags", "@flags")]))
        fig.toolbar.logo = None
        return fig

    def _map_figure(self) -> figure:
        fig = figure(height=330, sizing_mode="stretch_width", tools=_TOOLS,
                     x_range=Range1d(-0.5, 0.5), y_range=Range1d(-0.5, 0.5),
                     name="study_map")
        self.mapper = LinearColorMapper(palette=Viridis256, nan_color="#cccccc")
        fig.rect("i", "j", width=1, height=1, source=self.map_source,
                 fill_color={"field": "value", "transform": self.mapper}, line_color=None)
        fig.scatter("i", "j", source=self.map_flagged, marker="x", size=9, line_width=2,
                    color=FLAG_COLOR)
        self.color_bar = ColorBar(color_mapper=self.mapper, ticker=BasicTicker(), width=10,
                                  title="")
        fig.add_layout(self.color_bar, "right")
        self.map_hover = HoverTool(tooltips=[("x", "@x"), ("y", "@y"), ("value", "@value"),
                                             ("flags", "@flags")])
        fig.add_tools(self.map_hover)
        fig.toolbar.logo = None
        return fig

    @property
    def figures(self) -> list[figure]:
        """Every figure (one of them shown at a time)."""
        return [self.lines["linear"], self.lines["log"], self.map]

    def draw(self, result: StudyResult, output: str, time_index: int) -> figure:
        """Show a new result; returns the figure to show."""
        self.result = result
        planned = result.planned
        first = planned.choices[0]
        if len(planned.values) == 1:
            fig = self.lines["log" if planned.is_log(0) else "linear"]
            fig.xaxis.axis_label = first.title
            fig.select_one(HoverTool).tooltips = [(first.label, "@x"), ("value", "@y"),
                                                  ("flags", "@flags")]
        else:
            fig = self.map
            second = planned.choices[1]
            n1, n2 = planned.shape
            fig.x_range.update(start=-0.5, end=n1 - 0.5)
            fig.y_range.update(start=-0.5, end=n2 - 0.5)
            fig.xaxis.axis_label, fig.yaxis.axis_label = first.title, second.title
            for axis, values in ((fig.xaxis, planned.values[0]),
                                 (fig.yaxis, planned.values[1])):
                ticks = tick_indices(len(values))
                axis.ticker = FixedTicker(ticks=ticks)
                axis.major_label_overrides = {int(k): fmt(float(values[k])) for k in ticks}
            self.map_hover.tooltips = [(first.label, "@x"), (second.label, "@y"),
                                       ("value", "@value"), ("flags", "@flags")]
        self.shown = fig
        self.show(output, time_index)
        return fig

    def show(self, output: str, time_index: int) -> None:
        """Draw ``output`` at output time ``time_index`` of the result (in place)."""
        result = self.result
        if result is None:
            return
        planned = result.planned
        z = result.shown(output, time_index)
        flags = result.flags
        mark = result.flagged
        name, unit, _ = result.planned.outputs[output]
        self.shown.title.text = chart_title(result, output, time_index)
        if len(planned.values) == 1:
            x = planned.values[0]
            self.source.data = {"x": x, "y": z, "flags": list(flags)}
            self.flagged.data = {"x": x[mark], "y": z[mark]}
            # the legend names the red crosses only when there are some
            self.shown.legend.visible = bool(np.any(mark))
            self.shown.yaxis.axis_label = f"{name} [{unit}]"
            return
        n1, n2 = planned.shape
        i, j = np.meshgrid(np.arange(n1), np.arange(n2), indexing="ij")
        x, y = np.meshgrid(*planned.values, indexing="ij")
        self.map_source.data = {"i": i.ravel(), "j": j.ravel(), "x": x.ravel(),
                                "y": y.ravel(), "value": z.ravel(),
                                "flags": list(flags.ravel())}
        self.map_flagged.data = {"i": i[mark], "j": j[mark]}
        finite = z[np.isfinite(z)]
        low, high = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
        if high <= low:  # one value everywhere: a band around it
            low, high = low - 0.5 * (abs(low) or 1.0), high + 0.5 * (abs(high) or 1.0)
        self.mapper.update(low=low, high=high)
        self.color_bar.title = f"{name} [{unit}]"


def tick_indices(n: int) -> list[int]:
    """At most :data:`MAX_TICKS` evenly spread indices of ``n`` cells, both ends included."""
    if n <= MAX_TICKS:
        return list(range(n))
    return sorted({int(round(k)) for k in np.linspace(0, n - 1, MAX_TICKS)})
