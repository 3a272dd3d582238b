"""The CSV files of the explorer: the numbers on screen, in the units on screen.

The result's files (histories, q(x, t)) are written from the
:class:`~explorer.model.results.ResultView` that is drawn, so a file holds exactly what
the plots show (no second solve, no worker needed). Each starts with ``#`` lines saying
what was solved (the version, the whole scene as one line of JSON, the solver settings:
:func:`core.scene.provenance_lines`, as the command line writes them), how accurately,
which validity flags were raised and in which units the columns are, so a flagged result
never leaves unmarked (``pandas.read_csv(path,
comment="#")`` reads the table). A study's file (:func:`study_csv`) holds every output
at every time of every point. Numbers are written with
:data:`DIGITS` significant digits: more than any accuracy target the solver offers
(1e-8), without the binary round-off tails of ``repr`` (``799999.9999999999``).
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

import core
from core.scene import DesignLimits as CoreLimits
from core.scene import corner_note, provenance_lines
from core.study import PUNCH_OUTPUT

from ..model import (
    QUANTITIES,
    QUANTITY_UNITS,
    DesignLimits,
    ResultView,
    StudyResult,
    contact_widths,
    model_evidence,
    punch_verdicts,
    scene_with_limits,
    shown_flags,
    view_verdict,
)

#: Significant digits of every number in a CSV file.
DIGITS = 10
#: Largest file a page is sent for download [bytes]: it travels base64 in one websocket
#: message that the server's event loop encodes and writes, so its size is time the loop
#: (every page's) does nothing else: a 75 MB study CSV held it 11.7 s. Larger studies run
#: with ``coated-punch sweep``, which writes files of any size.
MAX_PAGE_DOWNLOAD_BYTES = 16 * 2**20

#: Column names of the histories, in the units the screen shows them in.
HISTORY_COLUMNS = {"settlement": "settlement_mm", "tilt": "tilt_mrad",
                   "force": "force_kN_per_m", "moment": "moment_kN_m_per_m"}
#: The contact zone's columns of the histories [m]: the length of the base in contact
#: and the length lifted off (their sum is the punch width 2a).
CONTACT_COLUMNS = ("contact_width_m", "lifted_length_m")


def project_version() -> str:
    """The project's version (``core.__version__``)."""
    return core.__version__


def number(value: float) -> str:
    """``value`` with :data:`DIGITS` significant digits ('-0' written as '0')."""
    text = f"{float(value):.{DIGITS}g}"
    return "0" if text == "-0" else text


def accuracy_statement(view: ResultView) -> str:
    """What the solver says of its own accuracy for this result, in one sentence."""
    info = view.info
    tol = float(view.scene.get("solver", {}).get("tol", 1e-6))
    err = info.get("error_estimate")
    err_text = f"{float(err):.1e}" if isinstance(err, (int, float)) else "not available"
    met = "met" if "tol_not_met" not in view.flags else "NOT met"
    # what the solver did not report is left out, not written as "?"
    counts = [f"{info[key]} {word}" for key, word in (("n_modes", "modes"),
                                                       ("n_steps", "time steps"))
              if isinstance(info.get(key), int)]
    return (f"estimated relative error {err_text}, target {tol:g} ({met})"
            + (f"; {', '.join(counts)}" if counts else ""))


def flag_lines(view: ResultView, evidence: Mapping[str, Any] | None = None) -> list[str]:
    """One line per flag raised as the page shows it (``evidence``:
    :func:`explorer.model.model_evidence`, the FE check's measurement raising or lowering
    ``model_error``; default: the answer's own flags), with its explanation (the solver's
    message filled in; the measurement's words for ``model_error``)."""
    lines = []
    for flag in shown_flags(view, evidence):
        text = (page_words(evidence["message"]) if flag == "model_error"
                and evidence is not None and evidence["source"] == "measured"
                else flag_message(view, flag))
        lines.append(f"{flag}: {text}")
    return lines


#: The core's pointers to the command line, as the page says them (the coating model's
#: badge read "check the coating model (coated-punch check)", a command a page user
#: never sees).
_PAGE_WORDS = (("coated-punch check, or the explorer's coating check",
                "the Coating tab's FE check"),
               ("coated-punch check", "the Coating tab's FE check"),
               # the page has no breakpoints to give (its profiles declare theirs): a
               # wavelength of 1e-9 m read "give the x of a jump or kink in breakpoints"
               ("give the x of a jump or kink in breakpoints (a roughness finer than the "
                "panels stays unresolved: a looser tol, or a smoother profile)",
                "a roughness finer than the panels stays unresolved: a looser accuracy "
                "target (Time tab), or a smoother or wider profile"))


def page_words(text: str) -> str:
    """``text`` (a core message) with its pointers to the command line in the page's
    words."""
    for core_words, ours in _PAGE_WORDS:
        text = text.replace(core_words, ours)
    return text


def flag_message(view: ResultView, flag: str) -> str:
    """The explanation of ``flag``, in the page's words; the core's pointer to its report
    is replaced by the report's own text, which the page and the files show."""
    text = page_words(view.flag_messages.get(flag, flag))
    detail = str(view.info.get("message", "")).strip()
    if "see info.message" in text:
        text = text.replace("see info.message", detail or "no further detail").rstrip(".")
        text += "."
    return text


def _header(view: ResultView, what: str, units: Iterable[str],
            limits: DesignLimits | None = None,
            evidence: Mapping[str, Any] | None = None) -> list[str]:
    # the Check tab's limits go into the scene and the check's verdict into the file, as
    # the command line writes them (a file without them lost a failing check)
    scene = view.scene if limits is None else scene_with_limits(view.scene, limits)
    given = ", ".join(view.given)
    lines = [
        f"# coated-punch explorer {project_version()}: {what}",
        f"# scene: {scene.get('name', '')}",
        # the version, the whole scene and the solver settings, as the command line writes
        *provenance_lines(scene),
        f"# given: {given}; computed: {', '.join(view.unknowns)} (and the pressure)",
        f"# accuracy: {accuracy_statement(view)}",
    ]
    if "limits" in scene and view.punches:
        # each punch's, as the page, its report and the command line check them (one
        # check of the first punch's histories with every punch's pressure said "pass"
        # where the middle of three punches failed, a review found)
        for k, verdict in enumerate(punch_verdicts(view, CoreLimits(**scene["limits"]))):
            lines.append(f"# design_check punches[{k}]: "
                         f"{verdict.summary(view.punches[k].flags)}")
    elif "limits" in scene:
        # (dated to the answer's accuracy, as the page, the report and the command line)
        verdict = view_verdict(view, CoreLimits(**scene["limits"]))
        lines.append(f"# design_check: {verdict.summary(shown_flags(view, evidence))}")
    flags = flag_lines(view, evidence)
    if flags:
        lines.append("# WARNING: this result is flagged; the model cannot fully stand "
                     "behind it")
        lines.extend(f"# flag {line}" for line in flags)
    else:
        lines.append("# flags: none")
    lines.extend(f"# unit {u}" for u in units)
    return lines


def histories_csv(view: ResultView, limits: DesignLimits | None = None,
                  check: Mapping[str, Any] | None = None) -> str:
    """The four histories as CSV, in mm, mrad, kN/m and kN·m/m, time in days, and the
    contact width and the lifted length in m (as the contact width plot shows them);
    with the Check tab's ``limits`` in the scene and the design check's verdict, and the
    flags as the page shows them (``check``: the Coating tab's FE check, when run)."""
    width = 2 * view.geometry.half_width
    units = ["time_day: days after loading"]
    units += [f"{HISTORY_COLUMNS[q]}: {QUANTITY_UNITS[q][0]}"
              f"{' (given)' if q in view.given else ' (computed)'}" for q in QUANTITIES]
    units += [f"{CONTACT_COLUMNS[0]}: m, length of the base in contact (of 2a = "
              f"{number(width)} m)",
              f"{CONTACT_COLUMNS[1]}: m, length lifted off (2a - contact width)"]
    evidence = model_evidence(view, check)
    lines = _header(view, "histories", units, limits, evidence)
    flags = ";".join(shown_flags(view, evidence))
    lines.append(",".join(["time_day", *(HISTORY_COLUMNS[q] for q in QUANTITIES),
                           *CONTACT_COLUMNS, "flags"]))
    contact = contact_widths(view)
    columns = [view.times, *(view.display(q) for q in QUANTITIES), contact, width - contact]
    for row in zip(*columns, strict=True):
        lines.append(",".join([*(number(v) for v in row), flags]))
    return "\n".join(lines) + "\n"


def pressure_csv(view: ResultView, unit: tuple[str, float] | None = None,
                 limits: DesignLimits | None = None,
                 check: Mapping[str, Any] | None = None) -> str:
    """q(x, t) as CSV in long form (time, x, q), on the grid of the plotted line.

    ``unit``: the pressure unit on screen and its size in Pa (default: the result's own);
    ``limits``: the Check tab's, as for :func:`histories_csv`.
    A row whose pressure is negative beyond the error band is marked ``lift_off``.
    """
    name, size = unit or view.pressure_unit
    column = f"q_{name}"
    lines = _header(view, "contact pressure q(x, t)", [
        "time_day: days after loading", "x_m: m from the punch centre",
        f"{column}: {name} (compression positive)"], limits, model_evidence(view, check))
    # the rows at a corner are a held value, not q there (the JSON says it too)
    corner = corner_note(view.info.get("corner_pressure"), number)
    if corner is not None:
        lines.append(corner)
    lines.append(f"time_day,x_m,{column},flags")
    band = view.lift_off_band()
    q = view.pressure
    for j, t in enumerate(view.times):
        tt = number(t)
        for xi, qi in zip(view.x, q[:, j], strict=True):
            mark = "lift_off" if qi < -band else ""
            lines.append(f"{tt},{number(xi)},{number(qi / size)},{mark}")
    return "\n".join(lines) + "\n"


def parse_csv(text: str) -> tuple[dict[str, str], list[str], np.ndarray]:
    """Read a file of this module back: header lines, column names and the numbers
    (the text ``flags`` column dropped). For tests and scripts."""
    meta: dict[str, str] = {}
    rows: list[list[float]] = []
    names: list[str] = []
    for line in text.splitlines():
        if line.startswith("#"):
            key, _, value = line[1:].strip().partition(": ")
            meta[key] = value
        elif not names:
            names = line.split(",")[:-1]
        elif line:
            rows.append([float(v) for v in line.split(",")[: len(names)]])
    return meta, names, np.array(rows, dtype=float)


def describe(view: ResultView) -> dict[str, Any]:
    """The metadata of a result as a dict (report and tests)."""
    return {"version": project_version(), "scene": view.scene.get("name", ""),
            "accuracy": accuracy_statement(view), "flags": flag_lines(view)}


def study_csv(result: StudyResult) -> str:
    """A design study as CSV: ``#`` lines saying what was varied, then one row per point
    and output time (the parameters and outputs in the units on screen, the solver's
    ``error_estimate`` (relative), ``flags`` and ``error`` of the point)."""
    planned = result.planned
    base = planned.study.base
    lines = [f"# coated-punch {project_version()}: design study around the scene "
             f"{str(base.get('name', ''))[:200]!r}",
             *provenance_lines(base),
             f"# {planned.study.n_points} points, "
             f"{int(result.failed.sum())} failed, {int(result.flagged.sum())} flagged "
             "(see the flags column: a flagged answer is outside the model's validity)"]
    for c, v in zip(planned.choices, planned.values, strict=True):
        lines.append(f"# varied: {c.label} [{c.unit}] from {number(v[0])} to "
                     f"{number(v[-1])}, {len(v)} values")
    header = [_study_column(c.label, c.unit) for c in planned.choices] + ["time_day"]
    header += [_study_column(_output_column(name), unit)
               for name, (_, unit, _) in planned.outputs.items()]
    # (the command line's CSV had the estimate, the page's did not)
    estimates = result.estimates
    lines.append(",".join(header + ["error_estimate", "flags", "error"]))
    grids = np.meshgrid(*planned.values, indexing="ij")
    for index in np.ndindex(planned.shape):
        params = [number(float(g[index])) for g in grids]
        flags = '"' + result.flags[index] + '"'
        error = '"' + str(result.errors[index]).replace('"', '""') + '"'
        estimate = "" if estimates is None or not math.isfinite(float(estimates[index])) \
            else f"{float(estimates[index]):.3g}"
        for k, t in enumerate(result.times):
            row = params + [number(float(t))]
            for name, (_, _, factor) in planned.outputs.items():
                value = float(result.outputs[name][index + (k,)])
                row.append(number(value * factor) if math.isfinite(value) else "")
            lines.append(",".join(row + [estimate, flags, error]))
    return "\n".join(lines) + "\n"


def _output_column(key: str) -> str:
    """An output's CSV name: its key (``settlement``), or of a punch of several
    ``punches[1].tilt`` -> ``punch 2 tilt`` (punches counted from 1, as on the page)."""
    match = PUNCH_OUTPUT.fullmatch(key)
    return key if match is None else f"punch {int(match[1]) + 1} {match[2]}"


def _study_column(label: str, unit: str) -> str:
    """A CSV column name: ``coating 1: Young's modulus`` [MPa] -> ``coating_1_young_s_
    modulus_MPa``."""
    name = re.sub(r"[^A-Za-z0-9]+", "_", label.split("=")[0]).strip("_").lower()
    unit = {"kN·m/m": "kN_m_per_m", "kN/m": "kN_per_m", "-": "1"}.get(unit, unit)
    return f"{name}_{unit}"
