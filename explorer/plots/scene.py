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
    LogColorMapper,
    NormalHead,
    Range1d,
)
from bokeh.plotting import figure

from ..model import ResultView
from .bokeh_data import MOVING
from .contact import ContactDrawing

# Number of slabs each coating layer is drawn with (its colour follows E(x)).
_SLABS = 120

#: The tools of every figure of the explorer.
TOOLS = "pan,wheel_zoom,box_zoom,reset,save"


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
        p.add_tools(HoverTool(renderers=[layers], tooltips=[
            ("layer", "@layer"), ("thickness", "@h_mm{0.00} mm"), ("E", "@E{0.0} MPa")]))
        self.arrow = Arrow(end=NormalHead(size=12, fill_color="#d62728", line_color="#d62728"),
                           x_start=0, y_start=1, x_end=0, y_end=0.5, line_width=3,
                           line_color="#d62728", visible=False, level=MOVING)
        p.add_layout(self.arrow)
        self.arrow_label = Label(x=0, y=0, text="", text_font_size="11px",
                                 text_color="#d62728", x_offset=6, level=MOVING)
        p.add_layout(self.arrow_label)
        self.base_label = Label(x=0, y=0, text="", text_font_size="11px", text_color="#333",
                                x_offset=4, y_offset=4)
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
        """The load's arrow and label at output ``index`` (at e = M/P) [m]."""
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
            self.arrow_label.update(x=xe, y=top + 0.3 * g.half_width,
                                    text=f"P = {force / 1e3:.4g} kN/m, {where}")
        else:
            self.arrow.visible = False
            self.arrow_label.update(x=-g.half_width, y=top + 0.3 * g.half_width,
                                    text=f"P = {force / 1e3:.4g} kN/m (no compressive load)")

    def show(self, view: ResultView, contact: ContactDrawing) -> None:
        """Draw the scene of ``view`` (``contact`` gets the coating's surface, for its
        contact zone)."""
        g = view.geometry
        a = g.half_width
        depth = min(g.base_thickness, 1.2 * a)
        total = np.sum(g.thickness, axis=0) if len(g.thickness) else np.zeros_like(g.x)
        t_max = float(np.max(total)) if total.size else 0.0
        scale = _nice(0.15 * depth / t_max) if t_max > 0 else 1.0
        # slabs: boundaries and values at the centres, interpolated from the fine grid
        edges = np.linspace(-a, a, _SLABS + 1)
        centres = 0.5 * (edges[1:] + edges[:-1])
        bottom = np.zeros(_SLABS)
        cols: dict[str, list] = {k: [] for k in ("left", "right", "bottom", "top", "E",
                                                 "layer", "h_mm")}
        # layer 1 is drawn on top, in contact with the punch
        for k in reversed(range(len(g.thickness))):
            h = np.interp(centres, g.x, g.thickness[k])
            e = np.interp(centres, g.x, g.modulus[k])
            top = bottom + scale * h
            cols["left"].extend(edges[:-1])
            cols["right"].extend(edges[1:])
            cols["bottom"].extend(bottom)
            cols["top"].extend(top)
            cols["E"].extend(e / 1e6)
            cols["layer"].extend([k + 1] * _SLABS)
            cols["h_mm"].extend(h * 1e3)
            bottom = top
        self.layer_src.data = cols
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
        self.fig.y_range.update(start=-1.08 * depth, end=punch_top + 0.55 * a)
        note = f"coating and punch profile drawn ×{scale:g} vertically" if scale > 1 else \
            "drawn to scale"
        self.scale_label.text = note

    _punch_top = 0.0
