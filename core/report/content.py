"""What a report says, independent of how it is printed: the sections an engineer files
with a check, as plain text rows (the HTML and PDF writers only lay them out)."""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from datetime import datetime, timezone
from typing import Any

import numpy as np

from core.coating import model_error_quantity
from core.report.contact import contact_text, lift_off_times, output_index
from core.report.inputs import SHOWN_UNITS, input_rows
from core.scene import (
    PunchesSolution,
    SceneSolution,
    answer_accuracy,
    days_text,
    engine_text,
    flagged_caution,
    flags_with_evidence,
    largest_pressure,
    model_error_evidence,
    number_text,
    percent_text,
    pressure_caution,
    thin_edge_note,
    time_of_largest,
)
from core.version import VERSION


@dataclass(frozen=True)
class Section:
    """A titled part of the report: a lead sentence, rows of (label, value), notes.

    ``tone`` is ``"bad"`` for a section that says the result must not be relied on
    (a failed check, a validity flag), ``"good"`` when it says all is well.
    """

    title: str
    lead: str = ""
    rows: list[tuple[str, str]] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    tone: str = ""


def _largest_pressure_text(result: Any, origin: float = 0.0) -> str:
    """The largest contact pressure, where and when (``origin + x`` [m]): unbounded at a
    rigid corner in contact, where the text says so (:func:`core.scene.largest_pressure`)."""
    line = largest_pressure(result)
    # (the short words: the long ones ran the PDF's text onto a fourth page)
    edge = thin_edge_note(line, result.scene.half_width, result.info.get("coating_model"),
                          short=True, dimensional=result.info.get("dimensional"))
    if line.x is not None and origin:
        line = replace(line, x=origin + line.x)
    text = line.value_text(number=number_text, shown=_shown, place_first=True, time=days_text)
    return f"{text} ({edge})" if edge else text


def _at(times: np.ndarray, values: np.ndarray, accuracy: float) -> tuple[float, float]:
    """The largest (by magnitude) value of a history and its time [day], when the design
    check and the page say it is (:func:`core.scene.time_of_largest` to the answer's
    ``accuracy``: a zero tilt read "at t = 0 days" here and "at t = 365 days" on the
    page)."""
    k = time_of_largest(values, accuracy)
    return float(values[int(np.nanargmax(np.abs(values)))]), float(times[k])


def _shown(value: float, si_unit: str) -> str:
    """``value`` [``si_unit``] in the unit the report shows it in (:data:`SHOWN_UNITS`)."""
    unit, size = SHOWN_UNITS[si_unit]
    return f"{number_text(value / size)} {unit}"


def key_numbers(result: SceneSolution, time: float | None = None,
                origin: float = 0.0) -> list[tuple[str, str]]:
    """The results in the units an engineer reads: largest over the history, with when;
    the contact at ``time`` [day] (default: the last output time) and, when the punch
    lifts off, when it does and the smallest contact width. Positions are ``origin + x``
    [m] (``x`` from the punch's centre; a punch of several: ``origin`` its centre)."""
    t = result.times
    accuracy = answer_accuracy(result.info)
    settlement, t_s = _at(t, result.settlement, accuracy)
    tilt, t_a = _at(t, result.tilt, accuracy)
    force, moment = float(result.force[-1]), float(result.moment[-1])
    # a computed moment within the answer's accuracy (at most ROUND_OFF_SHARE) of the
    # force's on the base is zero: the centred punch's round-off read "-1.113e-15
    # kN·m/m" and "e = -1.391e-18 m" (a given moment is the user's, shown as given)
    if "moment" not in result.scene.given and abs(moment) <= min(
            accuracy, ROUND_OFF_SHARE) * abs(force) * result.scene.half_width:
        moment = 0.0
    rows = [
        ("largest settlement δ", f"{_shown(settlement, 'm')} at t = {days_text(t_s)}"),
        ("largest tilt α", f"{_shown(tilt, 'rad')} at t = {days_text(t_a)}"),
        ("largest contact pressure q", _largest_pressure_text(result, origin)),
        ("force P at the last time", _shown(force, "N/m")),
        ("moment M at the last time", _shown(moment, "N")),
    ]
    if force != 0 and np.isfinite(force):
        rows.append(("eccentricity e = M/P at the last time",
                     f"{number_text(moment / force)} m"))
    k = output_index(result, time)
    # the output time nearest the one asked for, said so when it is another (365 days
    # asked read "contact at t = 379.6 days" with no word of why)
    nearest = ("" if time is None or abs(float(t[k]) - float(time)) <= 1e-9 * max(1.0, t[k])
               else f" (the output time nearest the {days_text(float(time))} asked for)")
    rows.append((f"contact at t = {days_text(t[k])}{nearest}",
                 contact_text(result, k, origin)))
    lifted = lift_off_times(result)
    if lifted.size:
        rows.append(("lift-off", f"at {lifted.size} of {len(t)} output times, first at "
                                 f"t = {days_text(t[lifted[0]])}, last at "
                                 f"t = {days_text(t[lifted[-1]])} (contact width plotted)"))
    if result.info.get("contact") == "unilateral" and result.contact_set:
        width = result.contact_width
        k = int(np.argmin(width))
        rows.append(("smallest contact width", f"{number_text(width[k])} m of "
                                               f"{number_text(2 * result.scene.half_width)} m at "
                                               f"t = {days_text(t[k])}"))
    return rows


def model_evidence(result: SceneSolution,
                   check: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """:func:`core.scene.model_error_evidence` of ``result``: the FE check's measurement
    when ``check`` was made for its scene, else the result's estimate."""
    return model_error_evidence(result.scene, float(result.model_error["estimate"]), check)


def _of_quantity(result: SceneSolution) -> str:
    """" of the moment M": whose error sets the coating model's estimate ("" when no one
    unknown's does)."""
    quantity = model_error_quantity(result.scene.given, result.model_error.get("part"))
    return f" of {quantity}" if quantity else ""


#: The unknowns' values in a report's line of the FE check: (unit, factor from SI).
_CHECK_UNITS = {"settlement": ("mm", 1e3), "tilt": ("rad", 1.0), "force": ("kN/m", 1e-3),
                "moment": ("kN·m/m", 1e-3)}


def _measured_of(result: SceneSolution, check: Mapping[str, Any]) -> str:
    """" of the settlement δ (0.083943 mm fast against 0.035653 mm resolved)": the unknown
    whose error the FE check measured (the largest of the two), with both answers (the
    report read "135 %" alone, where the page names it and shows both)."""
    errors, fast, fe = check.get("errors", {}), check.get("fast", {}), check.get("fe", {})
    unknowns = [q for q in _CHECK_UNITS if q not in result.scene.given and q in errors]
    if not unknowns:
        return ""
    name = max(unknowns, key=lambda q: abs(float(errors[q])))
    quantity = model_error_quantity(result.scene.given,
                                    "force" if name in ("settlement", "force") else "moment")
    unit, factor = _CHECK_UNITS[name]
    if name not in fast or name not in fe:
        return f" of {quantity}"
    return (f" of {quantity} ({number_text(factor * float(fast[name]), 5)} {unit} fast against "
            f"{number_text(factor * float(fe[name]), 5)} {unit} resolved)")


def accuracy_rows(result: SceneSolution,
                  check: Mapping[str, Any] | None = None) -> list[tuple[str, str]]:
    """The numerical error estimate against its target, and the coating model's error
    (measured by ``check``, a :func:`core.scene.check_scene` report of the scene, next
    to the estimate when it applies)."""
    info = result.info
    evidence = model_evidence(result, check)
    error = info.get("error_estimate")
    target = f" (target {result.scene.tol:g}: " + (
        "NOT met)" if "tol_not_met" in result.flags else "met)")
    return [
        ("numerical error (estimated, relative)",
         (f"{float(error):.1e}" if isinstance(error, (int, float)) else "not available")
         + target),
        # in percent, as the page and the command line write them (the report read
        # "1.8e-02" where the page read 1.81 %)
        *([(f"coating model error ({evidence['label']}, relative)",
            f"{percent_text(evidence['measured'])}{_measured_of(result, check)} at t = "
            f"{days_text(evidence['time_day'])} ("
            + ("FLAGGED: above " if evidence["flagged"] else "within ")
            + f"solver.model_tol {percent_text(result.scene.model_tol)})")]
          if evidence["source"] == "measured" and check is not None else []),
        ("coating model error (estimated, relative)",
         "0: no coating, no coating model" if not result.scene.coating else
         f"{percent_text(float(result.model_error['estimate']))}"
         + _of_quantity(result)
         # read off the map beyond what was measured, an estimate bounds nothing
         + (", EXTRAPOLATED beyond the measured map: no bound (run the coating check)"
            if "beyond_model_map" in result.flags and evidence["source"] != "measured" else
            " (" + ("FLAGGED: above " if float(result.model_error["estimate"])
                    > result.scene.model_tol else "within ")
            + f"solver.model_tol {percent_text(result.scene.model_tol)})")
         + ("; the FE check's measurement above overrides it"
            if evidence["source"] == "measured" else "")),
        *([("contact pressure against the FE model",
            f"{number_text(check['pressure_fast_Pa'] / 1e3)} kPa against "
            f"{number_text(check['pressure_fe_Pa'] / 1e3)} kPa at x = "
            f"{number_text(check['pressure_error_at_m'])} m, where they differ most: "
            f"{percent_text(check['errors']['pressure'])} of the largest pressure ("
            + ("FLAGGED: above " if check["errors"]["pressure"] > result.scene.model_tol
               else "within ") + f"solver.model_tol {percent_text(result.scene.model_tol)})")]
          if evidence["source"] == "measured" and "pressure_fe_Pa" in check else []),
        ("solved by", engine_text(result)),
        ("discretization", _discretization(info)),
        ("solver's message", str(info.get("message", ""))),
    ]


def _discretization(info: dict[str, Any]) -> str:
    """The sizes the solver chose (modes, nodes, panels, time steps), as it reported them."""
    sizes = [f"{info[key]} {word}" for key, word in (
        ("n_modes", "modes"), ("n_nodes", "nodes"), ("n_panels", "panels"),
        ("n_steps", "time steps")) if isinstance(info.get(key), (int, float))]
    return ", ".join(sizes) or "not reported"


def _check_line(line: Any) -> str:
    """A design-check line without its label: value, where, limit, utilisation, verdict,
    in the units of the results (kPa, mm, mrad)."""
    return line.verdict_text(number=number_text, shown=_shown, time=days_text)


def design_section(result: SceneSolution, flags: Sequence[str] | None = None,
                   fe_check: Mapping[str, Any] | None = None) -> Section | None:
    """The design check against the scene's limits, or None when the scene sets none;
    ``flags``: the answer's validity flags as the report shows them (default its own),
    under which the verdict is qualified (:func:`core.scene.flagged_caution`);
    ``fe_check``: an FE check made for this scene, whose pressure caution
    (:func:`core.scene.pressure_caution`) is noted (the command line warned of it, the
    report said nothing)."""
    check = result.design_check()
    if check is None:
        return None
    rows = [(line.label, _check_line(line)) for line in (*check.checks, check.q_min)]
    failed = check.passed is False
    caution = flagged_caution(result.flags if flags is None else flags)
    lead = "A limit is exceeded" if failed else "Every limit the scene sets holds"
    pressure = "" if fe_check is None else pressure_caution(fe_check)
    # (it qualifies a verdict on the pressure only: a scene limiting its settlement alone
    # is not turned red by it)
    limited = any(line.quantity == "q_max" and line.limit is not None
                  for line in check.checks)
    return Section("Design check", f"{lead}, {caution}." if caution else f"{lead}.", rows,
                   notes=[f"FE check: {pressure}"] if pressure else [],
                   tone="bad" if failed or caution or (pressure and limited) else "good")


#: A computed moment at most this share of the force's on the base (P a), within the
#: answer's accuracy, is round-off and reads 0 (a flagged answer's accuracy, up to 1e-3,
#: would have zeroed eccentricities of a millimetre a metre).
ROUND_OFF_SHARE = 1e-6
#: The confidence of the fitted values' intervals the report gives.
INTERVAL_LEVEL = 0.95


def calibration_section(calibration: Any) -> Section:
    """The back-analysis: the readings fitted, each fitted value with its standard error
    (in the field's unit), the correlations, chi^2/dof and the fit's warnings.

    ``calibration`` is a :class:`core.back_analysis.Calibration` (read by its attributes:
    the report sits below the back-analysis in core's layers)."""
    readings = calibration.readings
    values, errors, units = (calibration.values, calibration.standard_errors,
                             calibration.units)
    series = ", ".join(f"{name} [{SERIES_SI[name]}]" for name in readings.series)
    rows = [("readings", f"{readings.count} ({series}), t = {number_text(float(readings.time[0]))}"
                         f" to {days_text(float(readings.time[-1]))}"
                         + (", with standard deviations" if calibration.std_given else ""))]
    # (the page's column; the report had none)
    intervals = calibration.determined_intervals(INTERVAL_LEVEL)
    level = f"{100 * INTERVAL_LEVEL:g}"
    for path in calibration.paths:
        unit = f" {units[path]}" if units[path] else ""
        shown = intervals[path]
        # (as the Fit tab says it, where "0 to not finite Pa" and, at a bound, an
        # interval past it were read)
        interval = (calibration.not_determined if shown is None
                    else f"{number_text(shown[0], 4)} to {number_text(shown[1], 4)}{unit}")
        rows.append((path, f"{number_text(values[path], 6)} ± {number_text(errors[path], 2)}{unit}"
                           f" ({level} % interval {interval}; start "
                           f"{number_text(calibration.start[path], 6)}{unit})"))
    corr = calibration.correlation
    paths = calibration.paths
    for j in range(len(paths)):
        for k in range(j + 1, len(paths)):
            value = float(corr[j, k])
            rows.append((f"correlation {paths[j]} ~ {paths[k]}",
                         f"{value:+.3f}" if np.isfinite(value) else "not finite"))
    if calibration.std_given:
        rows.append(("χ²/dof", f"{calibration.chi2_text}; the readings' standard deviations"))
    else:  # no chi^2 without deviations (Calibration.chi2_per_dof)
        noise = ", ".join(f"{name} {number_text(v, 3)} {SERIES_SI[name]}"
                          for name, v in calibration.noise.items())
        rows.append(("noise", f"estimated from the scatter about the fit "
                              f"({calibration.dof} dof): {noise}"))
    warned = bool(calibration.warnings)
    lead = (f"{len(paths)} field(s) fitted to the readings (weighted least squares; "
            "standard errors from the linearised covariance)."
            + (" The fit warns: its values may not be determined." if warned else ""))
    return Section("Back-analysis", lead, rows,
                   notes=[f"warning: {w}" for w in calibration.warnings],
                   tone="bad" if warned else "")


#: The SI units of the series of readings.
SERIES_SI = {"settlement": "m", "tilt": "rad"}


def sections(result: SceneSolution | PunchesSolution, time: float | None = None,
             check: Mapping[str, Any] | None = None,
             calibration: Any = None) -> list[Section]:
    """The report's sections, in order; ``time`` [day after loading]: the output time
    nearest to it is the one whose contact the results describe (default: the last);
    ``check``: a :func:`core.scene.check_scene` report; made for this scene, its measured
    coating-model error overrides the estimate (the ``model_error`` flag, the accuracy);
    ``calibration``: a :class:`core.back_analysis.Calibration` of the scene, reported in
    a section "Back-analysis" after the results. Of several punches
    (:class:`core.scene.PunchesSolution`): :func:`core.report.punches.punches_sections`
    (a results section per punch; ``check`` and ``calibration`` are of one punch and
    refused).

    Raises
    ------
    ValueError
        When ``time`` is not within the output times (naming ``time``); ``check`` or
        ``calibration`` given with several punches.
    """
    if isinstance(result, PunchesSolution):
        # here, not at the top: the report of several punches builds on this module
        from core.report.punches import punches_sections, refuse_single_punch_options

        refuse_single_punch_options(check, calibration)
        return punches_sections(result, time)
    scene = result.scene
    stamp = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    out = [Section("About", rows=[
        ("scene", str(scene.name or "unnamed")),
        ("statement", f"{scene.statement}: " + " and ".join(
            q for q in ("settlement", "tilt", "force", "moment") if q in scene.given)
            + " given"),
        ("made by", f"coated-punch {VERSION}, {stamp}"),
        ("units", "plane strain, per metre out of plane; x in m from the punch centre; "
                  "t in days after loading; pressure in kPa (the plots: kPa or MPa, as "
                  "their axes say), compression positive; "
                  "settlement mm, tilt mrad, force kN/m, moment kN·m/m; the scene file "
                  "in SI"),
    ])]
    evidence = model_evidence(result, check)
    flags = flags_with_evidence(result.flags, evidence)
    messages = {**result.flag_messages, "model_error": evidence["message"]}
    if flags:
        out.append(Section("Validity", "This result is flagged: the model cannot fully "
                           "stand behind it.",
                           [(name, messages[name]) for name in flags],
                           tone="bad"))
    else:
        out.append(Section("Validity", "No validity flag: the model stands behind this "
                           "result.", tone="good"))
    design = design_section(result, flags,
                            check if evidence["source"] == "measured" else None)
    if design is not None:
        out.append(design)
    out.append(Section("Results", rows=key_numbers(result, time)))
    if calibration is not None:
        out.append(calibration_section(calibration))
    out.append(Section("Accuracy", rows=accuracy_rows(result, check)))
    out.append(Section("Inputs", rows=input_rows(scene)))
    return out


def scene_json(result: SceneSolution) -> str:
    """The scene file (canonical JSON), to be filed with the report."""
    return json.dumps(result.scene.to_dict(), indent=1, allow_nan=False)


def describe(result: SceneSolution, time: float | None = None,
             check: Mapping[str, Any] | None = None,
             calibration: Any = None) -> dict[str, Any]:
    """The report's text as one JSON-able dict (what the tests read)."""
    return {s.title: {"lead": s.lead, "rows": dict(s.rows), "tone": s.tone, "notes": s.notes}
            for s in sections(result, time, check, calibration)}
