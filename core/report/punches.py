"""The report of several punches on one foundation (:class:`core.scene.PunchesSolution`):
the same parts as the report of one punch, said of every punch.

Each punch of several is a single-punch answer (:class:`core.scene.PunchSolution`) in
its own coordinates, so the single punch's rows serve it: :func:`key_numbers`,
:func:`accuracy_rows` and :func:`input_rows` of each punch, positions moved to the global
x by its centre. What all punches share (the coating when it is uniform, the base, the
times, the solver) is said once; the rest once per punch, named ``punches[k]``. The
plots: q(x) over the whole surface at a few times (q = 0 on the free surface between the
punches, every punch's zone shaded) and the histories with a line per punch.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from datetime import datetime, timezone
from typing import Any

import numpy as np

from core.report.contact import lifted_parts, output_index
from core.report.content import Section, accuracy_rows, key_numbers
from core.report.inputs import SHOWN_UNITS, input_rows
from core.report.plots import (
    PLOT_HEIGHT,
    PLOT_WIDTH,
    ZONE_COLOUR,
    ZONE_GROUP,
)
from core.scene import (
    LIFT_OFF_COLOUR,
    PUNCH_COLOURS,
    PunchesSolution,
    PunchSolution,
    days_text,
    flagged_caution,
    holoviews_for_bokeh,
    number_text,
    pressure_unit,
    shown_times,
    time_colours,
)
from core.version import VERSION

#: The histories drawn, with their symbol and SI unit; force and moment only where some
#: punch's varies (a given constant load is a flat line the inputs already state).
HISTORIES = (("settlement", "δ", "m"), ("tilt", "α", "rad"), ("force", "P", "N/m"),
             ("moment", "M", "N"))
#: Rows of a punch's inputs that are its own (the rest, when alike for every punch, is
#: said once): its base and its loads.
OWN_INPUTS = ("punch", "(given)")
#: Width of a plot of several punches [screen pixels]: a plot of one punch's and its
#: legend beside it (times, or punches); two a row fit the page.
WIDTH = PLOT_WIDTH + 120


def refuse_single_punch_options(check: Mapping[str, Any] | None, calibration: Any) -> None:
    """The FE check and a back-analysis are of one punch: refused for several, naming
    the argument."""
    if check is not None:
        raise ValueError("check: the finite-element check is of one punch; run it on a "
                         "punch's own scene (result.punches[k].scene)")
    if calibration is not None:
        raise ValueError("calibration: a back-analysis is of one punch; a scene of several "
                         "punches is reported without it")


def local_view(punch: PunchSolution) -> PunchSolution:
    """``punch`` with its contact set in its own coordinates (``x - center`` [m]), as
    every other length of it: what the single punch's rows read (they are told the
    centre to write positions in the global x)."""
    view = copy.copy(punch)
    c = punch.center
    view.contact_set = [[(lo - c, hi - c) for lo, hi in zones] for zones in punch.contact_set]
    return view


def _name(k: int, punch: PunchSolution) -> str:
    return f"punches[{k}] at x = {number_text(punch.center)} m"


def _shown(value: float, si_unit: str) -> str:
    unit, size = SHOWN_UNITS[si_unit]
    return f"{number_text(value / size)} {unit}"


def _at_time(punch: PunchSolution, k: int) -> str:
    """Settlement, tilt, force and moment of ``punch`` at ``times[k]``, in shown units."""
    return ", ".join(f"{symbol} = {_shown(float(getattr(punch, name)[k]), unit)}"
                     for name, symbol, unit in HISTORIES)


def _merged(per_punch: list[list[tuple[str, str]]], own: tuple[str, ...] = ()
            ) -> tuple[list[tuple[str, str]], list[list[tuple[str, str]]]]:
    """Rows alike for every punch (said once, in the first punch's order) and each
    punch's other rows; a row whose label contains one of ``own`` is always the punch's."""
    def is_own(label: str) -> bool:
        return any(word in label for word in own)

    common = [row for row in per_punch[0]
              if not is_own(row[0]) and all(row in rows for rows in per_punch[1:])]
    return common, [[row for row in rows if row not in common] for rows in per_punch]


def punches_sections(result: PunchesSolution, time: float | None = None) -> list[Section]:
    """The report's sections for several punches, in order: about, validity, the design
    check of each punch (when the scene sets limits), the results of each punch at the
    output time nearest to ``time`` [day] (default: the last), accuracy and inputs.

    Raises ValueError naming ``time`` when it is not within the output times.
    """
    k_t = output_index(result, time)
    scene, punches = result.scene, result.punches
    t = float(result.times[k_t])
    stamp = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    statements = "; ".join(
        f"punches[{k}] {p.scene.statement}: " + " and ".join(
            q for q in ("settlement", "tilt", "force", "moment") if q in p.scene.given)
        + " given" for k, p in enumerate(punches))
    out = [Section("About", rows=[
        ("scene", str(scene.name or "unnamed")),
        ("punches", f"{len(punches)} rigid punches on one foundation, acting on each other "
                    "through the base"),
        ("statements", statements),
        ("made by", f"coated-punch {VERSION}, {stamp}"),
        ("units", "plane strain, per metre out of plane; x in m along the surface (the "
                  "scene file's x: each punch at its centre); t in days after loading; "
                  "pressure in kPa (the plots: kPa or MPa, as their axes say), compression "
                  "positive; settlement mm, tilt mrad, force "
                  "kN/m, moment kN·m/m about each punch's own centre; the scene file in SI"),
    ])]
    flagged = [(f"punches[{k}].{name}", p.flag_messages.get(name, ""))
               for k, p in enumerate(punches) for name in p.flags]
    out.append(Section("Validity", "This result is flagged: the model cannot fully stand "
                       "behind it.", flagged, tone="bad") if flagged else
               Section("Validity", "No validity flag on any punch: the model stands "
                       "behind this result.", tone="good"))
    checks = result.design_checks()
    if any(check is not None for check in checks):
        rows = [(f"punches[{k}] {line.label}",
                 line.verdict_text(number=number_text, shown=_shown, time=days_text))
                for k, check in enumerate(checks) if check is not None
                for line in (*check.checks, check.q_min)]
        failed = [f"punches[{k}]" for k, check in enumerate(checks)
                  if check is not None and check.passed is False]
        caution = flagged_caution(result.flags)
        lead = (f"A limit is exceeded under {', '.join(failed)}" if failed else
                "Every limit the scene sets holds under every punch")
        out.append(Section("Design check", f"{lead}, {caution}." if caution else f"{lead}.",
                           rows, tone="bad" if failed or caution else "good"))
    for k, punch in enumerate(punches):
        view = local_view(punch)
        rows = [("zone", _zone(punch)), (f"at t = {days_text(t)}", _at_time(punch, k_t)),
                *key_numbers(view, time, origin=punch.center),
                ("flags", ", ".join(punch.flags) or "none")]
        out.append(Section(f"Results: {_name(k, punch)}", rows=rows,
                           tone="bad" if punch.flags else ""))
    common, own = _merged([accuracy_rows(local_view(p)) for p in punches])
    out.append(Section("Accuracy", rows=common + [
        (f"punches[{k}] {label}", value) for k, rows in enumerate(own) for label, value in rows]))
    common, own = _merged([input_rows(p.scene) for p in punches], OWN_INPUTS)
    rows = list(common)
    for k, (punch, own_rows) in enumerate(zip(punches, own, strict=True)):
        for label, value in own_rows:
            # the punch's row (its half-width and base) leads with its centre
            rows.append((f"punches[{k}]", f"centre x = {number_text(punch.center)} m, {value}")
                        if label == "punch" else (f"punches[{k}] {label}", value))
    out.append(Section("Inputs", rows=rows))
    return out


# ------------------------------------------------------------------------------ plots


def _surface_curve(result: PunchesSolution, j: int) -> tuple[np.ndarray, np.ndarray]:
    """q [Pa] at ``times[j]`` along the surface: every punch's grid in the global x, and
    q = 0 on the free surface between neighbours (drawn from edge to edge)."""
    xs: list[np.ndarray] = []
    qs: list[np.ndarray] = []
    for k in sorted(range(len(result.punches)), key=lambda i: result.punches[i].center):
        punch = result.punches[k]
        x, q = punch.center + punch.x, punch.pressure_on_grid[:, j]
        if xs:
            xs.append(np.array([xs[-1][-1], x[0]]))
            qs.append(np.zeros(2))
        xs.append(x)
        qs.append(q)
    return np.concatenate(xs), np.concatenate(qs)


def surface_overlay(result: PunchesSolution, time: float | None = None) -> Any:
    """q(x) [kPa or MPa] over the whole surface at a few output times and at the one
    nearest to ``time``, coloured by time; every punch's zone shaded, and where a punch
    lifts off at that time, the part lifted."""
    hv = holoviews_for_bokeh("the report's plots")
    k_t = output_index(result, time)
    picked = sorted({*shown_times(result.times).tolist(), k_t})
    curves = [_surface_curve(result, j) for j in picked]
    largest = max(float(np.max(np.abs(q))) for _, q in curves) if curves else 0.0
    unit, size = pressure_unit(largest)
    colours = time_colours(len(picked))
    x_dim = hv.Dimension("x", label="x", unit="m")
    q_dim = hv.Dimension("q", label="q", unit=unit)
    elements = [hv.VSpan(p.center - p.scene.half_width, p.center + p.scene.half_width,
                         group=ZONE_GROUP).opts(color=ZONE_COLOUR, alpha=0.5, backend="bokeh")
                for p in result.punches]
    for punch in result.punches:
        for lo, hi in lifted_parts(local_view(punch), k_t):
            elements.append(hv.VSpan(punch.center + lo, punch.center + hi).opts(
                color=LIFT_OFF_COLOUR, alpha=0.5, backend="bokeh"))
    elements += [hv.Curve((x, q / size), kdims=[x_dim], vdims=[q_dim],
                          label=f"t = {days_text(float(result.times[j]))}")
                 .opts(color=colours[i], tools=["hover"], backend="bokeh")
                 for i, (j, (x, q)) in enumerate(zip(picked, curves, strict=True))]
    return hv.Overlay(elements).opts(
        title=surface_title(result), xlabel=x_dim.pprint_label, ylabel=q_dim.pprint_label,
        width=WIDTH, height=PLOT_HEIGHT, legend_position="right", backend="bokeh")


def surface_title(result: PunchesSolution) -> str:
    """The title of the q(x) plot over the surface (the zones are in each punch's
    results)."""
    return f"contact pressure q(x, t), {len(result.punches)} punches (zones shaded)"


def _zone(punch: PunchSolution) -> str:
    a = punch.scene.half_width
    return (f"x = {number_text(punch.center - a)} to {number_text(punch.center + a)} m "
            "(shaded in q(x))")


def history_overlay(result: PunchesSolution, name: str, symbol: str, si_unit: str) -> Any:
    """``name`` over time [shown unit] with a line per punch, in the punches' colours."""
    hv = holoviews_for_bokeh("the report's plots")
    unit, size = SHOWN_UNITS[si_unit]
    t_dim = hv.Dimension("time", label="t", unit="day")
    v_dim = hv.Dimension(name, label=f"{name} {symbol}", unit=unit)
    curves = [hv.Curve((result.times, np.asarray(getattr(p, name)) / size), kdims=[t_dim],
                       vdims=[v_dim], label=f"punches[{k}]")
              .opts(color=PUNCH_COLOURS[k % len(PUNCH_COLOURS)], tools=["hover"],
                    backend="bokeh")
              for k, p in enumerate(result.punches)]
    return hv.Overlay(curves).opts(title=f"{name} {symbol}(t)", width=WIDTH,
                                   height=PLOT_HEIGHT, legend_position="right",
                                   backend="bokeh")


def punches_layout(result: PunchesSolution, time: float | None = None
                   ) -> tuple[Any, list[str]]:
    """The plots of several punches as one ``holoviews.Layout`` and their titles in
    order: q(x) over the surface, then the settlement and the tilt with a line per punch
    (and the force and the moment where some punch's varies)."""
    hv = holoviews_for_bokeh("the report's plots")
    plots = [(surface_title(result), surface_overlay(result, time))]
    for name, symbol, unit in HISTORIES:
        varies = any(np.ptp(getattr(p, name)) > 0 for p in result.punches)
        if name in ("settlement", "tilt") or varies:
            plots.append((f"{name} {symbol}(t)", history_overlay(result, name, symbol, unit)))
    title = result.scene.name + (f": flags {', '.join(result.flags)}" if result.flags else "")
    layout = hv.Layout([element for _, element in plots]).cols(2).opts(title=title,
                                                                     backend="bokeh")
    return layout, [t for t, _ in plots]
