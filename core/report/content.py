"""What a report says, independent of how it is printed: the sections an engineer files
with a check, as plain text rows (the HTML and PDF writers only lay them out)."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from datetime import datetime, timezone
from typing import Any

import numpy as np

from core.scene import SceneSolution, engine_text
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


def _number(value: float, digits: int = 4) -> str:
    return f"{value:.{digits}g}" if np.isfinite(value) else "not finite"


def _at(times: np.ndarray, values: np.ndarray, pick: str) -> tuple[float, float]:
    """The largest (by magnitude) value of a history and its time [day]."""
    k = int(np.argmax(np.abs(values))) if pick == "abs" else int(np.argmax(values))
    return float(values[k]), float(times[k])


def key_numbers(result: SceneSolution) -> list[tuple[str, str]]:
    """The results in the units an engineer reads: largest over the history, with when."""
    t = result.times
    q = result.pressure_on_grid
    k_max = np.unravel_index(int(np.argmax(q)), q.shape)
    settlement, t_s = _at(t, result.settlement, "abs")
    tilt, t_a = _at(t, result.tilt, "abs")
    rows = [
        ("largest settlement δ", f"{_number(settlement * 1e3)} mm at t = {_number(t_s)} d"),
        ("largest tilt α", f"{_number(tilt * 1e3)} mrad at t = {_number(t_a)} d"),
        ("largest contact pressure q", f"{_number(q[k_max] / 1e3)} kPa at x = "
                                       f"{_number(result.x[k_max[0]])} m, t = "
                                       f"{_number(t[k_max[1]])} d"),
        ("force P at the last time", f"{_number(result.force[-1] / 1e3)} kN/m"),
        ("moment M at the last time", f"{_number(result.moment[-1] / 1e3)} kN·m/m"),
    ]
    if result.info.get("contact") == "unilateral" and result.contact_set:
        width = result.contact_width
        k = int(np.argmin(width))
        rows.append(("smallest contact width", f"{_number(width[k])} m of "
                                               f"{_number(2 * result.scene.half_width)} m at "
                                               f"t = {_number(t[k])} d"))
    return rows


def accuracy_rows(result: SceneSolution) -> list[tuple[str, str]]:
    """The numerical error estimate against its target, and the coating model's error."""
    info = result.info
    error = info.get("error_estimate")
    target = f" (target {result.scene.tol:g}: " + (
        "NOT met)" if "tol_not_met" in result.flags else "met)")
    return [
        ("numerical error (estimated, relative)",
         (f"{float(error):.1e}" if isinstance(error, (int, float)) else "not available")
         + target),
        ("coating model error (estimated, relative)",
         f"{float(result.model_error['estimate']):.1e} (flagged above "
         f"{result.scene.model_tol:g})"),
        ("solved by", engine_text(result)),
        ("solver's message", str(info.get("message", ""))),
    ]


def design_section(result: SceneSolution) -> Section | None:
    """The design check against the scene's limits, or None when the scene sets none."""
    check = result.design_check()
    if check is None:
        return None
    rows = [(line.label, line.verdict_text()) for line in (*check.checks, check.q_min)]
    failed = check.passed is False
    return Section("Design check", "A limit is exceeded." if failed else
                   "Every limit the scene sets holds.", rows, tone="bad" if failed else "good")


def sections(result: SceneSolution) -> list[Section]:
    """The report's sections, in order."""
    scene = result.scene
    stamp = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    out = [Section("About", rows=[
        ("scene", str(scene.name or "unnamed")),
        ("statement", f"{scene.statement}: " + " and ".join(
            q for q in ("settlement", "tilt", "force", "moment") if q in scene.given)
            + " given"),
        ("made by", f"coated-punch {VERSION}, {stamp}"),
        ("units", "SI; plane strain, per metre out of plane; t in days after loading; "
                  "compression positive"),
    ])]
    if result.flags:
        out.append(Section("Validity", "This result is flagged: the model cannot fully "
                           "stand behind it.",
                           [(name, result.flag_messages[name]) for name in result.flags],
                           tone="bad"))
    else:
        out.append(Section("Validity", "No validity flag: the model stands behind this "
                           "result.", tone="good"))
    design = design_section(result)
    if design is not None:
        out.append(design)
    out.append(Section("Results", rows=key_numbers(result)))
    out.append(Section("Accuracy", rows=accuracy_rows(result)))
    return out


def scene_json(result: SceneSolution) -> str:
    """The scene file (canonical JSON), to be filed with the report."""
    return json.dumps(result.scene.to_dict(), indent=1, allow_nan=False)


def describe(result: SceneSolution) -> dict[str, Any]:
    """The report's text as one JSON-able dict (what the tests read)."""
    return {s.title: {"lead": s.lead, "rows": dict(s.rows), "tone": s.tone}
            for s in sections(result)}
