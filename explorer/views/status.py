"""The status line in plain words, with the solver's stage timings behind "details".

A person reads what happened (solved in how long, what had to be recomputed, whether the
accuracy target was met); the stage timings, mode and step counts are one click away in a
native ``<details>`` element (no round trip to the server). Nothing here imports Panel.
"""

from __future__ import annotations

import html
from collections.abc import Mapping
from typing import Any

from ..model import ResultView

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


def plain_status(view: ResultView) -> str:
    """One or two sentences: how long, what was recomputed, how accurate."""
    info = view.info
    stages = info.get("stages", {}) or {}
    redone = [STAGE_WORDS.get(n, n) for n, s in stages.items() if not s.get("cached")]
    ms = 1e3 * _seconds(info.get("seconds"))
    if info.get("reused"):
        what = "Shown at once: this exact scene was solved before"
    elif not stages or len(redone) == len(stages):
        what = f"Solved in {ms:.0f} ms, everything computed afresh"
    elif set(redone) <= LOAD_STAGES:
        what = (f"Solved in {ms:.0f} ms: only the response to the loads was recomputed "
                "(the geometry and materials were unchanged)")
    else:
        what = (f"Solved in {ms:.0f} ms: recomputed {', '.join(redone) or 'nothing'}; "
                "the rest reused")
    tol = float(view.scene.get("solver", {}).get("tol", 1e-6))
    err = info.get("error_estimate")
    if not isinstance(err, (int, float)):
        accuracy = "no accuracy estimate"
    elif "tol_not_met" in view.flags:
        accuracy = (f"accuracy target NOT met: estimated error {err:.0e}, target {tol:g}")
    else:
        accuracy = f"accurate to about {max(err, 1e-16):.0e} (target {tol:g}, met)"
    return f"{what}; {accuracy}."


def details_text(view: ResultView) -> str:
    """The solver's own report: time per stage, cache use, modes, steps, message."""
    info = view.info
    stages = info.get("stages", {}) or {}
    parts = [f"{name} {1e3 * _seconds(s.get('seconds')):.1f} ms"
             + (" (cached)" if s.get("cached") else "") for name, s in stages.items()]
    return (f"stages: {', '.join(parts) or 'none reported'} · {info.get('n_modes', '?')} "
            f"modes, {info.get('n_steps', '?')} time steps · "
            f"solver: {info.get('message', '')}")


def model_error_text(evidence: Mapping[str, Any]) -> str:
    """The coating model's error in words: measured by the FE check, or estimated."""
    side = "above" if evidence["flagged"] else "within"
    return (f"Coating model error {100 * evidence['error']:.3g} % ({evidence['label']}), "
            f"{side} solver.model_tol {100 * evidence['model_tol']:g} %.")


def status_html(view: ResultView | None, busy: bool,
                evidence: Mapping[str, Any] | None = None) -> str:
    """The status line (plain words) and its details (the solver's numbers); ``evidence``
    (:func:`explorer.model.model_evidence`): the coating model's error it states."""
    if view is None:
        return ("<span class='cp-status solve-status first-solve'>Solving this scene for the "
                "first time… the plots appear when it is done.</span>") if busy else ""
    text = plain_status(view)
    if busy:
        text = "Solving the newest change… showing the previous result. " + text
    if evidence is not None:
        tone = " model-flagged" if evidence["flagged"] else ""
        text_model = html.escape(model_error_text(evidence))
        model = (f" <span class='cp-status model-evidence model-{evidence['source']}{tone}'>"
                 f"{text_model}</span>")
    else:
        model = ""
    return (f"<span class='cp-status solve-status'>{html.escape(text)}</span>{model} "
            f"<details class='cp-status solve-details'><summary>details</summary>"
            f"{html.escape(details_text(view))}</details>")
