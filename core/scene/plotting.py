"""Plots of a :class:`~core.scene.SceneSolution` (and of several punches' answer) with
HoloViews: the contact pressure q(x) at several times coloured by time, the settlement
and the tilt over time, flags and lift-off in the titles.

The only module of :mod:`core` that imports HoloViews, and only when a plot is asked for
(``import core`` stays free of it). The plots carry options of the Bokeh backend, which
is registered here if no ``hv.extension`` did it.
"""

from __future__ import annotations

import importlib
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from core.optional import import_optional
from core.scene.display import days_text, lifts_off_at, zones_text

if TYPE_CHECKING:
    import holoviews

    from core.scene.punches import PunchesSolution
    from core.scene.results import SceneSolution

#: q(x) curves drawn when no times are asked for.
PLOT_CURVES = 6
#: Units of the pressure axis, the first that the largest |q| reaches: (unit, Pa in it).
PRESSURE_UNITS: tuple[tuple[str, float], ...] = (("MPa", 1e6), ("kPa", 1e3), ("Pa", 1.0))
#: The colour map of the q(x) curves, early to late (its palest end is left out: on a
#: white page the latest curve must stay visible).
TIME_COLOURS = "viridis"
#: Size of each plot of the layout [screen pixels]; the pressure's is wider for its legend.
PLOT_WIDTH, PLOT_HEIGHT, PRESSURE_WIDTH = 400, 300, 580
#: The titles of the plots (the paper's symbols).
TITLES = {"pressure": "contact pressure q(x, t)", "settlement": "settlement δ(t)",
          "tilt": "tilt α(t)"}
#: The shade of the parts of the base that lift off at the last time.
LIFT_OFF_COLOUR = "#d9d9d9"


def holoviews_for_bokeh(feature: str = "SceneSolution.plot") -> Any:
    """HoloViews with its Bokeh backend registered (no notebook output, unlike
    ``hv.extension``, and the current backend is left as it was); ``feature`` names what
    needs them in the error when either is missing."""
    hv = import_optional("holoviews", feature)
    import_optional("bokeh", feature)
    if "bokeh" not in hv.Store.renderers:
        importlib.import_module("holoviews.plotting.bokeh")
    return hv


def pressure_unit(q_max: float) -> tuple[str, float]:
    """The unit of the pressure axis for pressures up to ``q_max`` [Pa], and its size [Pa]."""
    for unit, size in PRESSURE_UNITS:
        if abs(q_max) >= size:
            return unit, size
    return PRESSURE_UNITS[-1]


def time_colours(count: int) -> list[str]:
    """The colours of ``count`` q(x) curves, early to late (:data:`TIME_COLOURS` without
    its palest end)."""
    from holoviews.plotting.util import process_cmap

    return process_cmap(TIME_COLOURS, count + 1)[:count]


def shown_times(times: np.ndarray, count: int = PLOT_CURVES,
                wanted: Sequence[float] | None = None) -> np.ndarray:
    """Indices of the output times to draw: the ones nearest to ``wanted`` [day], else
    ``count`` spread evenly over the indices (the first and the last among them)."""
    if wanted is not None:
        picked = [int(np.argmin(np.abs(times - float(t)))) for t in wanted]
    else:
        picked = np.linspace(0, len(times) - 1, max(1, min(count, len(times)))).round()
    return np.unique(np.asarray(picked, dtype=int))


def _days(t: float) -> str:
    return f"t = {days_text(t)}"


def _lift_off_spans(hv: Any, result: SceneSolution) -> list[Any]:
    """Shaded spans where the base lifts off at the last time."""
    a = result.scene.half_width
    ends = [-a] + [e for zone in result.contact_set[-1] for e in zone] + [a]
    return [hv.VSpan(lo, hi).opts(color=LIFT_OFF_COLOUR, alpha=0.5, backend="bokeh")
            for lo, hi in zip(ends[::2], ends[1::2], strict=True) if hi > lo]


def pressure_overlay(result: SceneSolution, count: int = PLOT_CURVES,
                     times: Sequence[float] | None = None) -> holoviews.Overlay:
    """q(x) [kPa or MPa] against x [m] at some of the output times, coloured by time."""
    hv = holoviews_for_bokeh()
    picked = shown_times(result.times, count, times)
    q = result.pressure_on_grid[:, picked]
    unit, size = pressure_unit(float(np.max(np.abs(q))) if q.size else 0.0)
    colours = time_colours(len(picked))
    x_dim = hv.Dimension("x", label="x", unit="m")
    q_dim = hv.Dimension("q", label="q", unit=unit)
    curves = [hv.Curve((result.x, q[:, j] / size), kdims=[x_dim], vdims=[q_dim],
                       label=_days(result.times[k]))
              .opts(color=colours[j], tools=["hover"], backend="bokeh")
              for j, k in enumerate(picked)]
    title = TITLES["pressure"]
    spans: list[Any] = []
    # (a second line: one line was cut at the plot's width, e.g. "... contact on [-0.3486,")
    if lifts_off_at(result):
        title += f"\nlift-off at {_days(result.times[-1])}: contact on {zones_text(result)} m"
        spans = _lift_off_spans(hv, result)
    if result.contact_lost:
        title += "\ncontact lost (q < 0: not physical)"
    # the axes are labelled here: the spans' own dimensions (x, y) would name them
    return hv.Overlay(curves + spans).opts(
        title=title, xlabel=x_dim.pprint_label, ylabel=q_dim.pprint_label,
        width=PRESSURE_WIDTH, height=PLOT_HEIGHT, legend_position="right", backend="bokeh")


def history_curve(result: SceneSolution, name: str, factor: float,
                  unit: str) -> holoviews.Curve:
    """``name`` (an attribute of ``result`` over time) times ``factor``, in ``unit``."""
    hv = holoviews_for_bokeh()
    t_dim = hv.Dimension("time", label="t", unit="day")
    v_dim = hv.Dimension(name, label=name, unit=unit)
    values = np.asarray(getattr(result, name)) * factor
    return hv.Curve((result.times, values), kdims=[t_dim], vdims=[v_dim]).opts(
        title=TITLES[name], width=PLOT_WIDTH, height=PLOT_HEIGHT, tools=["hover"],
        backend="bokeh")


def plot_solution(result: SceneSolution, count: int = PLOT_CURVES,
                  times: Sequence[float] | None = None) -> holoviews.Layout:
    """A HoloViews layout of ``result``: q(x) at ``count`` output times (or those nearest
    to ``times`` [day]) coloured by time, the settlement [mm] and the tilt [mrad] over
    time; the flags in the layout's title, lift-off in the pressure's."""
    hv = holoviews_for_bokeh()
    layout = hv.Layout([pressure_overlay(result, count, times),
                        history_curve(result, "settlement", 1e3, "mm"),
                        history_curve(result, "tilt", 1e3, "mrad")]).cols(3)
    title = result.scene.name
    if result.flags:
        title += ": flags " + ", ".join(result.flags)
    return layout.opts(title=title, backend="bokeh")


#: The colours of the punches of several, in order (a line per punch in the histories;
#: the plots here and the report's).
PUNCH_COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2",
                 "#17becf", "#7f7f7f")


def plot_punches(result: PunchesSolution, count: int = PLOT_CURVES,
                 times: Sequence[float] | None = None) -> holoviews.Layout:
    """A HoloViews layout of an answer for several punches: q(x) [kPa or MPa] over the
    surface (the global x [m]; each punch's plotting grid, q = 0 between them) at ``count``
    output times (or those nearest to ``times`` [day]) coloured by time, and the
    settlement [mm] and the tilt [mrad] over time with a line per punch; the flags in the
    layout's title."""
    hv = holoviews_for_bokeh("PunchesSolution.plot")
    picked = shown_times(result.times, count, times)
    x = result.x
    q = result.pressure_on_grid[:, picked]
    unit, size = pressure_unit(float(np.max(np.abs(q))) if q.size else 0.0)
    colours = time_colours(len(picked))
    x_dim = hv.Dimension("x", label="x", unit="m")
    q_dim = hv.Dimension("q", label="q", unit=unit)
    curves = [hv.Curve((x, q[:, j] / size), kdims=[x_dim], vdims=[q_dim],
                       label=_days(result.times[k]))
              .opts(color=colours[j], tools=["hover"], backend="bokeh")
              for j, k in enumerate(picked)]
    pressure = hv.Overlay(curves).opts(
        title=f"{TITLES['pressure']}, {len(result.punches)} punches", width=PRESSURE_WIDTH,
        height=PLOT_HEIGHT, legend_position="right", backend="bokeh")
    t_dim = hv.Dimension("time", label="t", unit="day")
    plots = [pressure]
    for name, factor, shown in (("settlement", 1e3, "mm"), ("tilt", 1e3, "mrad")):
        v_dim = hv.Dimension(name, label=name, unit=shown)
        lines = [hv.Curve((result.times, np.asarray(getattr(p, name)) * factor),
                          kdims=[t_dim], vdims=[v_dim], label=f"punches[{k}]")
                 .opts(color=PUNCH_COLOURS[k % len(PUNCH_COLOURS)],
                       tools=["hover"], backend="bokeh")
                 for k, p in enumerate(result.punches)]
        plots.append(hv.Overlay(lines).opts(title=TITLES[name], width=PLOT_WIDTH,
                                            height=PLOT_HEIGHT, legend_position="right",
                                            backend="bokeh"))
    title = result.scene.name + (f": flags {', '.join(result.flags)}" if result.flags
                                 else "")
    return hv.Layout(plots).cols(3).opts(title=title, backend="bokeh")
