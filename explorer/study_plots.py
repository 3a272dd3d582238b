"""The design chart of a study: a line over one parameter, a heat map over two.

A :class:`DesignChart` is built for a study's result (the axis types follow its spacing,
so a new study gets a new figure); switching the output or the time shown only replaces
the data of its sources (the figure, and the user's zoom, stay). Points the solver
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
)
from bokeh.palettes import Viridis256
from bokeh.plotting import figure

from .study import OUTPUTS, StudyResult

#: Most tick labels along a heat map's axis.
MAX_TICKS = 7
FLAG_COLOR = "#d62728"
_TOOLS = "pan,wheel_zoom,box_zoom,reset,save"


def fmt(value: float) -> str:
    """A tick or hover number: four significant digits."""
    return f"{value:.4g}"


def chart_title(result: StudyResult, output: str, time_index: int) -> str:
    """``settlement [mm] at t = 365 days``."""
    name, unit, _ = OUTPUTS[output]
    return f"{name} [{unit}] at t = {fmt(float(result.times[time_index]))} days"


def flag_note(result: StudyResult) -> str:
    """What the marks mean, with the counts."""
    failed, flagged = int(result.failed.sum()), int(result.flagged.sum())
    kinds = sorted({f for flags in result.flags.ravel() for f in flags.split(",")
                    if f and f != "failed"})
    note = f"{flagged} flagged (red x"
    note += f": {', '.join(kinds)})" if kinds else ")"
    return note + (f", {failed} failed (no value)" if failed else "")


def empty_figure() -> figure:
    """The chart before a study has run."""
    fig = figure(height=300, sizing_mode="stretch_width", tools=_TOOLS,
                 title="Run a study to see its design chart", name="study_chart")
    fig.toolbar.logo = None
    return fig


class DesignChart:
    """The figure of one study's result; :meth:`show` picks the output and the time."""

    def __init__(self, result: StudyResult, output: str = "settlement",
                 time_index: int = -1) -> None:
        self.result = result
        planned = result.planned
        self.two = len(planned.values) == 2
        self.source = ColumnDataSource(name="study_source")
        self.flagged = ColumnDataSource(name="study_flagged")
        first = planned.choices[0]
        log_x = planned.is_log(0)
        if not self.two:
            fig = figure(height=300, sizing_mode="stretch_width", tools=_TOOLS,
                         x_axis_type="log" if log_x else "linear", name="study_chart",
                         x_axis_label=first.title)
            fig.line("x", "y", source=self.source, line_width=2)
            fig.scatter("x", "y", source=self.source, size=6)
            fig.scatter("x", "y", source=self.flagged, marker="x", size=12, line_width=2,
                        color=FLAG_COLOR, legend_label="flagged")
            fig.legend.location = "top_left"
            fig.legend.background_fill_alpha = 0.6
            fig.add_tools(HoverTool(tooltips=[(first.label, "@x{0.0000}"), ("value", "@y"),
                                              ("flags", "@flags")]))
        else:
            second = planned.choices[1]
            n1, n2 = planned.shape
            fig = figure(height=330, sizing_mode="stretch_width", tools=_TOOLS,
                         x_range=(-0.5, n1 - 0.5), y_range=(-0.5, n2 - 0.5),
                         name="study_chart", x_axis_label=first.title,
                         y_axis_label=second.title)
            self.mapper = LinearColorMapper(palette=Viridis256, nan_color="#cccccc")
            fig.rect("i", "j", width=1, height=1, source=self.source,
                     fill_color={"field": "value", "transform": self.mapper},
                     line_color=None)
            fig.scatter("i", "j", source=self.flagged, marker="x", size=9, line_width=2,
                        color=FLAG_COLOR)
            for axis, values in ((fig.xaxis, planned.values[0]), (fig.yaxis, planned.values[1])):
                ticks = tick_indices(len(values))
                axis.ticker = FixedTicker(ticks=ticks)
                axis.major_label_overrides = {int(k): fmt(float(values[k])) for k in ticks}
            self.color_bar = ColorBar(color_mapper=self.mapper, ticker=BasicTicker(),
                                      width=10, title="")
            fig.add_layout(self.color_bar, "right")
            fig.add_tools(HoverTool(tooltips=[(first.label, "@x"), (second.label, "@y"),
                                              ("value", "@value"), ("flags", "@flags")]))
        fig.toolbar.logo = None
        self.figure = fig
        self.show(output, time_index)

    def show(self, output: str, time_index: int) -> None:
        """Draw ``output`` at output time ``time_index`` (in place)."""
        result = self.result
        planned = result.planned
        z = result.shown(output, time_index)
        flags = result.flags
        mark = result.flagged
        name, unit, _ = OUTPUTS[output]
        self.figure.title.text = chart_title(result, output, time_index)
        if not self.two:
            x = planned.values[0]
            self.source.data = {"x": x, "y": z, "flags": list(flags)}
            self.flagged.data = {"x": x[mark], "y": z[mark]}
            self.figure.yaxis.axis_label = f"{name} [{unit}]"
            return
        n1, n2 = planned.shape
        i, j = np.meshgrid(np.arange(n1), np.arange(n2), indexing="ij")
        x, y = np.meshgrid(*planned.values, indexing="ij")
        self.source.data = {"i": i.ravel(), "j": j.ravel(), "x": x.ravel(), "y": y.ravel(),
                            "value": z.ravel(), "flags": list(flags.ravel())}
        self.flagged.data = {"i": i[mark], "j": j[mark]}
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
