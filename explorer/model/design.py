"""The design check: the numbers an engineer files for a footing, and pass or fail.

:func:`design_check` reads a :class:`~explorer.model.results.ResultView` (no solve): the largest
and smallest contact pressure over the whole history and where and when they occur, the
smallest contact width (the core's, :func:`core.scene.contact_width`: ``2a`` for a
full-contact answer, even one that lost contact), the eccentricity ``e = M/P``, and the
largest settlement and tilt, each compared with a limit the user sets
(:class:`DesignLimits`). The check itself is the core's
(:func:`core.scene.check_design`, the one the command line and scene files' ``limits``
use); this module holds the screen's units and the limits as the Check tab sets them.
Nothing here imports Panel.
"""

from __future__ import annotations

import html
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import param

from core.scene import DesignLimits as CoreLimits
from core.scene import (
    LimitCheck,
    answer_accuracy,
    check_design,
    days_text,
    flagged_caution,
    number_text,
    thin_edge_note,
)

from .contact_zone import contact_widths, punch_contact_widths
from .results import ResultView
from .state import QUANTITY_UNITS


class DesignLimits(param.Parameterized):
    """What the design must not exceed; ``None``: not checked."""

    allowable_pressure = param.Number(default=None, allow_None=True, bounds=(0, None),
                                      doc="Allowable bearing pressure [kPa].")
    settlement_limit = param.Number(default=None, allow_None=True, bounds=(0, None),
                                    doc="Largest settlement allowed [mm].")
    tilt_limit = param.Number(default=None, allow_None=True, bounds=(0, None),
                              doc="Largest tilt allowed, either way [mrad].")

    def take(self, spec: Mapping[str, Any] | None) -> None:
        """Take a scene file's (or a link's) ``limits`` (Pa, m, rad), when it has some:
        all three, one it leaves out not checked; a scene without limits leaves these."""
        if spec:
            self.param.update(**screen_limits(spec))


@dataclass
class Check:
    """One line of the check: a value, its limit (None: not set) and the verdict
    (``passed``, from the core's check; None: no limit)."""

    name: str
    value: float
    unit: str
    where: str
    limit: float | None = None
    passed: bool | None = None
    #: [mm] an unbounded pressure (a rigid corner in contact): how far from the corner
    #: ``value`` is read (None: bounded), and where q exceeds the limit, in words
    #: (:meth:`core.scene.LimitCheck.exceeded_text`)
    corner_distance: float | None = None
    exceeded: str = ""

    @property
    def verdict(self) -> str:
        if self.limit is None:
            return "no limit set"
        return "pass" if self.passed else "FAIL"


@dataclass
class DesignCheck:
    """The summary of one result (pressures in kPa, lengths in m, as on screen)."""

    q_max: Check
    q_min: Check
    contact_width: float           # [m], the smallest over the history, of the full width 2a
    full_width: float              # [m]
    eccentricity: float | None     # e = M/P [m] at the end of the history (None: P <= 0)
    checks: list[Check] = field(default_factory=list)
    #: [day after loading] when the contact is narrowest (None: not known)
    narrowest_time: float | None = None
    #: the answer's validity flags: a verdict on a flagged answer is qualified
    flags: list[str] = field(default_factory=list)
    #: what the largest pressure is when it is the thin coating model's at a punch's
    #: edge (:func:`core.scene.thin_edge_note`; "" otherwise)
    edge_note: str = ""

    @property
    def passed(self) -> bool | None:
        """True: every set limit holds; False: one fails; None: no limit set."""
        verdicts = [c.verdict for c in self.checks if c.limit is not None]
        if not verdicts:
            return None
        return all(v == "pass" for v in verdicts)


#: The screen's unit of each quantity of the core's check: (unit, its size in SI).
_SCREEN_UNITS: dict[str, tuple[str, float]] = {
    "q_max": ("kPa", 1e3), "q_min": ("kPa", 1e3),
    "settlement": QUANTITY_UNITS["settlement"], "tilt": QUANTITY_UNITS["tilt"]}


#: The session's limits: (field of :class:`DesignLimits`, quantity it bounds).
_LIMITS = (("allowable_pressure", "q_max"), ("settlement_limit", "settlement"),
           ("tilt_limit", "tilt"))


def core_limits(limits: DesignLimits | None) -> CoreLimits:
    """The session's limits (kPa, mm, mrad) as the core's (Pa, m, rad)."""
    if limits is None:
        return CoreLimits()
    values = {}
    for name, quantity in _LIMITS:
        value = getattr(limits, name)
        values[name] = None if value is None else value * _SCREEN_UNITS[quantity][1]
    return CoreLimits(**values)


def screen_limits(spec: Mapping[str, Any] | None) -> dict[str, float | None]:
    """A scene file's ``limits`` (Pa, m, rad; assumed valid) as the Check tab's values
    (kPa, mm, mrad); a limit the file leaves out is None."""
    spec = spec or {}
    return {name: None if spec.get(name) is None
            else float(spec[name]) / _SCREEN_UNITS[quantity][1]
            for name, quantity in _LIMITS}


def scene_limits(limits: DesignLimits | None) -> dict[str, float]:
    """The session's limits as a scene file's ``limits`` (Pa, m, rad; only those set)."""
    return core_limits(limits).to_dict()


def scene_with_limits(scene: dict[str, Any], limits: DesignLimits | None) -> dict[str, Any]:
    """``scene`` (a scene dict, not changed) with the session's limits as its ``limits``,
    as the command line checks them (Pa, m, rad); without a limit set, without any."""
    out = {key: value for key, value in scene.items() if key != "limits"}
    checked = scene_limits(limits)
    if checked:
        out["limits"] = checked
    return out


def _on_screen(line: LimitCheck, limits: DesignLimits | None) -> Check:
    """A line of the core's check in the screen's units, with the limit as typed."""
    unit, size = _SCREEN_UNITS[line.quantity]
    where = f"t = {days_text(line.time)}" + (" and after" if line.held else "")
    if line.x is not None:
        where = f"x = {line.x:.3g} m, " + where
    if line.sign_note:
        where += f" ({line.sign_note})"
    typed = None if limits is None or line.limit_name is None \
        else getattr(limits, line.limit_name)
    if line.unbounded:
        return Check(line.label, line.value / size, unit, where, typed, line.passed,
                     corner_distance=1e3 * float(line.corner_distance),
                     exceeded=line.exceeded_text())
    return Check(line.label, line.value / size, unit, where, typed, line.passed)


def design_check(view: ResultView, limits: DesignLimits | None = None,
                 flags: list[str] | None = None) -> DesignCheck:
    """The design check of ``view`` over its whole history, against ``limits``: the
    core's check (:func:`core.scene.check_design`) in the screen's units, with the
    contact width and the eccentricity the screen shows beside it; ``flags``: the
    result's as the page shows them (default: the answer's own)."""
    verdict = view_verdict(view, core_limits(limits))
    # (one punch: several draw their pressure over the whole surface, in global x)
    edge = "" if view.punches else thin_edge_note(
        verdict.checks[0], view.geometry.half_width, view.info.get("coating_model"),
        dimensional=view.info.get("dimensional"))
    return _on_screen_check(verdict, limits, view.times, contact_widths(view),
                            2 * view.geometry.half_width, view.values,
                            list(view.flags if flags is None else flags), edge)


def punch_design_checks(view: ResultView, limits: DesignLimits | None = None
                        ) -> list[DesignCheck]:
    """The design check of each punch of a scene of several (:func:`design_check` of
    each: its pressure on its own grid in the global x, its settlement and tilt about its
    own centre, dated to its answer's accuracy), as the core checks them
    (``PunchesSolution.design_checks``); empty for a scene of one punch."""
    return [_on_screen_check(verdict, limits, view.times, punch_contact_widths(p),
                             2 * p.half_width, p.values, list(p.flags))
            for p, verdict in zip(view.punches, punch_verdicts(view, core_limits(limits)),
                                  strict=True)]


def _on_screen_check(verdict: Any, limits: DesignLimits | None, times: np.ndarray,
                     widths: np.ndarray, full_width: float, values: Mapping[str, Any],
                     flags: list[str], edge: str = "") -> DesignCheck:
    """The core's ``verdict`` in the screen's units, with the narrowest contact of
    ``widths`` [m] (of ``full_width``) and the eccentricity of the last loads of
    ``values`` (SI histories) beside it."""
    j_narrow = int(np.argmin(widths))
    force, moment = float(values["force"][-1]), float(values["moment"][-1])
    checks = [_on_screen(line, limits) for line in verdict.checks]
    return DesignCheck(q_max=checks[0], q_min=_on_screen(verdict.q_min, limits),
                       contact_width=float(widths[j_narrow]), full_width=full_width,
                       eccentricity=moment / force if force > 0 else None, checks=checks,
                       narrowest_time=float(times[j_narrow]), flags=flags, edge_note=edge)


def view_verdict(view: ResultView, limits: CoreLimits) -> Any:
    """The core's check (:func:`core.scene.check_design`, SI units) of a scene of one
    punch against ``limits`` (SI), dated to its answer's accuracy."""
    return check_design(view.times, view.x, view.pressure, view.values["settlement"],
                        view.values["tilt"], limits, view.info.get("corner_pressure"),
                        answer_accuracy(view.info))


def punch_verdicts(view: ResultView, limits: CoreLimits) -> list[Any]:
    """:func:`view_verdict` of each punch of a scene of several: its pressure on its own
    grid in the global x, its settlement and tilt about its own centre."""
    return [check_design(view.times, p.x, p.pressure, p.values["settlement"],
                         p.values["tilt"], limits, None,
                         answer_accuracy({"error_estimate": p.error_estimate}))
            for p in view.punches]


def punches_check_html(view: ResultView, checks: list[DesignCheck]) -> str:
    """The checks of :func:`punch_design_checks`, each named as the page names it and as
    the files do (``punches[k]``, its centre in the global x): one table, a heading and
    rows a punch, so that the punches' columns line up."""
    parts = [_check_parts(check, f"Design check of punch {k + 1}",
                          f"punches[{k}], centre x = {number_text(p.center)} m; its moment "
                          "and tilt about it")
             for k, (p, check) in enumerate(zip(view.punches, checks, strict=True))]
    body = "".join(
        f"<tr><td colspan='5' class='check-heading'>{heading}</td></tr>{CHECK_HEADER}{rows}"
        f"<tr><td colspan='5' class='check-footer'>{footer}</td></tr>"
        for heading, rows, footer in parts)
    return f"<div class='design-check'><table class='cp-readout'>{body}</table></div>"


#: The column heads of a design check's table.
CHECK_HEADER = "<tr><th></th><th>value</th><th>where</th><th>limit</th><th></th></tr>"


def check_html(check: DesignCheck, title: str = "Design check", about: str = "") -> str:
    """The check as an HTML table with a headline (pass, FAIL, or no limits set);
    ``title`` heads it, ``about`` says what it is of, beside the title."""
    heading, rows, footer = _check_parts(check, title, about)
    return (f"<div class='design-check'>{heading}<table class='cp-readout'>{CHECK_HEADER}"
            f"{rows}</table>{footer}</div>")


def _check_parts(check: DesignCheck, title: str, about: str) -> tuple[str, str, str]:
    """The heading (title and verdict), the table rows and the lines under them."""
    passed = check.passed
    if passed is None:
        head = "<span class='cp-badge check-none'>no limits set: enter them to check</span>"
    elif passed:
        head = "<span class='cp-badge cp-ok check-pass'>✓ all set limits hold</span>"
    else:
        head = "<span class='cp-badge cp-bad check-fail'>✗ a limit is exceeded</span>"
    caution = flagged_caution(check.flags)
    if passed is not None and caution:
        head += f"<span class='cp-badge cp-bad check-flagged'>⚠ {html.escape(caution)}</span>"
    rows = []
    for c in check.checks + [check.q_min]:
        limit = "" if c.limit is None else number_text(c.limit)
        cls = {"pass": "cp-ok", "FAIL": "cp-bad"}.get(c.verdict, "")
        value, where = number_text(c.value), html.escape(c.where)
        if c.corner_distance is not None:
            # q ~ 1/sqrt(distance) at a rigid corner in contact: no largest value
            value = (f"<span class='check-unbounded'>unbounded at the corner</span>; "
                     f"{number_text(c.value)} at {number_text(c.corner_distance, 2)} mm "
                     "from it")
            if c.limit is not None:
                where += f"; over the limit {html.escape(c.exceeded)}"
        rows.append(f"<tr><td>{html.escape(c.name)} [{c.unit}]</td><td>{value}</td>"
                    f"<td>{where}</td><td>{limit}</td>"
                    f"<td class='{cls}'>{c.verdict if c.limit is not None else ''}</td></tr>")
    share = 100 * check.contact_width / check.full_width if check.full_width else 0.0
    lift = check.full_width - check.contact_width
    if lift > 0:
        when = ("" if check.narrowest_time is None
                else f" at t = {days_text(check.narrowest_time)}")
        contact = (f"smallest contact width {check.contact_width:.4g} m of "
                   f"{check.full_width:.4g} m ({share:.0f} %){when}, lift-off length "
                   f"{lift:.4g} m")
    else:
        contact = f"full contact: {check.full_width:.4g} m at every time"
    ecc = ("e = M/P = undefined (P ≤ 0)" if check.eccentricity is None else
           f"e = M/P = {check.eccentricity:.4g} m (B/6 = {check.full_width / 6:.4g} m)")
    what = html.escape(f"whole history; {about}" if about else "whole history")
    heading = f"<b>{html.escape(title)}</b> ({what}) {head}"
    footer = (f"<div class='cp-status'>{contact} · {ecc}</div>"
              + (f"<div class='cp-status check-edge'>q_max {html.escape(check.edge_note)}</div>"
                 if check.edge_note else ""))
    return heading, "".join(rows), footer
