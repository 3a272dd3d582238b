"""The design check: the numbers an engineer files for a footing, and pass or fail.

:func:`design_check` reads a :class:`~explorer.model.results.ResultView` (no solve): the largest
and smallest contact pressure over the whole history and where and when they occur, the
width in contact (the part not lifting off beyond the solver's error band), the
eccentricity ``e = M/P``, and the largest settlement and tilt, each compared with a limit
the user sets (:class:`DesignLimits`). Nothing here imports Panel.
"""

from __future__ import annotations

import html
from dataclasses import dataclass, field

import numpy as np
import param

from .results import ResultView


class DesignLimits(param.Parameterized):
    """What the design must not exceed; ``None``: not checked."""

    allowable_pressure = param.Number(default=None, allow_None=True, bounds=(0, None),
                                      doc="Allowable bearing pressure [kPa].")
    settlement_limit = param.Number(default=None, allow_None=True, bounds=(0, None),
                                    doc="Largest settlement allowed [mm].")
    tilt_limit = param.Number(default=None, allow_None=True, bounds=(0, None),
                              doc="Largest tilt allowed, either way [mrad].")


@dataclass
class Check:
    """One line of the check: a value, its limit (None: not set) and the verdict."""

    name: str
    value: float
    unit: str
    where: str
    limit: float | None = None

    @property
    def verdict(self) -> str:
        if self.limit is None:
            return "no limit set"
        return "pass" if abs(self.value) <= self.limit else "FAIL"


@dataclass
class DesignCheck:
    """The summary of one result (pressures in kPa, lengths in m, as on screen)."""

    q_max: Check
    q_min: Check
    contact_width: float           # [m], of the full width 2a
    full_width: float              # [m]
    eccentricity: float | None     # e = M/P [m] at the end of the history (None: P <= 0)
    checks: list[Check] = field(default_factory=list)

    @property
    def passed(self) -> bool | None:
        """True: every set limit holds; False: one fails; None: no limit set."""
        verdicts = [c.verdict for c in self.checks if c.limit is not None]
        if not verdicts:
            return None
        return all(v == "pass" for v in verdicts)


def _contact_width(view: ResultView, index: int) -> float:
    lifted = sum(hi - lo for lo, hi in view.negative_intervals(index))
    return float(2 * view.geometry.half_width - lifted)


def design_check(view: ResultView, limits: DesignLimits | None = None) -> DesignCheck:
    """The design check of ``view`` over its whole history, against ``limits``."""
    limits = limits or DesignLimits()
    q = view.pressure / 1e3  # kPa
    i_max = np.unravel_index(int(np.nanargmax(q)), q.shape)
    i_min = np.unravel_index(int(np.nanargmin(q)), q.shape)

    def at(i: tuple[int, ...]) -> str:
        return f"x = {view.x[i[0]]:.3g} m, t = {view.times[i[1]]:.4g} days"

    widths = [_contact_width(view, j) for j in range(len(view.times))]
    j_narrow = int(np.argmin(widths))
    force = float(view.values["force"][-1])
    moment = float(view.values["moment"][-1])
    settlement = view.display("settlement")
    tilt = view.display("tilt")
    k_d = int(np.argmax(np.abs(settlement)))
    k_t = int(np.argmax(np.abs(tilt)))
    q_max = Check("largest contact pressure q_max", float(q[i_max]), "kPa", at(i_max),
                  limits.allowable_pressure)
    q_min = Check("smallest contact pressure q_min", float(q[i_min]), "kPa", at(i_min))
    checks = [
        q_max,
        Check("largest settlement", float(settlement[k_d]), "mm",
              f"t = {view.times[k_d]:.4g} days", limits.settlement_limit),
        Check("largest tilt", float(tilt[k_t]), "mrad", f"t = {view.times[k_t]:.4g} days",
              limits.tilt_limit),
    ]
    return DesignCheck(q_max=q_max, q_min=q_min, contact_width=widths[j_narrow],
                       full_width=2 * view.geometry.half_width,
                       eccentricity=moment / force if force > 0 else None, checks=checks)


def check_html(check: DesignCheck) -> str:
    """The check as an HTML table with a headline (pass, FAIL, or no limits set)."""
    passed = check.passed
    if passed is None:
        head = "<span class='cp-badge check-none'>no limits set: enter them to check</span>"
    elif passed:
        head = "<span class='cp-badge cp-ok check-pass'>✓ all set limits hold</span>"
    else:
        head = "<span class='cp-badge cp-bad check-fail'>✗ a limit is exceeded</span>"
    rows = []
    for c in check.checks + [check.q_min]:
        limit = "" if c.limit is None else f"{c.limit:.4g}"
        cls = {"pass": "cp-ok", "FAIL": "cp-bad"}.get(c.verdict, "")
        rows.append(f"<tr><td>{html.escape(c.name)} [{c.unit}]</td><td>{c.value:.4g}</td>"
                    f"<td>{html.escape(c.where)}</td><td>{limit}</td>"
                    f"<td class='{cls}'>{c.verdict if c.limit is not None else ''}</td></tr>")
    share = 100 * check.contact_width / check.full_width if check.full_width else 0.0
    lift = check.full_width - check.contact_width
    lifted = f", lift-off length {lift:.4g} m" if lift > 0 else ""
    ecc = ("e = M/P = undefined (P ≤ 0)" if check.eccentricity is None else
           f"e = M/P = {check.eccentricity:.4g} m (B/6 = {check.full_width / 6:.4g} m)")
    return (f"<div class='design-check'><b>Design check</b> (whole history) {head}"
            f"<table class='cp-readout'><tr><th></th><th>value</th><th>where</th>"
            f"<th>limit</th><th></th></tr>{''.join(rows)}</table>"
            f"<div class='cp-status'>contact width {check.contact_width:.4g} m of "
            f"{check.full_width:.4g} m ({share:.0f} %){lifted} · {ecc}</div></div>")
