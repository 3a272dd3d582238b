"""The best evidence of a result's coating-model error: the FE check's, once it has run.

A result carries an estimate of its coating model's error (``SceneSolution.model_error``,
read from a map of measurements, :mod:`core.coating`); :func:`core.scene.check_scene`
measures that error for the scene itself against a resolved finite-element model. Where
both exist for the same scene, the measurement is the better evidence: every line that
speaks of the model's error (a badge, a status, a report row, the ``model_error`` flag)
uses :func:`model_error_evidence`, which picks the measurement when the check was run on
this scene (:func:`checked_key`) and falls back to the estimate otherwise.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any

from core.cache import fingerprint
from core.scene.display import days_text
from core.scene.model import Scene
from core.scene.records import percent_text
from core.scene.results import FLAG_MESSAGES
from core.scene.validate import scene_from_dict, solver_model_tol

#: The parts of a scene the FE check's answer depends on (its geometry, materials, age at
#: loading and loads) and its contact model (full contact is checked in full contact, the
#: others with lift-off); the name, output times, tolerances and limits do not enter it.
CHECKED_PARTS = ("punch", "coating", "base", "loading")
#: How a measured error is named wherever it is shown.
MEASURED = "measured by the FE check"
#: How an estimated error is named wherever it is shown.
ESTIMATED = "estimated"


def checked_key(scene: Scene | Mapping[str, Any]) -> str:
    """Content hash of what :func:`core.scene.check_scene`'s answer depends on: equal for
    two scenes whose check gives the same measurement (``CHECKED_PARTS`` equal)."""
    scene = scene_from_dict(scene)
    data = scene.to_dict()
    # a check in full contact is no measurement of a scene that may lift off
    contact = "full" if scene.contact == "full" else "lift-off"
    return fingerprint("coating_check", json.dumps(
        [data.get(part) for part in CHECKED_PARTS] + [contact], sort_keys=True,
        separators=(",", ":")))


def model_error_evidence(scene: Scene | Mapping[str, Any], estimate: float,
                         check: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The coating model's error to show for a result of ``scene``, and whether to flag it.

    Parameters
    ----------
    scene : Scene or mapping
        The scene of the result (its ``solver.model_tol`` is the flag's threshold; a
        mapping is validated as a whole only when ``check`` is given, to compare it with
        the checked scene, else only its ``solver.model_tol`` is read and checked).
    estimate : float
        The result's estimated relative error of its coating model
        (``info["model_error_estimate"]``) [-].
    check : mapping, optional
        A report of :func:`core.scene.check_scene`. It overrides the estimate when it was
        made for this scene (same :func:`checked_key`) and its FE contact set settled
        (:func:`check_settled`); a check of another scene (the geometry or the loads
        changed since) or an unsettled one is ignored.

    Returns
    -------
    dict
        ``"source"``: ``"measured"`` or ``"estimated"``; ``"label"``: how to name it
        (``MEASURED`` or ``ESTIMATED``); ``"error"``: the relative error shown (the
        measured one when there is one); ``"estimate"``; ``"measured"`` (None without an
        applicable check); ``"time_day"``: when the check measured it [day after loading]
        (None without one); ``"model_tol"``; ``"flagged"``: ``error > model_tol``;
        ``"message"``: the ``model_error`` flag's explanation.
    """
    solver = scene.get("solver", {}) if check is None and isinstance(scene, Mapping) else None
    if isinstance(solver, Mapping):
        # the flag's threshold alone: a result's scene was validated when it was solved
        # (a whole validation here cost the explorer's server 1-2 ms a geometry step)
        tol = solver_model_tol(solver)
    else:
        scene = scene_from_dict(scene)
        tol = float(scene.model_tol)
    estimate = float(estimate)
    applies = (check is not None and check.get("scene_key") == checked_key(scene)
               and check_settled(check))
    if applies:
        measured = float(check["model_error"])
        time = float(check.get("time_day", 0.0))
        side = "above" if measured > tol else "within"
        message = (f"The coating model's error {MEASURED} (the resolved finite-element "
                   f"model at t = {days_text(time)}) is {percent_text(measured)}, {side} "
                   f"solver.model_tol {100 * tol:g} % (estimated: {percent_text(estimate)}).")
        return {"source": "measured", "label": MEASURED, "error": measured,
                "estimate": estimate, "measured": measured, "time_day": time,
                "model_tol": tol, "flagged": measured > tol, "message": message}
    return {"source": "estimated", "label": ESTIMATED, "error": estimate,
            "estimate": estimate, "measured": None, "time_day": None, "model_tol": tol,
            "flagged": estimate > tol, "message": FLAG_MESSAGES["model_error"]}


def check_settled(check: Mapping[str, Any]) -> bool:
    """Whether a report of :func:`core.scene.check_scene` measured the model's error: not
    when its FE model lifted off and its contact set had not settled when its sweeps ran
    out (``lift_off["fe_converged"]`` False)."""
    lift = check.get("lift_off") or {}
    return bool(lift.get("fe_converged", True))


def flags_with_evidence(flags: list[str], evidence: Mapping[str, Any]) -> list[str]:
    """``flags`` with ``model_error`` raised or lowered as ``evidence`` says
    (:func:`model_error_evidence`), and ``beyond_model_map`` lowered once the error is
    measured (no extrapolation is left to doubt); the other flags and their order kept."""
    if evidence["source"] == "measured":
        flags = [name for name in flags if name != "beyond_model_map"]
    kept = [name for name in flags if name != "model_error"]
    if not evidence["flagged"]:
        return kept
    if "model_error" in flags:
        return list(flags)
    return [*kept, "model_error"]
