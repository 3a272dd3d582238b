"""The report's plots, one HoloViews layout for both printers: those of
:meth:`SceneSolution.plot` (q(x) at a few times and at the time the reader chose,
settlement and tilt over time), the contact width and the lifted length over time when
the punch lifts off, and the punch base and the coating thickness over x when they vary.

Options are set for the Bokeh backend, as :mod:`core.scene.plotting` sets them (the HTML
report); :mod:`core.report.pdf` draws the same elements with Matplotlib. HoloViews is imported
when a plot is made, never with :mod:`core.report`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from core.report.contact import lift_off_times, output_index
from core.report.inputs import LAYER_FIELDS, SHAPE_UNIT
from core.scene import (
    PRESSURE_WIDTH,
    PunchesSolution,
    SceneSolution,
    holoviews_for_bokeh,
    known_contact_width,
    shown_times,
)

#: The curves of the contact plot: (label, colour), the part in contact dark blue and the
#: part lifted off red, as the explorer draws them.
CONTACT_CURVES = (("contact width", "#08306b"), ("lifted length", "#d62728"))
#: The geometry plots: (name of the plotted value, title, colour).
GEOMETRY_PLOTS = (("punch_base", "punch base f(x) above its lowest point", "#333333"),
                  ("coating_thickness", "coating thickness, all layers", "#2b7bb9"))
#: Size of a plot of the report [screen pixels] (those of SceneSolution.plot are 400 x 300).
PLOT_WIDTH, PLOT_HEIGHT = 400, 300
#: The titles of the three plots of :meth:`SceneSolution.plot` in the PDF, in its order
#: (their Bokeh titles are options Matplotlib does not read).
PLOT_TITLES = ("contact pressure q(x, t) (grey: lifted off)", "settlement δ(t)", "tilt α(t)")
#: Points of the geometry plots over [-a, a], besides both sides of every breakpoint.
GEOMETRY_POINTS = 801
#: The shade of a punch's zone in the q(x) plot over the surface of several punches, and
#: the group that tells its spans from the lift-off shade.
ZONE_COLOUR, ZONE_GROUP = "#c6dbef", "Zone"


def contact_overlay(result: SceneSolution) -> Any:
    """The contact width and the lifted length [m] over time (their sum is 2a)."""
    hv = holoviews_for_bokeh("the report's plots")
    width = known_contact_width(result)
    full = 2 * result.scene.half_width
    t_dim = hv.Dimension("time", label="t", unit="day")
    length = hv.Dimension("length", label="length", unit="m")
    curves = [hv.Curve((result.times, values), kdims=[t_dim], vdims=[length], label=label)
              .opts(color=colour, tools=["hover"], backend="bokeh")
              for (label, colour), values in zip(CONTACT_CURVES, (width, full - width),
                                                 strict=True)]
    return hv.Overlay(curves).opts(
        title=contact_title(result), width=PLOT_WIDTH, height=PLOT_HEIGHT,
        legend_position="right", backend="bokeh")


def contact_title(result: SceneSolution) -> str:
    """The contact plot's title."""
    return f"contact width and lifted length (2a = {2 * result.scene.half_width:g} m)"


def _geometry_x(result: SceneSolution) -> np.ndarray:
    a = result.scene.half_width
    # both sides of a jump of a profile (a step of the punch base, a coating patch)
    sides = [p + s * 1e-9 * a for p in result.scene.breakpoints for s in (-1.0, 1.0)]
    return np.clip(np.union1d(np.linspace(-a, a, GEOMETRY_POINTS), sides), -a, a)


def geometry_curves(result: SceneSolution) -> list[tuple[str, Any]]:
    """(title, curve) of the punch base f(x) [mm] and of the coating thickness of all
    layers [mm] over x [m], each only where it varies (a flat base and a uniform coating
    are said in the inputs)."""
    hv = holoviews_for_bokeh("the report's plots")
    scene = result.scene
    x = _geometry_x(result)

    def values(profile: Any) -> np.ndarray:
        return np.broadcast_to(np.asarray(profile(x), dtype=float), x.shape)

    _, shape_unit, shape_size = SHAPE_UNIT
    _, unit, size = LAYER_FIELDS["thickness"]
    heights = {"punch_base": (values(scene.shape) / shape_size, shape_unit),
               "coating_thickness": (sum(values(layer.thickness) for layer in scene.coating)
                                     / size, unit)}
    x_dim = hv.Dimension("x", label="x", unit="m")
    out = []
    for name, title, colour in GEOMETRY_PLOTS:
        height, unit = heights[name]
        if np.ptp(height) == 0:
            continue
        title = f"{title} [{unit}]"
        y_dim = hv.Dimension(name, label=name.replace("_", " "), unit=unit)
        out.append((title, hv.Curve((x, height), kdims=[x_dim], vdims=[y_dim]).opts(
            title=title, color=colour, width=PLOT_WIDTH, height=PLOT_HEIGHT,
            tools=["hover"], backend="bokeh")))
    return out


def report_layout(result: SceneSolution | PunchesSolution,
                  time: float | None = None) -> tuple[Any, list[str]]:
    """The report's plots as one ``holoviews.Layout`` (two a row, for a printed page) and
    their titles in order (what the PDF writes over them).

    ``time`` [day after loading]: its output time is drawn among the q(x) curves. Of
    several punches: :func:`core.report.punches.punches_layout`.
    """
    if isinstance(result, PunchesSolution):
        # here, not at the top: the punches' plots build on this module
        from core.report.punches import punches_layout

        return punches_layout(result, time)
    holoviews_for_bokeh("the report's plots")
    k = output_index(result, time)
    picked = shown_times(result.times)
    wanted = [float(result.times[j]) for j in sorted({*picked.tolist(), k})]
    layout = result.plot(times=wanted)
    extra: list[tuple[str, Any]] = []
    if lift_off_times(result).size:
        extra.append((contact_title(result), contact_overlay(result)))
    extra.extend(geometry_curves(result))
    titles = [*PLOT_TITLES, *(title for title, _ in extra)]
    items = [*layout, *(element for _, element in extra)]
    # every plot as wide as q(x)'s (its legend beside it): a narrower one in its column of
    # the page's grid was drawn a third as wide (the tilt's, ~120 px of plot on a 1500 px
    # page, its ticks overlapping; an engineer's audit)
    items = [items[0], *(item.opts(width=PRESSURE_WIDTH, backend="bokeh")
                         for item in items[1:])]
    # a clone keeps the layout's title (the scene and its flags)
    return layout.clone(items).cols(2), titles


def readings_overlay(result: SceneSolution, calibration: Any) -> Any:
    """The settlement history of ``result`` [mm] with the settlement readings of
    ``calibration`` (a :class:`core.back_analysis.Calibration`) as points, error bars of
    one standard deviation where given (HoloViews, Bokeh options)."""
    hv = holoviews_for_bokeh()
    readings = calibration.readings
    given = np.isfinite(readings.settlement)
    t = readings.time[given]
    v = readings.settlement[given] * 1e3
    curve = hv.Curve((result.times, result.settlement * 1e3), "t [days after loading]",
                     "settlement δ [mm]", label="fitted scene").opts(color="#1f77b4")
    points = hv.Scatter((t, v), "t [days after loading]", "settlement δ [mm]",
                        label="readings").opts(color="#111111", size=6)
    parts = [curve, points]
    if readings.settlement_std is not None:
        std = readings.settlement_std[given] * 1e3
        parts.append(hv.ErrorBars((t, v, std), "t [days after loading]",
                                  ["settlement δ [mm]", "std"]).opts(color="#111111"))
    return hv.Overlay(parts).opts(title="settlement δ(t): readings and the fitted scene",
                                  width=PLOT_WIDTH + 200, height=PLOT_HEIGHT,
                                  legend_position="top_left")
