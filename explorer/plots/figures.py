"""Bokeh figures of the explorer, built once and updated in place.

Every figure is created once per session; a new result or a new time only replaces the
``data`` of ``ColumnDataSource`` objects and a few properties (titles, axis labels,
span locations). Rebuilding figures would cost a full re-render in the browser and lose
the user's zoom. Nothing here imports Panel.
"""

from __future__ import annotations

import json
from collections.abc import Sequence

import numpy as np
from bokeh.core.properties import value as fixed_label
from bokeh.models import (
    ColorBar,
    ColumnDataSource,
    HoverTool,
    Legend,
    LegendItem,
    LinearColorMapper,
    LogColorMapper,
    Range1d,
    Span,
    Whisker,
)
from bokeh.palettes import Viridis256
from bokeh.plotting import figure

from core.scene import days_text

from ..model import (
    MODIFIED,
    QUANTITIES,
    QUANTITY_UNITS,
    SCREEN_PUNCHES,
    STEP_END,
    DisplayScales,
    Pin,
    ResultView,
    lifts_or_pulls,
)
from .bokeh_data import (
    MOVING,
    broken_at,
    f32,
    legend_above,
    legend_rows,
    set_data,
    steady_range,
    wrap_legend,
)
from .classical import bearing_rule_pressure, half_space_pressure
from .contact import ContactDrawing, FeatureInset
from .pins import PinLines
from .scene import PUNCH_COLORS, TOOLS, SceneDrawing, empty_columns
from .time_axis import times_drawn

SYMBOLS = {"settlement": "δ", "tilt": "α", "force": "P", "moment": "M"}
TITLES = {"settlement": "Settlement", "tilt": "Tilt", "force": "Force", "moment": "Moment"}
UNKNOWN_COLOR = "#1f77b4"
#: What the shaded strips of q(x) are: negative pressure of the full-contact model, or
#: the parts a unilateral solve lifted off (q = 0 there).
LOST_LABEL = "q < 0 (contact lost)"
LIFTED_LABEL = "lifted off (q = 0)"
#: The marks at a rigid corner in contact on an exact layered coating or a bare base,
#: where q rises without bound and the answer holds it from ``held_within_m`` on (the
#: flat end of the line read as a bounded maximum: an audit).
CORNER_LABEL = "q → ∞ at the corner (held within {within})"
GIVEN_COLOR = "#8c8c8c"
#: The readings of a back-analysis (Fit tab) and the fitted scene's forecast band.
READINGS_COLOR = "#111111"
#: The fitted scene's forecast: a colour no pin or punch takes (it was a pin's orange, and
#: dashed like a pin, so a fitted curve read as pin 2)
FORECAST_COLOR = "#17becf"
#: The histories the readings of a back-analysis are drawn on.
READ_SERIES = ("settlement", "tilt")

#: Font size of the entries of the legends above the plots (normal mode).
LEGEND_FONT = "11px"

#: Height of the pressure plot and of the q(x, t) map beside it [px], in presentation mode
#: (True) and not, with a legend of one row.
Q_HEIGHT = {True: 240, False: 280}
#: Height of each further row of the q(x) legend above its plot [px] (11 px labels with
#: their padding): the plot grows by it, so its frame keeps its height (five pins, three
#: rows of entries, left a frame of ~70 px of a 240 px plot in presentation mode).
LEGEND_ROW = 22

#: Font size of ticks, axis labels and titles in presentation mode (a projector).
PRESENTATION_FONT = "18px"
#: The colour bars' ticks and titles in presentation mode.
PRESENTATION_BAR_FONT = "14px"
#: Ticks an axis aims at in presentation mode (Bokeh's default is 6).
PRESENTATION_TICKS = 4
#: ... on the y axis of a short plot (the histories, the contact width): three ticks of
#: 18 px fit its ~80 px of axis.
PRESENTATION_SHORT_TICKS = 3
#: The tallest a plot is in normal mode and still short [px] (presentation mode makes it
#: shorter still).
SHORT_FIGURE = 210

#: Longest scene name shown in the drawing's title [characters]: a Bokeh title does not
#: wrap, and at 1024 px a longer one was cut off.
TITLE_CHARS = 40


#: Room beside the loaded stretch on the pressure plot's x axis, a share of its width on
#: each side (as Bokeh's automatic ranges pad: the punch's edges clear of the frame).
X_PADDING = 0.05


def short(text: str, limit: int = TITLE_CHARS) -> str:
    """``text`` cut to ``limit`` characters with an ellipsis; a changed scene's
    " (modified)" and a lesson step's ", step 2 of 4" are kept (the cut took them:
    "Eccentric footing: from full contact to…", "Force, eccentricity and tilt, step 4
    of…")."""
    text = " ".join(str(text).split())
    if len(text) <= limit:
        return text
    step = STEP_END.search(text)
    end = MODIFIED if text.endswith(MODIFIED) else step.group() if step else ""
    if end and limit > 2 * len(end):
        return short(text[: -len(end)], limit - len(end)) + end
    head = text[: limit - 1]
    if text[limit - 1] != " " and " " in head:
        head = head[: head.rfind(" ")]  # at a word's end ("tilt" read "ti…")
    return head.rstrip(" ,;:") + "…"


#: Longest line of the drawing's title in presentation mode [characters] (its 18 px
#: font beside the inset of small features at 1024 px cut "..., step 2 of 3 (modifi"
#: after 43).
PRESENTING_TITLE_CHARS = 36


def scene_title(name: str, presenting: bool = False) -> str:
    """The drawing's title of a scene named ``name``: one line, or two of at most
    :data:`TITLE_CHARS` characters of the name (:data:`PRESENTING_TITLE_CHARS` of the
    title in presentation mode) each: a lesson step's "step 2 of 3" and a changed scene's
    "(modified)" on the second, else the name split at the word that balances the lines
    best, its end cut by :func:`short`."""
    text = f"Scene: {' '.join(str(name).split())}"
    limit = PRESENTING_TITLE_CHARS if presenting else len("Scene: ") + TITLE_CHARS
    if len(text) <= limit:
        return text
    base = text.removesuffix(MODIFIED)
    step = STEP_END.search(base)
    if step:
        tail = base[step.start():] + text[len(base):]
        return f"{short(text[:len(text) - len(tail)], limit)}\n{tail.lstrip(', ')}"
    spaces = [k for k, c in enumerate(base[:limit + 1]) if c == " " and k > len("Scene:")]
    if not spaces:
        return text[:limit - 1] + "…"  # no word ends on the first line
    # the split nearest the middle whose second line fits whole, else the last one
    fitting = [k for k in spaces if len(text) - k - 1 <= limit]
    cut = min(fitting, key=lambda k: abs(2 * k - len(text))) if fitting else spaces[-1]
    # the second line keeps a changed scene's " (modified)"
    return f"{text[:cut]}\n{short(text[cut + 1:], limit)}"


class Figures:
    """All figures of one session and the sources behind them."""

    def __init__(self, scales: DisplayScales | None = None) -> None:
        self.scales = scales or DisplayScales()
        self.modulus_mapper = LogColorMapper(palette=Viridis256, low=1.0, high=1e5)
        self.drawing = SceneDrawing(self.modulus_mapper)
        self.scene_fig = self.drawing.fig
        # the drawing's sources, by the names they had here
        self.base_src, self.layer_src = self.drawing.base_src, self.drawing.layer_src
        self.punch_src = self.drawing.punch_src
        self._build_pressure()
        self._build_image()
        self._build_histories()
        # the contact zone under the punch, the width history (its time axis shared with
        # the other histories) and the inset of small features
        self.contact = ContactDrawing(self.scene_fig, self.history_fig["settlement"].x_range)
        self.contact_fig = self.contact.width_fig
        self.inset = FeatureInset()
        self.inset_fig = self.inset.fig
        self.pins = PinLines(self.q_fig, self.history_fig, self.scales)

    # -- construction ----------------------------------------------------------------
    def _build_pressure(self) -> None:
        # the value axes are set here, not fitted in the page (see steady_range)
        p = figure(height=Q_HEIGHT[False], sizing_mode="stretch_width", tools=TOOLS,
                   title="Contact pressure q(x)", toolbar_location="above",
                   name="pressure_figure", x_range=Range1d(-1, 1), y_range=Range1d(0, 1))
        p.toolbar.autohide = True
        p.xaxis.axis_label = "x [m]"
        p.yaxis.axis_label = "q [kPa]"
        # one point until the first result, so the auto ranges have something to fit
        self.q_src = ColumnDataSource({"x": [0.0], "q": [0.0]}, name="q_source")
        self.neg_src = ColumnDataSource(empty_columns("left", "right"), name="negative_source")
        self.neg_strip = p.vstrip(x0="left", x1="right", source=self.neg_src,
                                  fill_color="#d62728", fill_alpha=0.18, line_color=None,
                                  legend_label=LOST_LABEL)
        p.add_layout(Span(location=0, dimension="width", line_color="#555", line_width=1))
        self.classic_src = ColumnDataSource(empty_columns("x", "half_space", "bearing_rule"),
                                            name="classical_source")
        self.classic_lines = [
            p.line(x="x", y="half_space", source=self.classic_src, line_color="#7f7f7f",
                   line_dash="dotdash", line_width=1.5, visible=False,
                   legend_label="elastic half-space"),
            p.line(x="x", y="bearing_rule", source=self.classic_src, line_color="#2ca02c",
                   line_dash="dotted", line_width=2, visible=False,
                   legend_label="Winkler / trapezoid")]
        line = p.line(x="x", y="q", source=self.q_src, line_color=UNKNOWN_COLOR, line_width=2.5,
                      legend_label="current")
        self.corner_src = ColumnDataSource(empty_columns("x", "q"), name="corner_source")
        self.corner_marks = p.scatter(x="x", y="q", source=self.corner_src, marker="triangle",
                                      size=10, fill_color="#333333", line_color=None,
                                      legend_label=CORNER_LABEL.format(within="a few mm"))
        self.q_hover = HoverTool(renderers=[line], tooltips=[("x", "@x{0.000} m"),
                                                             ("q", "@q{0.000} kPa")],
                                 mode="vline", name="q_hover")
        p.add_tools(self.q_hover)
        # small entries, and only those of lines shown, in two columns when more than two
        # (see wrap_legend): at 1024 px the plot is ~320 px wide
        legend = legend_above(p, LEGEND_FONT)
        legend.click_policy = "hide"
        for item in legend.items:
            if any(r in (*self.classic_lines, self.corner_marks) for r in item.renderers):
                item.visible = False
        self.q_fig = p

    def _build_image(self) -> None:
        p = figure(height=Q_HEIGHT[False], sizing_mode="stretch_width", tools=TOOLS,
                   title="q(x, t)", toolbar_location="above", name="image_figure",
                   x_range=Range1d(-1, 1), y_range=Range1d(0, 1))
        p.toolbar.autohide = True
        p.xaxis.axis_label = "x [m]"
        p.yaxis.axis_label = "t [days after loading]"
        self.image_mapper = LinearColorMapper(palette=Viridis256, low=0, high=1,
                                              name="image_mapper")
        self.image_src = ColumnDataSource(empty_columns("image", "x", "y", "dw", "dh"),
                                          name="image_source")
        image = p.image(image="image", x="x", y="y", dw="dw", dh="dh", source=self.image_src,
                        color_mapper=self.image_mapper)
        self.image_hover = HoverTool(renderers=[image], name="image_hover", tooltips=[
            ("x", "$x{0.000} m"), ("t", "$y{0.0} days"), ("q", "@image{0.000} kPa")])
        p.add_tools(self.image_hover)
        self.image_bar = ColorBar(color_mapper=self.image_mapper, title="q [kPa]", width=8)
        p.add_layout(self.image_bar, "right")
        self.image_cursor = Span(location=0, dimension="width", line_color="white",
                                 line_width=2, line_dash="dashed", level=MOVING)
        p.add_layout(self.image_cursor)
        self.image_fig = p

    def _build_histories(self) -> None:
        self.readings_src: dict[str, ColumnDataSource] = {}
        self.forecast_src: dict[str, ColumnDataSource] = {}
        self.history_src: dict[str, ColumnDataSource] = {}
        self.history_point_src: dict[str, ColumnDataSource] = {}
        self.jump_src: dict[str, ColumnDataSource] = {}
        self.history_fig = {}
        self._presenting = False
        self._preview = False  # a dragged value's preview: the base without creep
        self._history_state = dict.fromkeys(QUANTITIES, "computed")
        self.history_line = {}
        self.history_cursor = {}
        # several punches: a line per punch on each history (none for one punch)
        self.punch_history_src: dict[str, ColumnDataSource] = {}
        # the time axis of every history, set from here on each result (fit_time): an
        # automatic range kept the span of a longer history after a preset with a
        # shorter one (-50 to 1050 days for 0 to 365)
        shared_x = self.time_range = Range1d(-0.05, 1.05, name="history_time_range")
        for q in QUANTITIES:
            unit = QUANTITY_UNITS[q][0]
            p = figure(height=210, sizing_mode="stretch_width", tools=TOOLS,
                       toolbar_location="above", name=f"{q}_figure",
                       title=f"{TITLES[q]} {SYMBOLS[q]} [{unit}]", y_range=Range1d(-1, 1),
                       x_range=shared_x)
            p.toolbar.autohide = True
            p.xaxis.axis_label = "t [days after loading]"
            p.yaxis.axis_label = f"{SYMBOLS[q]} [{unit}]"
            src = ColumnDataSource({"t": [0.0], "v": [0.0]}, name=f"{q}_source")
            point = ColumnDataSource(empty_columns("t", "v"), name=f"{q}_point_source")
            line = p.line(x="t", y="v", source=src, line_color=UNKNOWN_COLOR, line_width=2.5)
            p.scatter(x="t", y="v", source=point, size=8, color="#d62728", level=MOVING)
            p.add_tools(HoverTool(renderers=[line], mode="vline", tooltips=[
                ("t", "@t{0.0} days"), (SYMBOLS[q], f"@v{{0.0000}} {unit}")]))
            # where a given load jumps: the line breaks there (broken_at), and a dashed
            # mark says why
            jumps = ColumnDataSource({"t": []}, name=f"{q}_jumps_source")
            marks = p.vspan(x="t", source=jumps, line_color="#bbb", line_dash="dashed",
                            line_width=1, name=f"{q}_jumps")
            p.add_tools(HoverTool(renderers=[marks], tooltips=[
                ("a given load jumps at t", "@t{0.0} days")]))
            self.jump_src[q] = jumps
            cursor = Span(location=0, dimension="height", line_color="#999", line_dash="dotted",
                          level=MOVING)
            p.add_layout(cursor)
            # a fit's readings are made when first drawn (_readings): 8 plot renderers and
            # their sources, ~70 of a page's Bokeh models, which the server builds and the
            # browser renders for every page. The lines of several punches are made here
            # (one renderer, see _build_punch_lines)
            self._build_punch_lines(p, q, unit)
            self.history_src[q] = src
            self.history_point_src[q] = point
            self.history_fig[q], self.history_line[q] = p, line
            self.history_cursor[q] = cursor

    def _readings(self) -> None:
        """The readings and forecast of a fit on its histories, made when a fit's readings
        or forecast are first drawn (:meth:`_build_readings`)."""
        if not self.readings_src:
            for q in READ_SERIES:
                self._build_readings(self.history_fig[q], q, QUANTITY_UNITS[q][0])

    def _build_punch_lines(self, p: figure, q: str, unit: str) -> None:
        """The history of ``q`` of each punch of several, in its colour, with a legend
        (hidden, and empty, for a scene of one punch).

        One renderer draws every punch's line (a multi-line, a row per punch), the legend
        an entry per row: a renderer per punch made 144 of a page's 960 Bokeh models (852
        now), built by the server and rendered by the browser for every page though most
        scenes have one punch."""
        src = ColumnDataSource({"xs": [], "ys": [], "color": [], "label": []},
                               name=f"{q}_punches_source")
        lines = p.multi_line(xs="xs", ys="ys", line_color="color", line_width=2.5,
                             source=src, name=f"{q}_punches")
        p.add_tools(HoverTool(renderers=[lines], tooltips=[
            ("", "@label"), ("t", "$snap_x{0.0} days"),
            (SYMBOLS[q], f"$snap_y{{0.0000}} {unit}")]))
        # made with the figure: legend entries made later found no view in the page.
        # Above the plot, in a row: inside at the top left it hid the old footing's step
        # at one year (new_footing_beside_old), where every history starts
        p.add_layout(Legend(items=[
            LegendItem(label=f"punch {k + 1}", renderers=[lines], index=k, visible=False)
            for k in range(SCREEN_PUNCHES)], visible=False, orientation="horizontal",
            margin=0, padding=2, spacing=8, label_text_font_size="10px"), "above")
        self.punch_history_src[q] = src

    def _show_punch_histories(self, view: ResultView) -> None:
        """A line per punch on each history (several punches), or none (one punch)."""
        n = len(view.punches)
        for q in QUANTITIES:
            lines = [broken_at(view.times, view.punches[k].display(q), view.jumps)
                     for k in range(n)]
            set_data(self.punch_history_src[q], {
                "xs": [t for t, _ in lines], "ys": [v for _, v in lines],
                "color": list(PUNCH_COLORS[:n]),
                "label": [f"punch {k + 1}" for k in range(n)]})
            legend = self.history_fig[q].legend[0]
            for k, item in enumerate(legend.items):
                item.visible = k < n
            legend.visible = n > 0
            self.history_line[q].visible = n == 0

    def _build_readings(self, p: figure, q: str, unit: str) -> None:
        """The readings of a fit (points with one-standard-deviation bars) and the fitted
        scene's forecast with its band, on the history of ``q``; empty until a fit."""
        band = ColumnDataSource(empty_columns("t", "v", "lower", "upper"),
                                name=f"forecast_{q}")
        p.varea(x="t", y1="lower", y2="upper", source=band, fill_color=FORECAST_COLOR,
                fill_alpha=0.25)
        p.line(x="t", y="v", source=band, line_color=FORECAST_COLOR, line_width=2,
               line_dash="dotdash")
        src = ColumnDataSource(empty_columns("t", "v", "lower", "upper"),
                               name=f"readings_{q}")
        marks = p.scatter(x="t", y="v", source=src, size=6, color=READINGS_COLOR,
                          marker="circle_x", fill_alpha=0.0)
        p.add_layout(Whisker(base="t", lower="lower", upper="upper", source=src,
                             dimension="height", line_color=READINGS_COLOR,
                             upper_head=None, lower_head=None))
        p.add_tools(HoverTool(renderers=[marks], tooltips=[
            ("reading at t", "@t{0.0} days"), (SYMBOLS[q], f"@v{{0.0000}} {unit}")]))
        self.readings_src[q] = src
        self.forecast_src[q] = band

    # -- updates ---------------------------------------------------------------------
    def show_readings(self, columns: dict[str, dict[str, list[float]]]) -> None:
        """Draw the readings of a fit (:func:`explorer.model.readings_columns`, display
        units) on the settlement and tilt histories; empty lists clear them."""
        if not self.readings_src and not any(len(v) for q in READ_SERIES
                                             for v in columns[q].values()):
            return  # nothing drawn, nothing to clear
        self._readings()
        for q in READ_SERIES:
            set_data(self.readings_src[q], {k: f32(v) for k, v in columns[q].items()})
        self._fit_extra()

    def show_forecast(self, columns: dict[str, dict[str, list[float]]]) -> None:
        """Draw the fitted scene's forecast and its band
        (:func:`explorer.model.forecast_columns`, display units); empty lists clear it."""
        if not self.forecast_src and not any(len(v) for q in READ_SERIES
                                             for v in columns[q].values()):
            return  # nothing drawn, nothing to clear
        self._readings()
        for q in READ_SERIES:
            set_data(self.forecast_src[q], {k: f32(v) for k, v in columns[q].items()})
        self._fit_extra()

    def fit_time(self) -> None:
        """The time axis of the histories: every time drawn (the result, the pins, the
        readings and the forecast), with 5 % of the span beside each end (as the page's
        automatic range pads); sent only when it changes."""
        t = times_drawn(list(self.history_fig.values()))
        if not t.size:
            return  # nothing drawn
        lo, hi = float(t.min()), float(t.max())
        pad = 0.05 * (hi - lo) if hi > lo else max(abs(hi), 1.0) * 0.05
        start, end = lo - pad, hi + pad
        time_range = self.time_range  # the linear axis's (the log axis fits its own)
        if (time_range.start, time_range.end) != (start, end):
            time_range.update(start=start, end=end, reset_start=start, reset_end=end)

    def _fit_extra(self) -> None:
        """Value axes of the histories that also hold the readings and the band."""
        for q in READ_SERIES:
            extra = [self.readings_src[q].data.get(k, []) for k in ("lower", "upper")]
            extra += [self.forecast_src[q].data.get(k, []) for k in ("lower", "upper")]
            shown = [self.history_src[q].data.get("v", []), *extra,
                     *(pin.view.display(q) for pin in self._pins)]
            steady_range(self.history_fig[q].y_range, *shown)
        self.fit_time()

    def show(self, view: ResultView, index: int, pins: Sequence[Pin] = ()) -> None:
        """Draw a new result (call inside ``pn.io.hold`` to send one message)."""
        # A change of the loads leaves the drawing as it is: do not send it again.
        punches = [{k: v for k, v in spec.items() if k != "loading"}
                   for spec in view.scene.get("punches", [])]
        key = json.dumps([view.scene.get(k) for k in ("punch", "coating", "base")] + punches,
                         sort_keys=True, default=str)
        if key != self._scene_key:
            self.drawing.show(view, self.contact)
            if view.several:
                self.inset.hide()
            else:
                self.inset.show(view.geometry)
            self._scene_key = key
        if view.several:
            pins = ()  # pins compare results of one punch
        self.contact.show(view)
        self._scene_name = str(view.scene.get("name", ""))
        self._title_scene()
        self._show_image(view)
        self._label_strips(view)
        self._show_punch_histories(view)
        for q in QUANTITIES:
            given = q in view.given
            t, v = (broken_at(view.times, view.display(q), view.jumps)
                    if not view.several else ([], []))
            set_data(self.history_src[q], {"t": t, "v": v})
            set_data(self.jump_src[q], {"t": f32(view.jumps)})
            self.history_line[q].glyph.line_color = GIVEN_COLOR if given else UNKNOWN_COLOR
            state = "given" if given else "computed"
            if view.several:
                gives = [q in p.given for p in view.punches]
                state = ("given, per punch" if all(gives) else "computed, per punch"
                         if not any(gives) else "per punch (given for some)")
            self._history_state[q] = state
            self._title_history(q)
        self.pins.show(view, pins, index)
        self._fit_legend()
        self.show_time(view, index, pins, pinned_drawn=True)
        self.fit_axes(view, pins)

    def show_pinned(self, view: ResultView, pins: Sequence[Pin], index: int) -> None:
        """Overlay (or clear) the pinned results on the histories and the pressure."""
        self.pins.show(view, pins, index)
        self._fit_legend()
        self.fit_axes(view, pins)

    def _fit_legend(self) -> None:
        """The pressure plot and the map beside it as tall as the rows of the q(x) legend
        need (:data:`LEGEND_ROW` each past the first), so that its frame keeps its
        height."""
        height = (Q_HEIGHT[self._presenting]
                  + (legend_rows(self.q_fig.legend[0]) - 1) * LEGEND_ROW)
        if self.q_fig.height != height:
            self.q_fig.height = self.image_fig.height = height

    def fit_axes(self, view: ResultView, pins: Sequence[Pin] = ()) -> None:
        """Value axes of q(x) and the histories that hold the result at every output
        time and the pins (kept while they fit, see :func:`steady_range`): playing the
        times or stepping the load moves the curves, not the axes."""
        if view.several:
            pins = ()
        self._pins = tuple(pins)
        for q in QUANTITIES:
            extra = [] if q not in READ_SERIES or not self.readings_src else [
                src.data.get(k, []) for src in (self.readings_src[q], self.forecast_src[q])
                for k in ("lower", "upper")]
            extra += [p.display(q) for p in view.punches]
            steady_range(self.history_fig[q].y_range,
                         view.display(q) if not view.several else [],
                         *(pin.view.display(q) for pin in pins), *extra)
        self.fit_time()
        self._fit_pressure_x(view)
        self._fit_pressure(view)

    def _fit_pressure_x(self, view: ResultView) -> None:
        """The x axis of q(x): the punch (or punches) and the pins, set here rather than
        fitted in the page, whose automatic range sent its new ends back to the server at
        every geometry step (a message each way). Not a function of the time shown."""
        lo, hi = view.span
        for pin in self._pins:
            lo, hi = min(lo, pin.view.span[0]), max(hi, pin.view.span[1])
        pad = X_PADDING * (hi - lo)
        self.q_fig.x_range.update(start=lo - pad, end=hi + pad, reset_start=lo - pad,
                                  reset_end=hi + pad)

    def _fit_pressure(self, view: ResultView) -> None:
        size = self.scales.pressure_unit(view)[1]
        shown = [view.pressure / size, *(pin.view.pressure / size for pin in self._pins)]
        if self.classical:
            shown += [self.classic_src.data[k] for k in ("half_space", "bearing_rule")]
        steady_range(self.q_fig.y_range, *shown)

    def show_time(self, view: ResultView, index: int, pins: Sequence[Pin] = (),
                  pinned_drawn: bool = False) -> None:
        """Move every time cursor to output ``index`` (no solve)."""
        if view.several:
            pins = ()
        unit, size = self.scales.pressure_unit(view)
        t = float(view.times[index])
        q = view.pressure[:, index]
        set_data(self.q_src, {"x": f32(view.x), "q": f32(q / size)})
        self._show_corners(view, q / size)
        intervals = view.negative_intervals(index)
        set_data(self.neg_src, {"left": [lo for lo, _ in intervals],
                                "right": [hi for _, hi in intervals]})
        self._q_time = t
        self._title_pressure()
        self.q_fig.yaxis.axis_label = f"q [{unit}]"
        self.q_hover.tooltips = [("x", "@x{0.000} m"), ("q", f"@q{{0.000}} {unit}")]
        if not pinned_drawn:
            self.pins.show_time(view, pins, index)
        self._show_classical(view, index)
        self.image_cursor.location = t
        for name in QUANTITIES:
            self.history_cursor[name].location = t
            values = ([float(p.display(name)[index]) for p in view.punches] if view.several
                      else [float(view.display(name)[index])])
            set_data(self.history_point_src[name], {"t": [t] * len(values), "v": values})
        self.drawing.show_arrow(view, index)
        self.contact.show_time(view, index)

    def _show_corners(self, view: ResultView, q: np.ndarray) -> None:
        """Mark the rigid corners where q is unbounded and drawn held (``info
        ["corner_pressure"]``), at the held value, with the width held in the legend."""
        corner = None if view.several else view.info.get("corner_pressure")
        xs: list[float] = []
        if corner and q.size:
            ends = {-1: float(q[0]), 1: float(q[-1])}
            a = float(view.x[-1])
            xs = [float(c) for c in corner.get("corners_m", ()) if abs(abs(float(c)) - a)
                  <= 1e-9 * max(a, 1.0)]
        set_data(self.corner_src, {"x": xs, "q": [ends[1 if x > 0 else -1] for x in xs]})
        for item in self.q_fig.legend[0].items:
            if self.corner_marks in item.renderers:
                if xs:
                    within = float(corner.get("held_within_m", 0.0))
                    label = CORNER_LABEL.format(within=f"{1e3 * within:.3g} mm")
                    if item.label != fixed_label(label):
                        item.label = fixed_label(label)
                if item.visible != bool(xs):
                    item.visible = bool(xs)

    def _label_strips(self, view: ResultView) -> None:
        label = LIFTED_LABEL if view.info.get("contact") == "unilateral" else LOST_LABEL
        # listed only for a result with shaded strips at some time
        shaded = lifts_or_pulls(view)
        for item in self.q_fig.legend[0].items:
            if self.neg_strip in item.renderers:
                if item.label != fixed_label(label):
                    item.label = fixed_label(label)
                if item.visible != shaded:
                    item.visible = shaded
        wrap_legend(self.q_fig.legend[0])

    def set_classical(self, view: ResultView | None, index: int, shown: bool) -> None:
        """Show or hide the classical answers on the pressure plot."""
        self.classical = shown
        for line in self.classic_lines:
            line.visible = shown
        for item in self.q_fig.legend[0].items:
            if any(r in self.classic_lines for r in item.renderers):
                item.visible = shown
        wrap_legend(self.q_fig.legend[0])
        self._fit_legend()
        if view is not None:
            self._show_classical(view, index)

    def _show_classical(self, view: ResultView, index: int) -> None:
        if not self.classical:
            return
        if view.several:  # the classical answers are of one punch
            set_data(self.classic_src, empty_columns("x", "half_space", "bearing_rule"))
            return
        size = self.scales.pressure_unit(view)[1]
        a = view.geometry.half_width
        force = float(view.values["force"][index])
        moment = float(view.values["moment"][index])
        x = view.x
        set_data(self.classic_src, {
            "x": f32(x), "half_space": f32(half_space_pressure(x, force, moment, a) / size),
            "bearing_rule": f32(bearing_rule_pressure(x, force, moment, a) / size)})
        self._fit_pressure(view)

    classical = False

    def all_figures(self) -> list:
        """Every figure of the session."""
        return [self.scene_fig, self.q_fig, self.image_fig,
                *(self.history_fig[q] for q in QUANTITIES), self.contact_fig, self.inset_fig]

    def _title_history(self, q: str) -> None:
        """A history's title: the quantity, its unit and whether it is given or computed;
        without the unit (which its axis label gives) in presentation mode, where at
        1024 px the title ran past its plot ("Settlement δ [mm]: computed")."""
        unit = "" if self._presenting else f" [{QUANTITY_UNITS[q][0]}]"
        state = self._history_state[q]
        if self._presenting and "per punch" in state:
            # at 18 px "Settlement δ: computed, per punch" was cut at 1024 px too; the
            # colour of each punch's line says given or computed no more than this did
            state = "per punch"
        text = f"{TITLES[q]} {SYMBOLS[q]}{unit}: {state}"
        if self.history_fig[q].title.text != text:
            self.history_fig[q].title.text = text

    def _title_pressure(self) -> None:
        """The pressure plot's title: the time shown; in presentation mode without its
        years (beside the time player already), where at 1024 px it was cut ("Pressure
        q(x), t = 1000 days (2.7")."""
        t = getattr(self, "_q_time", None)
        if t is None:
            return
        text = (f"q(x) at t = {days_text(t, years=False)}" if self._presenting
                else f"Pressure q(x), t = {days_text(t)}")
        if self._preview:
            # the values of a preview are the base's without creep, whatever t is shown
            text += ": preview" if self._presenting else ": preview, without creep"
        if self.q_fig.title.text != text:
            self.q_fig.title.text = text

    def _title_scene(self) -> None:
        """The drawing's title: the scene's name, on two lines where it is long."""
        text = scene_title(getattr(self, "_scene_name", ""), self._presenting)
        if self.scene_fig.title.text != text:
            self.scene_fig.title.text = text

    def set_preview(self, on: bool) -> None:
        """Whether the result drawn next is a preview of a dragged value (the base without
        creep): the pressure plot's title says so beside its time."""
        if self._preview != on:
            self._preview = on
            self._title_pressure()

    def set_presentation(self, on: bool) -> None:
        """Fonts a projector shows from the back of a room (ticks and labels of
        :data:`PRESENTATION_FONT`), or the normal ones."""
        self._presenting = on
        for q in QUANTITIES:
            self._title_history(q)
        self._title_pressure()
        if hasattr(self, "_scene_name"):
            self._title_scene()
        tick, label, title = ((PRESENTATION_FONT, PRESENTATION_FONT, PRESENTATION_FONT)
                              if on else ("11px", "13px", "13px"))
        for fig in self.all_figures():
            fig.title.text_font_size = title
            for axis in (*fig.xaxis, *fig.yaxis):
                axis.major_label_text_font_size = tick
                axis.axis_label_text_font_size = label
                # ticks of 18 px on a 240 px plot: fewer of them, or they touch
                if hasattr(axis.ticker, "desired_num_ticks"):
                    axis.ticker.desired_num_ticks = PRESENTATION_TICKS if on else 6
            if on and fig.height is not None and fig.height <= SHORT_FIGURE:
                # the histories' and the contact width's plots are 190 and 170 px tall
                # there, ~70-80 px of axis: four ticks of 18 px ran into each other
                # ("0.08 0.06 0.04 0.02 0" on a settlement, "2 1.5 1 0.5 0" on a
                # contact width)
                for axis in fig.yaxis:
                    if hasattr(axis.ticker, "desired_num_ticks"):
                        axis.ticker.desired_num_ticks = PRESENTATION_SHORT_TICKS
            # hidden, not taken off: a toolbar put back (toolbar_location) made BokehJS
            # throw "cannot find a view for ToolbarPanel" as presentation mode ended
            fig.toolbar.visible = not on
            # the colour bars' ticks and titles larger too (they stayed at 11 px), short
            # of the axes' 18 px: six decades on a bar of ~130 px would touch
            for bar in fig.select({"type": ColorBar}):
                bar.major_label_text_font_size = PRESENTATION_BAR_FONT if on else "11px"
                bar.title_text_font_size = PRESENTATION_BAR_FONT if on else "13px"
        legend = self.q_fig.legend[0]
        legend.label_text_font_size = "11px" if on else LEGEND_FONT
        legend.glyph_width = 14 if on else 20
        for q in QUANTITIES:
            self.history_fig[q].height = 190 if on else 210
        self.scene_fig.height = self.inset_fig.height = 240 if on else 300
        self.contact_fig.height = 170 if on else 210
        self._fit_legend()

    def _show_image(self, view: ResultView) -> None:
        unit, size = self.scales.pressure_unit(view)
        x0, x1 = view.span  # (-a, a) for one punch
        t0, t1 = float(view.times[0]), float(view.times[-1])
        span = t1 - t0
        if not span > 0:
            # one output time: a band around it, so that the axis reads that time (a
            # zero-height image gave ticks like 10.000000001)
            span = max(0.1 * abs(t0), 1.0)
            t0 -= span / 2
        img = f32(view.image / size)
        set_data(self.image_src, {"image": [img], "x": [x0], "y": [t0], "dw": [x1 - x0],
                                  "dh": [span]})
        lo, hi = self.scales.image_range(view)
        self.image_mapper.update(low=lo, high=hi)
        self.image_bar.title = f"q [{unit}]"
        self.image_hover.tooltips = [("x", "$x{0.000} m"), ("t", "$y{0.0} days"),
                                     ("q", f"@image{{0.000}} {unit}")]
        self.image_fig.x_range.update(start=x0, end=x1)
        self.image_fig.y_range.update(start=t0, end=t0 + span)

    _scene_key: str | None = None
    _pins: tuple[Pin, ...] = ()
