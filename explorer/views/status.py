"""The status line in plain words, with the solver's stage timings behind "details".

A person reads what happened (solved in how long, what had to be recomputed, whether the
accuracy target was met); the stage timings, mode and step counts are one click away in a
native ``<details>`` element (no round trip to the server). Nothing here imports Panel.
"""

from __future__ import annotations

import html
import numbers
import re
from collections.abc import Mapping, Sequence
from typing import Any

from core.scene import percent_text

from ..files import page_words
from ..model import ResultView

#: The validity badges of each plot group: flag -> (text when raised, text when the
#: check passes).
BADGES: dict[str, dict[str, tuple[str, str]]] = {
    # group: flag -> (text when raised, text when the check passes)
    "scene": {"thick_coating": ("coating not thin", "coating thin"),
              "stiff_coating": ("coating stiffer than base", "coating softer than base"),
              "model_error": ("coating model error above solver.model_tol",
                              "coating model within solver.model_tol"),
              "beyond_model_map": ("coating model error extrapolated: check it (Coating "
                                   "tab)", "")},
    "pressure": {"contact_lost": ("contact lost: q < 0 (shaded)", "full contact"),
                 "no_contact": ("no contact at some times: the punch is clear of the surface",
                                "")},
    "history": {"large_settlement": ("settlement beyond small strains", "small strains"),
                "large_tilt": ("large tilt", "small tilt"),
                "undersampled_load": ("load faster than the output times: histories "
                                      "aliased (Time tab: more output times)", "")},
    "status": {"tol_not_met": ("tolerance not met", ""),
               "unresolved_input": ("input finer than the quadrature", "")},
}

#: Raised flags the status line repeats at the top of the results (the model does not hold
#: for the answer, or its histories are aliased): a force of 1e9 N/m settled 81 m on a 4 m
#: slab with green badges at the top and the one warning below the design check (a
#: teacher's audit). The model's error (its own note) and the accuracy target (the status
#: line's own words) are said there already.
STATUS_WARNINGS = ("thick_coating", "stiff_coating", "contact_lost", "no_contact",
                   "large_settlement", "large_tilt", "undersampled_load")


def raised_warnings(flags: Sequence[str]) -> list[str]:
    """The words of the raised :data:`STATUS_WARNINGS` among ``flags``, in the badges'
    order."""
    return [bad for group in BADGES.values() for flag, (bad, _) in group.items()
            if flag in STATUS_WARNINGS and flag in flags]


#: The solver's stages (``info["stages"]``) in words: what a change made it redo.
STAGE_WORDS = {
    "panels": "the coating and punch profiles",
    "operator": "the foundation's response",
    "basis": "the pressure basis",
    "correction": "the edge correction",
    "sample_rows": "the check points",
    "galerkin": "the contact equations",
    "modes": "the creep modes",
    "mode_selection": "the choice of modes",
    "time": "the time history",
    # the default engine's stages (core/engines/nystrom/prepared.py)
    "grid": "the grid and the foundation's response",
    "bordered": "the contact equations",
    "modal": "the creep modes",
    "solve": "the response to the loads",
}

#: Stages a change of the loads alone redoes (in words).
LOAD_STAGES = {STAGE_WORDS["mode_selection"], STAGE_WORDS["time"], STAGE_WORDS["solve"]}


def _seconds(value: object) -> float:
    return float(value) if isinstance(value, (int, float)) else 0.0


def _duration(seconds: float) -> str:
    """A solve's wall time [s] in words: "240 ms", "under 1 ms", "3.2 s"."""
    if seconds < 1e-3:
        return "under 1 ms"
    return f"{1e3 * seconds:.0f} ms" if seconds < 10 else f"{seconds:.1f} s"


def plain_status(view: ResultView) -> str:
    """One or two sentences: how long, what was recomputed, how accurate."""
    info = view.info
    stages = info.get("stages", {}) or {}
    redone = [STAGE_WORDS.get(n, n) for n, s in stages.items() if not s.get("cached")]
    seconds = info.get("seconds")
    if isinstance(seconds, (int, float)):
        # the solve's own time, and the stages built for it (the grid of a new geometry
        # is timed apart: "under 1 ms" read beside "grid 2.2 ms")
        seconds = float(seconds) + sum(_seconds(s.get("seconds")) for n, s in stages.items()
                                       if n != "solve" and not s.get("cached"))
    took = (f"Solved in {_duration(float(seconds))}" if isinstance(seconds, (int, float))
            else "Solved")
    if info.get("reused"):
        what = "Shown at once: this exact scene was solved before"
    elif not stages:
        # the engine says nothing of what it reused: claim nothing either way
        what = took
    elif len(redone) == len(stages):
        what = f"{took}, everything computed afresh"
    elif set(redone) <= LOAD_STAGES:
        # (reused from an earlier solve of this geometry, not necessarily the last one:
        # a preset switched to read "the geometry and materials were unchanged")
        what = (f"{took}: only the response to the loads was recomputed (the geometry "
                "and materials were solved before and reused)")
    else:
        what = (f"{took}: recomputed {', '.join(redone) or 'nothing'}; "
                "the rest reused")
    tol = float(view.scene.get("solver", {}).get("tol", 1e-6))
    err = info.get("error_estimate")
    if not isinstance(err, (int, float)):
        accuracy = "no accuracy estimate"
    elif "tol_not_met" in view.flags:
        # digits enough to tell the two apart, and the solver's reason: an error of
        # 1.17e-8 read "1e-08, target 1e-08", and a lift-off answer misses where 3 x its
        # estimate is over tol
        reason = page_words(missed_reason(str(info.get("message", ""))))
        accuracy = (f"accuracy target NOT met: estimated error {_apart(err, tol)}, target "
                    f"{tol:g}" + (f"; {reason}" if reason else ""))
    else:
        accuracy = f"accurate to about {max(err, 1e-16):.0e} (target {tol:g}, met)"
    return f"{what}; {accuracy}."


def _apart(value: float, other: float) -> str:
    """``value`` to two significant digits, or as many more (up to six) as tell it from
    ``other`` written the same way."""
    for digits in range(2, 7):
        text = f"{value:.{digits}g}"
        if text != f"{other:.{digits}g}":
            return text
    return text


def missed_reason(message: str) -> str:
    """Why a solve's message says tol was not met, in the engines' own words: after "not
    met: " (the default and layered engines), in and after the parentheses of "not met
    (...)" (the projection engine's margin), after "is above ...: " (the collocation
    engine), else the reasons a verdict appends after "; " (lift-off: "not within tol:
    ...", a zone end out of its band, ends that did not converge, an unsettled contact
    set); empty when it does not say."""
    if "not met: " in message:
        return message.partition("not met: ")[2].strip().rstrip(".")
    if "not met (" in message:
        inside, _, rest = message.partition("not met (")[2].partition(")")
        return (inside + rest).strip().rstrip(".")
    if " is above " in message:
        return message.partition(" is above ")[2].partition(": ")[2].strip().rstrip(".")
    reasons = [part.strip().removeprefix("not within tol: ")
               for part in message.split("; ")[1:]]
    return "; ".join(r for r in reasons if r).rstrip(".")


def details_text(view: ResultView) -> str:
    """The solver's own report: time per stage, cache use, modes, steps, message; what
    the solver did not report is left out (not written as "?")."""
    info = view.info
    stages = info.get("stages", {}) or {}
    parts = [f"{name} {1e3 * _seconds(s.get('seconds')):.1f} ms"
             + (" (cached)" if s.get("cached") else "") for name, s in stages.items()]
    counts = [f"{info[key]} {word}" for key, word in (("n_modes", "modes"),
                                                       ("n_steps", "time steps"))
              if isinstance(info.get(key), numbers.Integral)]
    pieces = [f"stages: {', '.join(parts)}" if parts else "",
              ", ".join(counts), f"solver: {info['message']}" if info.get("message") else ""]
    return " · ".join(p for p in pieces if p) or "the solver reported no details"


def held_text(cpu_seconds: float | None) -> str:
    """What the page says while a dragged slider waits for its release: the plots show
    the last result; ``cpu_seconds`` [s]: what that result cost (None: not known)."""
    took = "" if cpu_seconds is None else f" (the last one took {_duration(cpu_seconds)})"
    return (f"Solves are too slow to follow a dragged slider{took}: the plots show the "
            "last result and update when you release it.")


def following_text(cpu_seconds: float | None) -> str:
    """What the page says while a dragged slider that applies every step (a load) is
    ahead of the plots: each solve takes ``cpu_seconds`` [s] of CPU time (None: not
    known), so the plots show the last value solved, a few a second."""
    took = "" if cpu_seconds is None else f" (the last one took {_duration(cpu_seconds)})"
    return (f"Solves are too slow to follow a dragged slider at every step{took}: the "
            "plots show the last value solved and catch up when you release it.")


def preview_text(cpu_seconds: float | None) -> str:
    """What the page says while it shows a preview of a dragged slider's value (solves
    with creep too slow to follow it, ``cpu_seconds`` [s] the last one; None: not
    known): the base elastic at loading (at t = 0 the answer with creep up to the coating
    model, later without creep), the answer with creep on release."""
    took = "" if cpu_seconds is None else f" (the last one took {_duration(cpu_seconds)})"
    return (f"Preview while you drag: solves with creep are too slow to follow the "
            f"slider{took}, so the plots show the base as it answers at loading, elastic "
            "and without creep (at t = 0 d the answer with creep, up to the coating model; "
            "later without creep). The answer "
            "with creep follows when you release it.")


def model_error_text(evidence: Mapping[str, Any], extrapolated: bool = False) -> str:
    """The coating model's error in words: measured by the FE check, or estimated;
    ``extrapolated``: the estimate reads the map beyond what was measured (flag
    ``beyond_model_map``), so it is no ground for "within"."""
    if extrapolated and evidence["source"] != "measured":
        return (f"Coating model error {percent_text(evidence['error'])} (estimated, "
                "extrapolated beyond the measured map): check it on the Coating tab.")
    side = "above" if evidence["flagged"] else "within"
    quantity = evidence.get("quantity")
    of = f" of {quantity}" if quantity else ""
    return (f"Coating model error {percent_text(evidence['error'])}{of} "
            f"({evidence['label']}), {side} solver.model_tol "
            f"{100 * evidence['model_tol']:g} %.")


def status_html(view: ResultView | None, busy: bool,
                evidence: Mapping[str, Any] | None = None, preview: bool = False) -> str:
    """The status line (plain words) and its details (the solver's numbers); ``evidence``
    (:func:`explorer.model.model_evidence`): the coating model's error it states;
    ``preview``: ``view`` is a preview of a dragged value (the base elastic at loading)."""
    if view is None:
        return ("<span class='cp-status solve-status first-solve'>Solving this scene for the "
                "first time… the plots appear when it is done.</span>") if busy else ""
    text = plain_status(view)
    if preview:
        text = "Preview (the base elastic at loading, without creep): " + text
    if busy:
        text = ("Solving the newest change… showing a preview until its answer comes. "
                if preview else "Solving the newest change… showing the previous result. "
                ) + text
    if evidence is not None:
        tone = " model-flagged" if evidence["flagged"] else ""
        text_model = html.escape(model_error_text(
            evidence, view is not None and "beyond_model_map" in view.flags))
        model = (f" <span class='cp-status model-evidence model-{evidence['source']}{tone}'>"
                 f"{text_model}</span>")
    else:
        model = ""
    raised = raised_warnings(view.flags)
    warning = ("" if not raised else
               f" <span class='cp-status cp-msg status-warnings'>⚠ Flagged: "
               f"{html.escape('; '.join(raised))} (the badges below say why).</span>")
    # a percentage on one line ("135" ended a line, "%" began the next)
    return _NUMBER_UNIT.sub("\\1&nbsp;\\2", (
        f"<span class='cp-status solve-status'>{html.escape(text)}</span>{model}"
        f"{warning} <details class='cp-status solve-details'><summary>details</summary>"
        f"{html.escape(details_text(view))}</details>"))


#: A number and the percent sign after it in the status line, kept together.
_NUMBER_UNIT = re.compile(r"(\d) (%)")
