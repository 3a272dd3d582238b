"""Bokeh parts that show the contact zone: a bar under the punch in the scene drawing,
the contact width (and lift-off length) over time, and the inset of small features.

Built once per session and updated in place, like the other figures
(:mod:`explorer.plots.figures`). Nothing here imports Panel.
"""

from __future__ import annotations

import numpy as np
from bokeh.core.properties import value as fixed_label
from bokeh.models import ColumnDataSource, HoverTool, Label, Range1d, Span
from bokeh.plotting import figure

from core.scene import days_text

from ..model import (
    Geometry,
    ResultView,
    contact_widths,
    contact_zones,
    lift_off_lengths,
    lifts_off,
    lifts_or_pulls,
)
from .bokeh_data import MOVING, f32, legend_above, legend_below, legend_inside, set_data

# navy: apart from the viridis colours of the coating it lies on; red as the lifted
# (shaded) parts of q(x)
CONTACT_COLOR = "#08306b"
LIFTED_COLOR = "#d62728"
#: The dashed parts: a gap a unilateral solve opened, or where the full-contact model
#: pulls (q < 0), which a real base would not do.
GAP_LABEL = "lifted off (gap open)"
PULL_LABEL = "q < 0 (full-contact model)"
_TOOLS = "pan,wheel_zoom,box_zoom,reset,save"

#: Geometric features of less than this [m] are not drawn in the inset: below the
#: round-off of a thickness of 1 m (a flat punch on a uniform coating has none).
FEATURE_FLOOR_M = 1e-9


def _along(x: np.ndarray, y: np.ndarray, lo: float, hi: float
           ) -> tuple[np.ndarray, np.ndarray]:
    """The curve ``y(x)`` from ``lo`` to ``hi`` (ends interpolated), as arrays: the page
    gets them as binary buffers, not as JSON lists of numbers to write and parse (a zone
    over a whole drawing: ~400 points), and keeps the zone's ends as computed."""
    inside = (x > lo) & (x < hi)
    xs = np.concatenate([[lo], x[inside], [hi]])
    return xs, np.interp(xs, x, y)


class ContactDrawing:
    """The contact zone on the scene drawing and the contact width history figure."""

    def __init__(self, scene_fig: figure, x_range: Range1d | None = None) -> None:
        self.zone_src = ColumnDataSource({"xs": [], "ys": []}, name="contact_zone_source")
        self.lifted_src = ColumnDataSource({"xs": [], "ys": []}, name="lifted_zone_source")
        scene_fig.multi_line(xs="xs", ys="ys", source=self.zone_src, line_color=CONTACT_COLOR,
                             line_width=6, line_alpha=0.9, legend_label="in contact")
        self.lifted_line = scene_fig.multi_line(xs="xs", ys="ys", source=self.lifted_src,
                                                line_color=LIFTED_COLOR, line_width=5,
                                                line_dash="dashed", legend_label=GAP_LABEL)
        # in the base's corner: the load's arrow and its label use the top of the drawing
        self.scene_legend = legend_inside(scene_fig, "bottom_right", "11px")
        # beside the punch, just above the coating (placed at each time, see show_time)
        self.zone_label = Label(x=0, y=0, text="", text_font_size="11px", x_offset=4,
                                y_offset=-6, text_baseline="top",
                                text_color="#333", background_fill_color="white",
                                background_fill_alpha=0.7, name="contact_zone_label",
                                level=MOVING)
        scene_fig.add_layout(self.zone_label)
        self._surface: tuple[np.ndarray, np.ndarray] = (np.array([-1.0, 1.0]), np.zeros(2))
        self._zone_key: tuple | None = None
        self._build_width(x_range)

    def _build_width(self, x_range: Range1d | None) -> None:
        kwargs = {"x_range": x_range} if x_range is not None else {}
        p = figure(height=210, sizing_mode="stretch_width", tools=_TOOLS,
                   toolbar_location="above", name="contact_width_figure",
                   title="Contact width [m]", **kwargs)
        p.toolbar.autohide = True
        p.xaxis.axis_label = "t [days after loading]"
        p.yaxis.axis_label = "length [m]"
        self.width_src = ColumnDataSource({"t": [0.0], "width": [0.0], "lifted": [0.0]},
                                          name="contact_width_source")
        width = p.line(x="t", y="width", source=self.width_src, line_color=CONTACT_COLOR,
                       line_width=2.5, legend_label="contact width")
        p.line(x="t", y="lifted", source=self.width_src, line_color=LIFTED_COLOR,
               line_width=2, line_dash="dashed", legend_label="lift-off length")
        p.add_tools(HoverTool(renderers=[width], mode="vline", tooltips=[
            ("t", "@t{0.0} days"), ("contact width", "@width{0.0000} m"),
            ("lift-off length", "@lifted{0.0000} m")]))
        self.width_point = ColumnDataSource({"t": [], "v": []}, name="contact_width_point")
        p.scatter(x="t", y="v", source=self.width_point, size=8, color=LIFTED_COLOR,
                  level=MOVING)
        self.width_cursor = Span(location=0, dimension="height", line_color="#999",
                                 line_dash="dotted", level=MOVING)
        p.add_layout(self.width_cursor)
        legend_above(p, "11px")
        self.width_fig = p
        self._widths = np.zeros(1)

    def set_surface(self, x: np.ndarray, y: np.ndarray) -> None:
        """The coating's top surface as drawn (``x`` [m], ``y`` in drawing units)."""
        self._surface = (np.asarray(x, dtype=float), np.asarray(y, dtype=float))

    def show(self, view: ResultView) -> None:
        """A new result: the width history (the zone itself follows :meth:`show_time`)."""
        a = view.geometry.half_width
        widths = contact_widths(view)
        self._widths = widths
        set_data(self.width_src, {"t": f32(view.times), "width": f32(widths),
                                  "lifted": f32(lift_off_lengths(view))})
        self.width_fig.y_range.start = 0.0
        self.width_fig.y_range.end = 2.1 * a
        label = fixed_label(GAP_LABEL if view.info.get("contact") == "unilateral"
                            else PULL_LABEL)
        dashed = lifts_or_pulls(view)
        for item in self.scene_legend.items:
            if self.lifted_line in item.renderers:
                if item.label != label:
                    item.label = label
                item.visible = dashed  # listed only when some time has a dashed part
        # short titles: at 1024 px this figure is ~300 px wide
        if lifts_off(view):
            self.width_fig.title.text = "Contact width [m]: lift-off"
        elif dashed:  # the full-contact model's width is 2a, though it pulls somewhere
            self.width_fig.title.text = "Contact width [m]: full-contact model, q < 0"
        else:
            self.width_fig.title.text = "Contact width [m]: full contact"

    def show_time(self, view: ResultView, index: int) -> None:
        """The zone under the punch and the cursor at output ``index``."""
        a = view.geometry.half_width
        x, y = self._surface
        zones = contact_zones(view, index)
        lifted = view.negative_intervals(index)
        key = (zones, lifted, id(self._surface))
        if key != self._zone_key:  # a load step in full contact leaves the bar as it is
            self._zone_key = key
            pieces = [_along(x, y, lo, hi) for lo, hi in zones]
            self.zone_src.data = {"xs": [p[0] for p in pieces], "ys": [p[1] for p in pieces]}
            pieces = [_along(x, y, lo, hi) for lo, hi in lifted]
            self.lifted_src.data = {"xs": [p[0] for p in pieces],
                                    "ys": [p[1] for p in pieces]}
        t = float(view.times[index])
        width = float(self._widths[index]) if index < len(self._widths) else 2 * a
        # at the drawing's left edge (0.52 of the widest punch's half-width left of the
        # loaded stretch, -1.52 a for one punch), just below the base's top: above the
        # surface it ran over the leftmost punch and its load's label at 1024 px
        widest = max((p.half_width for p in view.punches), default=a)
        self.zone_label.update(x=view.span[0] - 0.52 * widest, y=0.0)
        if width < 2 * a and lifted:
            self.zone_label.text = f"contact {width:.3f} m of {2 * a:.3g} m at t = {days_text(t)}"
        elif lifted:
            self.zone_label.text = f"full-contact model, q < 0 at t = {days_text(t)}"
        else:
            self.zone_label.text = f"full contact at t = {days_text(t)}"
        self.width_cursor.location = t
        set_data(self.width_point, {"t": [t], "v": [width]})


class FeatureInset:
    """Small features of the punch and the coating, in micrometres: the punch's base and
    the coating's top before loading, and the gap between them.

    A wear patch of 20 µm on a 20 mm coating, a 15 µm step, a crown of 25 µm: drawn at the
    scale of the coating they are a fraction of a pixel, yet they decide where the punch
    bears. Hidden when there is no such feature (a flat punch on a uniform coating).
    """

    def __init__(self) -> None:
        p = figure(height=300, width=220, tools="pan,wheel_zoom,reset", toolbar_location=None,
                   title="Features [µm]", name="features_figure", visible=False)
        p.xaxis.axis_label = "x [m]"
        p.yaxis.axis_label = "height [µm]"
        self.src = ColumnDataSource({"x": [], "punch": [], "surface": []},
                                    name="features_source")
        self.gap_area = p.varea(x="x", y1="surface", y2="punch", source=self.src,
                                fill_color="#ffbb78", fill_alpha=0.6,
                                legend_label="initial gap")
        p.line(x="x", y="surface", source=self.src, line_color="#8c564b", line_width=2,
               legend_label="coating top")
        punch = p.line(x="x", y="punch", source=self.src, line_color="#333", line_width=2,
                       legend_label="punch base")
        p.add_tools(HoverTool(renderers=[punch], mode="vline", tooltips=[
            ("x", "@x{0.000} m"), ("punch base", "@punch{0.00} µm"),
            ("coating top", "@surface{0.00} µm")]))
        # below the plot, not inside it: the coating's top is the lowest line of a uniform
        # coating (heights above its highest point), and a legend in the corner hid it
        legend_below(p)
        self.fig = p

    def hide(self) -> None:
        """Show no features (a scene of several punches: the inset draws one punch)."""
        self.fig.visible = False
        self.src.data = {"x": [], "punch": [], "surface": []}

    def show(self, g: Geometry) -> None:
        """Draw the features of ``g`` (heights above the coating's highest point [µm])."""
        total = np.sum(g.thickness, axis=0) if len(g.thickness) else np.zeros_like(g.x)
        surface = total - float(np.max(total))
        # the punch rests on the coating where the gap shape - thickness is smallest
        gap = g.shape - total
        gap = gap - float(np.min(gap))
        punch = surface + gap
        relief = max(float(np.ptp(gap)), float(np.ptp(surface)))
        self.fig.visible = relief > FEATURE_FLOOR_M
        if not self.fig.visible:
            self.src.data = {"x": [], "punch": [], "surface": []}
            return
        self.src.data = {"x": f32(g.x), "punch": f32(punch * 1e6),
                         "surface": f32(surface * 1e6)}
        # the size in the legend: a title longer than "Features [µm]" overflowed the
        # inset's 220 px in presentation mode, and so did "gap before loading (≤ 25 µm)"
        # under it, past the page's right edge at 1024 px
        label = fixed_label(f"initial gap (≤ {float(np.max(gap)) * 1e6:.3g} µm)")
        for item in self.fig.legend[0].items:
            if self.gap_area in item.renderers and item.label != label:
                item.label = label
