"""The ``contact=`` switch of :func:`core.solver.solve_dimensionless`.

``"full"`` answers with the full-contact model (q may come out negative: flag
``contact_lost``), ``"unilateral"`` with :func:`core.contact.solve_unilateral`, ``"auto"``
with full contact unless it is lost (then unilateral). :func:`predicted_unilateral` is
the cheap check that lets ``"auto"`` skip a full-contact solve that would be thrown away.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np

from core.contact.step import LoadNotCarried
from core.contact.unilateral import CONTACT_MODELS, FULL_CONTACT, solve_unilateral
from core.problem import UNRESOLVED_ADVICE

if TYPE_CHECKING:
    from core.problem import Geometry, TimeInputs


def check_contact_model(contact: object) -> str:
    """The ``contact`` argument checked: one of :data:`CONTACT_MODELS`."""
    if not isinstance(contact, str) or contact not in CONTACT_MODELS:
        raise ValueError(f"contact: must be one of {', '.join(CONTACT_MODELS)}, "
                         f"got {contact!r}")
    return contact


#: Samples of a load history over [1, t_end] under creep, besides the output times (the
#: base remembers the loads between them): as the dimensional check
#: (``core.scene.load_limits.LOAD_SAMPLES``).
LOAD_SAMPLES = 1025


def refuse_loads_without_contact(times: Any, kernel: Any, force: Any, moment: Any) -> None:
    """Refuse a given force or moment no contact can carry, in every contact mode.

    ``force`` (P) and ``moment`` (M) as given to :func:`core.solver.solve_dimensionless`
    (numbers, callables of t, or None), dimensionless. Raises ``ValueError`` naming
    ``force`` when P < 0 at some time (the punch is pulled away) or P = 0 at every time
    (nothing presses it), and ``moment`` when the resultant leaves the punch (|M/P| >= 1
    half-width, or M != 0 with P = 0). Checked at the output times and, on a creeping
    base (``kernel`` not None, whose memory holds the loads between them), at
    ``LOAD_SAMPLES`` times over [1, t_end]. An instant with P = M = 0 (a load taken off)
    carries nothing and passes. Inputs that fail their own checks are left to the solver.
    """
    from core.problem import as_function, validate_times

    if force is None:
        return  # statements with a given settlement or tilt: contact may be absent
    try:
        t = validate_times(times)
        force_fn = as_function(force, "force")
        moment_fn = None if moment is None else as_function(moment, "moment")
    except ValueError:
        return  # the solver names the bad argument
    if kernel is not None and t[-1] > 1.0:
        t = np.unique(np.concatenate([t, np.linspace(1.0, t[-1], LOAD_SAMPLES)]))
    p = np.asarray(force_fn(t), dtype=float) * np.ones_like(t)
    if not np.all(np.isfinite(p)):
        return
    pulled = p < 0.0
    if pulled.any():
        k = int(np.argmax(pulled))
        raise ValueError(f"force: the punch is pulled away (P = {p[k]:.6g} at t = {t[k]:.6g});"
                         " P must be > 0 for the punch to touch the coating, and no contact "
                         "model answers for a pulled punch")
    if not (p > 0.0).any():
        raise ValueError("force: must be > 0 for the punch to touch the coating (P = 0 at "
                         "every time: nothing presses it)")
    if moment_fn is None:
        return
    mo = np.asarray(moment_fn(t), dtype=float) * np.ones_like(t)
    if not np.all(np.isfinite(mo)):
        return
    pressed = p > 0.0
    e = np.where(pressed, mo / np.where(pressed, p, 1.0), 0.0)
    outside = (np.abs(e) >= 1.0) | (~pressed & (mo != 0.0))
    if outside.any():
        k = int(np.argmax(outside))
        if not pressed[k]:
            reason = f"M = {mo[k]:.6g} with no force (P = 0) at t = {t[k]:.6g}"
        else:
            reason = (f"the eccentricity M/P = {e[k]:.6g} at t = {t[k]:.6g} (M = {mo[k]:.6g}, "
                      f"P = {p[k]:.6g}) is not inside the punch, |M/P| must be < 1 half-width")
        raise ValueError(f"moment: {reason}: the resultant acts outside the base, so no "
                         "contact can carry it")


def predicted_unilateral(arguments: dict[str, Any], geometry: Geometry | None = None,
                         inputs: TimeInputs | None = None):
    """The unilateral answer when a cheap check shows full contact lost, else None.

    ``contact="auto"`` would solve full contact over all times and then, finding q < 0,
    solve again with lift-off: under creep the first solve is wasted work (it roughly
    doubled the cost of a 100-time scene). The check solves full contact at the first
    time only, elastic at the loading instant, from the prepared geometry the default
    engine would use (shared with it: a later full solve reuses it; only a pressure the
    full-contact model itself flags ``contact_lost`` counts). Applies to an elastic base
    (any first time; :func:`core.solver.solve_dimensionless` does not call it when the
    modulus is also constant, since the full-contact answer costs what the check costs)
    and to creep when the first time is t = 1 (at loading the base is elastic);
    otherwise, or when no unilateral answer exists (loads pulling the punch away) or the
    check fails on the input, returns None and the caller takes the
    full-contact path, whose messages and flags then speak. A new elastic geometry is
    prepared for the check as well: preparing it (3-10 ms on the work-precision scenes at
    tol 1e-6) is work the full-contact answer needs anyway, where a separate check on
    the unilateral solver's nodal rule cost 3-14 ms on top of it. Under creep the grid is
    the one the engine refines at :func:`core.engines.nystrom.creep_reference` (finer than
    the grid at loading, so the check is as good, and no second grid is built).
    ``arguments`` are those of :func:`solve_unilateral`; ``geometry`` and ``inputs``, when
    given, the same arguments as :func:`core.problem.validate_geometry` and
    :func:`core.problem.validate_time_inputs` returned them (not checked again).
    """
    from core.engines.nystrom import creep_reference, prepared_for
    from core.problem import validate_geometry, validate_time_inputs

    loads = {k: arguments.get(k) for k in ("settlement", "tilt", "force", "moment")}
    try:
        if geometry is None:
            geometry = validate_geometry(arguments["lam"], arguments["m"], arguments["g"],
                                         arguments.get("breakpoints", ()),
                                         arguments.get("tol", 1e-8))
        if inputs is None:
            inputs = validate_time_inputs(arguments["times"], arguments.get("c", 1.0),
                                          arguments.get("kernel"), loads)
        first = float(inputs.times[0])
        if inputs.kernel is not None and first != 1.0:
            return None
        at = np.array([first])
        values = {k: float(inputs.loads[k](at)[0]) for k in inputs.given}
        c_first = float(inputs.c(at)[0])
        # on the grid the engine solves the creep on: one refinement a geometry
        check = prepared_for(geometry, creep_reference(inputs)).solve_validated(
            validate_time_inputs([first], c_first, None, values), check_only=True)
        if "contact_lost" not in check.info["flags"]:
            return None
        check_info = {"flags": list(check.info["flags"]),
                      "min_pressure": check.info.get("min_pressure"),
                      "seconds": check.info.get("seconds")}
    except ValueError:
        return None
    try:
        result = solve_unilateral(**arguments)
    except ValueError:
        return None
    result.info["full_contact"] = {**check_info, "checked_at": first}
    result.info["seconds"] += float(check_info.get("seconds") or 0.0)
    return unresolved_carried(result, check_info["flags"])


def unresolved_carried(result: Any, checked: Sequence[str]) -> Any:
    """``result`` (a unilateral answer that did not succeed) flagged ``unresolved_input``
    with the advice of :data:`~core.problem.UNRESOLVED_ADVICE` when the
    full-contact model that sent it there (its ``checked`` flags) did not resolve m or g:
    a jump of m without its breakpoint read only "not within tol". A success is left as
    it is: its own estimate stands."""
    info = result.info
    if "unresolved_input" in checked and not info.get("success", False) \
            and "unresolved_input" not in info["flags"]:
        info["flags"] = ["unresolved_input", *info["flags"]]
        info["message"] += f"; the full-contact model found that {UNRESOLVED_ADVICE}"
    return result


def with_contact_model(full, contact: str, arguments: dict[str, Any]):
    """The answer for ``contact`` given the full-contact answer ``full``.

    ``"full"``, or ``"auto"`` while full contact holds: ``full`` with ``contact_set`` the
    whole base at every time and ``info["contact"] = "full"``. ``"auto"`` when the
    full-contact pressure is negative somewhere (flag ``contact_lost``): the unilateral
    answer, whose ``info["full_contact"]`` keeps what the full-contact model said; if the
    loads pull the punch away or its contact shrinks to a point (no unilateral answer),
    the flagged full-contact answer with ``info["unilateral_refused"]`` giving the reason
    and ``info["success"]`` False.
    ``arguments`` are those of :func:`solve_unilateral`.
    """
    if contact == "auto" and "contact_lost" in full.info.get("flags", []):
        try:
            result = solve_unilateral(**arguments)
        except ValueError as exc:
            # The loads pull the punch away (arguments were validated by the full solve):
            # no unilateral answer exists, and the flagged full-contact one says so.
            full.info["contact"] = "full"
            full.info["unilateral_refused"] = str(exc)
            if isinstance(exc, LoadNotCarried):
                # what a scene needs to say it in its own terms (core.scene.load_limits)
                full.info["unilateral_refused_load"] = {"quantity": exc.quantity,
                                                        "time": exc.time,
                                                        "detail": exc.detail}
            full.info["message"] += f"; unilateral contact refused: {exc}"
            # the punch lifts off, so the full-contact answer is not this scene's, however
            # well it meets tol: never a success
            full.info["success"] = False
            return replace(full, contact_set=[list(FULL_CONTACT) for _ in full.times])
        result.info["full_contact"] = {
            "flags": list(full.info["flags"]),
            "min_pressure": full.info.get("min_pressure"),
            "seconds": full.info.get("seconds"),
        }
        result.info["seconds"] += float(full.info.get("seconds", 0.0))
        return unresolved_carried(result, full.info["flags"])
    full.info["contact"] = "full"
    return replace(full, contact_set=[list(FULL_CONTACT) for _ in full.times])
