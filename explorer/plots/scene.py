"""The scene drawing of the explorer: base, coating layers (coloured by modulus), the
punch and the load's arrow, to scale across and exaggerated vertically.

Built once per session and updated in place (see :mod:`explorer.plots.figures`); the drawing is
redrawn only when the punch, coating or base change, not for a load step. Nothing here
imports Panel.
"""

from __future__ import annotations

import math

import numpy as np
from bokeh.models import (
    Arrow,
    ColorBar,
    ColumnDataSource,
    HoverTool,
    Label,
    LabelSet,
    LogColorMapper,
    NormalHead,
    Range1d,
)
from bokeh.plotting import figure

from core.scene import PUNCH_COLOURS, number_text

from ..model import SCREEN_PUNCHES, Geometry, ResultView
from .bokeh_data import MOVING, f32
from .contact import ContactDrawing

# Number of slabs each coating layer is drawn with (its colour follows E(x)).
_SLABS = 120

#: The tools of every figure of the explorer.
TOOLS = "pan,wheel_zoom,box_zoom,reset,save"

#: The colour of each punch of a scene of several, in order (drawing, histories,
#: readout): core's (its plots and reports), Bokeh's Category10 less its red, which marks
#: loads and lift-off; as many as the page edits.
PUNCH_COLORS = PUNCH_COLOURS[:SCREEN_PUNCHES]


def _nice(value: float) -> float:
    """The largest of 1, 2, 5 times a power of ten not above ``value`` (at least 1)."""
    if not np.isfinite(value) or value <= 1:
        return 1.0
    power = 10 ** math.floor(math.log10(value))
    for step in (5, 2, 1):
        if step * power <= value:
            return float(step * power)
    return float(power)


def empty_columns(*columns: str) -> dict[str, list]:
    """The data of an empty ColumnDataSource with ``columns``."""
    return {c: [] for c in columns}


class SceneDrawing:
    """The figure of the scene (``fig``, named ``scene_figure``) and its sources."""

    def __init__(self, modulus_mapper: LogColorMapper) -> None:
        self.modulus_mapper = modulus_mapper
        p = figure(height=300, sizing_mode="stretch_width", tools=TOOLS,
                   x_range=Range1d(-1.5, 1.5), y_range=Range1d(-1.5, 1.0),
                   title="Scene", toolbar_location="above", name="scene_figure")
        p.toolbar.autohide = True
        p.xaxis.axis_label = "x [m]"
        p.yaxis.axis_label = "y [m] (exaggerated)"
        self.base_src = ColumnDataSource(empty_columns("left", "right", "bottom", "top", "E"),
                                         name="base_source")
        self.layer_src = ColumnDataSource(
            empty_columns("left", "right", "bottom", "top", "E", "layer", "h_mm"),
            name="layer_source")
        self.punch_src = ColumnDataSource(empty_columns("x", "y"), name="punch_source")
        self.cut_src = ColumnDataSource(empty_columns("x", "y"), name="cut_source")
        fill = {"field": "E", "transform": self.modulus_mapper}
        p.quad(left="left", right="right", bottom="bottom", top="top", source=self.base_src,
               fill_color=fill, line_color=None, fill_alpha=0.55)
        layers = p.quad(left="left", right="right", bottom="bottom", top="top",
                        source=self.layer_src, fill_color=fill, line_color=fill)
        p.patch(x="x", y="y", source=self.punch_src, fill_color="#b0b7c3", line_color="#333",
                line_width=1.5)
        p.line(x="x", y="y", source=self.cut_src, line_dash="dashed", line_color="#333")
        # several punches: one patch each, edged in its colour, its load's arrow and label
        self.punches_src = ColumnDataSource(empty_columns("xs", "ys", "color", "name"),
                                            name="punches_source")
        p.patches(xs="xs", ys="ys", source=self.punches_src, fill_color="#b0b7c3",
                  line_color="color", line_width=2.5)
        self.punch_arrow_src = ColumnDataSource(
            empty_columns("x", "y_start", "y_end", "label_y", "text"), name="punch_arrow_source")
        p.add_layout(Arrow(end=NormalHead(size=10, fill_color="#d62728", line_color="#d62728"),
                           x_start="x", y_start="y_start", x_end="x", y_end="y_end",
                           source=self.punch_arrow_src, line_width=3, line_color="#d62728",
                           level=MOVING))
        p.add_layout(LabelSet(x="x", y="label_y", text="text", source=self.punch_arrow_src,
                              text_font_size="11px", text_color="#d62728", x_offset=4,
                              level=MOVING))
        p.add_tools(HoverTool(renderers=[layers], tooltips=[
            ("layer", "@layer"), ("thickness", "@h_mm{0.00} mm"), ("E", "@E{0.0} MPa")]))
        self.arrow = Arrow(end=NormalHead(size=12, fill_color="#d62728", line_color="#d62728"),
                           x_start=0, y_start=1, x_end=0, y_end=0.5, line_width=3,
                           line_color="#d62728", visible=False, level=MOVING)
        p.add_layout(self.arrow)
        self.arrow_label = Label(x=0, y=0, text="", text_font_size="11px",
                                 text_color="#d62728", x_offset=6, level=MOVING)
        p.add_layout(self.arrow_label)
        # above the scale note (bottom left, 4 px up): at 4 px both overlapped
        self.base_label = Label(x=0, y=0, text="", text_font_size="11px", text_color="#333",
                                x_offset=4, y_offset=20)
        p.add_layout(self.base_label)
        # the vertical exaggeration, inside the plot: in the title it made the title too
        # long for a 1024 px screen
        self.scale_label = Label(x=4, y=4, x_units="screen", y_units="screen", text="",
                                 text_font_size="11px", text_color="#555",
                                 background_fill_color="white", background_fill_alpha=0.7,
                                 name="scale_label")
        p.add_layout(self.scale_label)
        p.add_layout(ColorBar(color_mapper=self.modulus_mapper, title="E [MPa]", width=8),
                     "right")
        self.fig = p

    def show_arrow(self, view: ResultView, index: int) -> None:
        """The load's arrow and label at output ``index`` (at e = M/P) [m]; one per punch
        for several."""
        if view.punches:
            self.arrow.visible = False
            self.arrow_label.text = ""
            self._show_punch_arrows(view, index)
            return
        if self.punch_arrow_src.data["x"]:
            self.punch_arrow_src.data = empty_columns("x", "y_start", "y_end", "label_y",
                                                      "text")
        g = view.geometry
        force = float(view.values["force"][index])
        moment = float(view.values["moment"][index])
        top = self._punch_top
        if force > 0 and np.isfinite(moment):
            e = moment / force
            inside = abs(e) <= 1.45 * g.half_width
            xe = float(np.clip(e, -1.45 * g.half_width, 1.45 * g.half_width))
            self.arrow.update(x_start=xe, x_end=xe, y_start=top + 0.45 * g.half_width,
                              y_end=top + 0.02 * g.half_width, visible=True)
            where = f"e = M/P = {e:.3g} m" + ("" if inside else " (off the drawing)")
            # the words toward the middle of the drawing: to the right of an arrow at e =
            # 0.83 m they ran off the plot ("P = 800 kN/m, e = M/P =", the value cut)
            right = xe > 0
            self.arrow_label.update(x=xe, y=top + 0.3 * g.half_width,
                                    text=f"P = {number_text(force / 1e3)} kN/m, {where}",
                                    text_align="right" if right else "left",
                                    x_offset=-6 if right else 6)
        else:
            self.arrow.visible = False
            self.arrow_label.update(x=-g.half_width, y=top + 0.3 * g.half_width,
                                    text=f"P = {number_text(force / 1e3)} kN/m (no "
                                         "compressive load)", text_align="left", x_offset=6)

    def _show_punch_arrows(self, view: ResultView, index: int) -> None:
        """Each punch's force at output ``index``, drawn at its e = M/P [m] (within the
        punch; the label says where it acts)."""
        cols: dict[str, list] = empty_columns("x", "y_start", "y_end", "label_y", "text")
        top = self._punch_top
        for k, p in enumerate(view.punches):
            force = float(p.values["force"][index])
            moment = float(p.values["moment"][index])
            a = p.half_width
            e = moment / force if force > 0 else 0.0
            xe = p.center + float(np.clip(e, -a, a))
            cols["x"].append(xe)
            cols["y_start"].append(top + 0.45 * self._a_ref)
            cols["y_end"].append(top + 0.02 * self._a_ref)
            cols["label_y"].append(top + 0.3 * self._a_ref)
            where = f", e = {e:.3g} m" if force > 0 and e else ""
            cols["text"].append(f"{k + 1}: P = {number_text(force / 1e3)} kN/m{where}")
        self.punch_arrow_src.data = cols

    def show(self, view: ResultView, contact: ContactDrawing) -> None:
        """Draw the scene of ``view`` (``contact`` gets the coating's surface, for its
        contact zone)."""
        if view.punches:
            self._show_punches(view, contact)
            return
        if self.punches_src.data["xs"]:
            self.punches_src.data = empty_columns("xs", "ys", "color", "name")
        g = view.geometry
        a = g.half_width
        depth = min(g.base_thickness, 1.2 * a)
        total = np.sum(g.thickness, axis=0) if len(g.thickness) else np.zeros_like(g.x)
        t_max = float(np.max(total)) if total.size else 0.0
        scale = _nice(0.15 * depth / t_max) if t_max > 0 else 1.0
        self.layer_src.data = _slabs(g, -a, a, _SLABS, scale)
        self.base_src.data = {"left": [-1.5 * a], "right": [1.5 * a], "bottom": [-depth],
                              "top": [0.0], "E": [g.base_modulus / 1e6]}
        if g.base_thickness > depth:
            self.cut_src.data = {"x": [-1.5 * a, 1.5 * a], "y": [-depth, -depth]}
            self.base_label.update(x=-1.5 * a, y=-depth,
                                   text=f"base continues to H = {g.base_thickness:.3g} m")
        else:
            self.cut_src.data = {"x": [], "y": []}
            self.base_label.update(x=-1.5 * a, y=-depth,
                                   text=f"base H = {g.base_thickness:.3g} m on rigid ground")
        lift = float(np.min(g.shape - total))
        bottom_y = scale * (g.shape - lift)
        punch_top = float(np.max(bottom_y)) + 0.35 * a
        self._punch_top = punch_top
        contact.set_surface(g.x, scale * total)
        self.punch_src.data = {"x": np.concatenate([g.x, [a, -a]]),
                               "y": np.concatenate([bottom_y, [punch_top, punch_top]])}
        self.fig.x_range.update(start=-1.55 * a, end=1.55 * a)
        self.fig.y_range.update(start=-1.08 * depth, end=_top_of_drawing(punch_top, a, depth))
        self._say_scale(scale, "coating and punch profile")

    def _show_punches(self, view: ResultView, contact: ContactDrawing) -> None:
        """Draw a scene of several punches: the coating along the loaded stretch and
        beyond, and each punch in its colour (global x [m])."""
        g = view.geometry
        lo, hi = view.span
        a_ref = max(p.half_width for p in view.punches)
        self._a_ref = a_ref
        left, right = lo - 0.5 * a_ref, hi + 0.5 * a_ref
        depth = min(g.base_thickness, 0.6 * (hi - lo))
        total = np.sum(g.thickness, axis=0) if len(g.thickness) else np.zeros_like(g.x)
        t_max = float(np.max(total)) if total.size else 0.0
        scale = _nice(0.15 * depth / t_max) if t_max > 0 else 1.0
        self.layer_src.data = _slabs(g, left, right, _SLABS * len(view.punches), scale)
        self.base_src.data = {"left": [left], "right": [right], "bottom": [-depth],
                              "top": [0.0], "E": [g.base_modulus / 1e6]}
        if g.base_thickness > depth:
            self.cut_src.data = {"x": [left, right], "y": [-depth, -depth]}
            self.base_label.update(x=left, y=-depth,
                                   text=f"base continues to H = {g.base_thickness:.3g} m")
        else:
            self.cut_src.data = {"x": [], "y": []}
            self.base_label.update(x=left, y=-depth,
                                   text=f"base H = {g.base_thickness:.3g} m on rigid ground")
        self.punch_src.data = {"x": [], "y": []}
        xs, ys = [], []
        punch_top = 0.0
        bottoms = []
        for x, shape in zip(g.punch_x, g.punch_shape, strict=True):
            under = np.interp(x, g.x, total)
            lift = float(np.min(shape - under))
            bottom_y = scale * (shape - lift)
            bottoms.append((x, bottom_y))
            punch_top = max(punch_top, float(np.max(bottom_y)) + 0.35 * a_ref)
        for x, bottom_y in bottoms:
            xs.append(np.concatenate([x, [x[-1], x[0]]]))
            ys.append(np.concatenate([bottom_y, [punch_top, punch_top]]))
        self._punch_top = punch_top
        self.punches_src.data = {"xs": xs, "ys": ys,
                                 "color": list(PUNCH_COLORS[: len(xs)]),
                                 "name": [f"punch {k + 1}" for k in range(len(xs))]}
        contact.set_surface(g.x, scale * total)
        self.fig.x_range.update(start=left - 0.05 * a_ref, end=right + 0.05 * a_ref)
        self.fig.y_range.update(start=-1.08 * depth,
                                end=_top_of_drawing(punch_top, a_ref, depth))
        self._say_scale(scale, "coating and punch profiles")

    def _say_scale(self, scale: float, what: str) -> None:
        """The note in the corner and the y axis's label say the same of the drawing's
        vertical ``scale`` (a bare layer read "drawn to scale" beside "y [m]
        (exaggerated)")."""
        self.scale_label.text = (f"{what} drawn ×{scale:g} vertically" if scale > 1
                                 else "drawn to scale")
        label = "y [m] (exaggerated)" if scale > 1 else "y [m]"
        axis = self.fig.yaxis[0]
        if axis.axis_label != label:  # (a label set anew lays the figure out)
            axis.axis_label = label

    _punch_top = 0.0
    _a_ref = 1.0


#: Room above the punches for the loads' arrows and labels: at least this share of the
#: drawing's height (a wide scene of several punches is drawn deep, and the labels, of a
#: fixed size in pixels, ran out of its top in presentation mode at 1024x768).
HEADROOM_SHARE = 0.25


def _top_of_drawing(punch_top: float, a: float, depth: float) -> float:
    """The y range's end [m, drawn]: 0.55 ``a`` above the punch top, or more where the
    drawing is deep (``depth`` of base shown)."""
    return punch_top + max(0.55 * a, HEADROOM_SHARE * (punch_top + 1.08 * depth))


def _slabs(g: Geometry, left: float, right: float, count: int, scale: float
           ) -> dict[str, np.ndarray]:
    """The coating drawn as ``count`` slabs a layer over [left, right] [m]: their bounds,
    tops (thickness times the drawing's vertical ``scale``) and, at their centres
    (interpolated from the geometry's fine grid), modulus [MPa], layer and thickness [mm];
    layer 1 on top, in contact with the punch. Arrays (float32: a drawing and its hover
    need no more), which the page gets as binary buffers instead of JSON lists."""
    edges = np.linspace(left, right, count + 1)
    centres = 0.5 * (edges[1:] + edges[:-1])
    n = len(g.thickness)
    h = np.array([np.interp(centres, g.x, g.thickness[k])
                  for k in reversed(range(n))]).reshape(n, count)
    e = np.array([np.interp(centres, g.x, g.modulus[k])
                  for k in reversed(range(n))]).reshape(n, count)
    tops = np.cumsum(scale * h, axis=0)
    bottoms = tops - scale * h
    return {"left": f32(np.tile(edges[:-1], n)), "right": f32(np.tile(edges[1:], n)),
            "bottom": f32(bottoms.ravel()), "top": f32(tops.ravel()),
            "E": f32(e.ravel() / 1e6), "h_mm": f32(h.ravel() * 1e3),
            "layer": np.repeat(np.arange(n, 0, -1, dtype=np.int32), count)}
