"""Loads no contact can carry, refused before solving and named in the scene's units.

A punch pressed by a force ``P`` [N/m] and a moment ``M`` [N·m/m] touches the coating
only while ``P > 0`` and the resultant acts inside the base, ``|e| = |M / P| < a``: the
pressure is never negative, so its resultant lies within the contact zone, itself within
``[-a, a]``. Otherwise no contact model has an answer: the full-contact one would need a
tensile pressure, the unilateral one has no zone left. Every contact mode refuses such a
load, with the field to change, the value and the time in days after loading (the
dimensionless solver would otherwise name ``t* = 1`` and half-widths).

An instant where both ``P`` and ``M`` are zero (a ramp starting from nothing, a load
taken off) carries nothing and is allowed here; a load that is zero at every time is not.
The lift-off model meets the loads again on its own time grid and has no answer at such
an instant: :func:`not_carried` says so in the scene's terms.
Of several punches, those of a full-contact scene are not checked: that model is linear
and reads an unloaded or pulled punch as a bonded one.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from core.contact import LoadNotCarried

if TYPE_CHECKING:
    from core.scene.model import Scene
    from core.scene.punches import PunchesScene

#: Samples of a load history between 0 and the last output time, besides the output
#: times and the points where the history kinks or jumps: a pull shorter than end/1024
#: is left to the solver's own check on its time grid.
LOAD_SAMPLES = 1025


def _sample_days(scene: Scene) -> np.ndarray:
    end = float(scene.times[-1])
    days = [np.asarray(scene.times, dtype=float), np.linspace(0.0, end, LOAD_SAMPLES)]
    for profile in scene.loading.values():
        if hasattr(profile, "nonsmooth_points"):
            kinks = np.asarray(list(profile.nonsmooth_points(0.0, end)), dtype=float)
            # both sides of a jump
            days.append(np.clip(np.concatenate([kinks, kinks * (1 - 1e-12) - 1e-12,
                                                kinks * (1 + 1e-12) + 1e-12]), 0.0, end))
    return np.unique(np.concatenate(days))


def check_loads_touch(scene: Scene | PunchesScene) -> None:
    """Refuse a given force that pulls the punch away (``P < 0``, or ``P = 0`` at every
    time) or a given moment that puts the resultant outside the punch (``|M/P| >= a``,
    or ``M != 0`` with ``P = 0``), with a ``ValueError`` naming ``loading.force`` or
    ``loading.moment``, the value [N/m, N·m/m, m] and the time [days after loading].

    Scenes whose force is not given (settlement or tilt given) are not checked here. A
    scene of several punches is checked punch by punch, the field named
    ``punches[k].loading.<field>``, where it may lift off (``solver.contact`` "auto" or
    "unilateral"), or where it is one punch: the full-contact model of several is linear
    in the loads, a punch unloaded or pulled in it is a bonded one (the pair's influence
    coefficients are read that way).
    """
    punches = getattr(scene, "scenes", None)
    if punches is not None:
        if punches[0].contact == "full" and len(punches) > 1:
            return
        for k, sub in enumerate(punches):
            try:
                _check_one(sub)
            except ValueError as exc:
                raise ValueError(f"punches[{k}].{exc}") from None
        return
    _check_one(scene)


def _check_one(scene: Scene) -> None:
    """:func:`check_loads_touch` for one punch."""
    if "force" not in scene.loading:
        return
    days = _sample_days(scene)
    force = np.asarray(scene.loading["force"](days), dtype=float) * np.ones_like(days)
    if not np.all(np.isfinite(force)):
        return  # the scene's own checks name a non-finite load
    pulled = force < 0.0
    if pulled.any():
        k = int(np.argmax(pulled))
        raise ValueError(
            f"loading.force: the punch is pulled away (P = {force[k]:.6g} N/m at t = "
            f"{days[k]:.6g} days after loading); P must be > 0 for the punch to touch the "
            "coating, and no contact model answers for a pulled punch")
    if not (force > 0.0).any():
        raise ValueError("loading.force: must be > 0 for the punch to touch the coating "
                         "(P = 0 N/m at every time: nothing presses it)")
    if "moment" not in scene.loading:
        return
    moment = np.asarray(scene.loading["moment"](days), dtype=float) * np.ones_like(days)
    if not np.all(np.isfinite(moment)):
        return
    a = scene.half_width
    with np.errstate(divide="ignore", invalid="ignore"):
        e = np.where(force > 0.0, moment / np.where(force > 0.0, force, 1.0), 0.0)
    unloaded_moment = (force == 0.0) & (moment != 0.0)
    outside = (np.abs(e) >= a) | unloaded_moment
    if outside.any():
        k = int(np.argmax(outside))
        if unloaded_moment[k]:
            reason = (f"M = {moment[k]:.6g} N·m/m with no force (P = 0 N/m) at t = "
                      f"{days[k]:.6g} days after loading")
        else:
            reason = (f"the eccentricity e = M/P = {e[k]:.6g} m at t = {days[k]:.6g} days "
                      f"after loading (M = {moment[k]:.6g} N·m/m, P = {force[k]:.6g} N/m) "
                      f"is not inside the punch, |e| must be < a = {a:.6g} m")
        raise ValueError(f"loading.moment: {reason}: the resultant acts outside the base, "
                         "so no contact can carry it")


def not_carried(scene: Scene, exc: LoadNotCarried, prefix: str = "") -> str:
    """The message of a load the lift-off model found no contact for at one of the times
    it steps through (``exc``, in the solver's terms: dimensionless time, half-widths), in
    the scene's: the field ``{prefix}loading.<quantity>``, the time in days after loading
    and the loads there [N/m, N·m/m]. ``prefix``: ``punches[k].`` for punch ``k`` of
    several.

    The checks before solving (:func:`check_loads_touch`) sample the histories; the solver
    meets the loads on its own time grid, where a force of 0 (a ramp from nothing, which
    the full-contact model answers) leaves the lift-off model nothing to answer: with no
    pressure the punch's settlement is not determined."""
    day = float(np.asarray(scene.dimensionless.days_after_loading(exc.time)))
    at = np.array([day])

    def value(name: str) -> float | None:
        profile = scene.loading.get(name)
        return None if profile is None else float(np.asarray(profile(at), dtype=float).ravel()[0])

    force, moment = value("force"), value("moment")
    shown = f"{day:.6g}"
    when = f"t = {shown} {'day' if shown == '1' else 'days'} after loading"
    found = f" ({exc.detail})" if exc.detail else ""
    if force is not None and force <= 0.0:
        return (f"{prefix}loading.force: P = {force:.6g} N/m at {when}: the lift-off model "
                "steps through every time and has no answer where nothing presses the punch "
                "(its settlement is then not determined); a force > 0 from loading on is "
                "answered, or solver.contact 'full' (a linear model) answers this history")
    a = scene.half_width
    if force is not None and moment is not None:
        e = moment / force
        if abs(e) >= a:
            return (f"{prefix}loading.moment: the eccentricity e = M/P = {e:.6g} m at {when} "
                    f"(M = {moment:.6g} N·m/m, P = {force:.6g} N/m) is not inside the punch, "
                    f"|e| must be < a = {a:.6g} m: the resultant acts outside the base, so no "
                    "contact can carry it")
        if e == 0.0:
            return _force_too_small(prefix, force, when, "centred (e = M/P = 0)", found)
        return (f"{prefix}loading.moment: at {when} the eccentricity e = M/P = {e:.6g} m "
                f"(a = {a:.6g} m) leaves the lift-off model no contact zone to carry the "
                f"loads{found}; a smaller eccentricity there is answered")
    settlement = value("settlement")
    if settlement is not None:
        # held at a given settlement, the punch is left above the surface as it creeps
        return (f"{prefix}loading.settlement: {settlement:.6g} m at {when} leaves the punch "
                f"above the surface, or touching it at a point at most{found}: no contact "
                f"carries the given {exc.quantity} or holds the punch's tilt, and the "
                "lift-off model has no answer; a larger settlement there, or a given force, "
                "is answered")
    tilt = value("tilt")
    if tilt == 0.0 and force is not None:
        # a level punch: no smaller tilt exists, the force is what is too small
        return _force_too_small(prefix, force, when, "the punch level (tilt 0)", found)
    if tilt is not None:
        # a given tilt turns the punch about its centre onto one edge
        return (f"{prefix}loading.tilt: {tilt:.6g} rad at {when} leaves the punch touching "
                f"the surface at a point at most{found}, and no contact zone carries the "
                f"given {exc.quantity}; a smaller tilt there, or a given moment, is "
                "answered")
    return (f"{prefix}loading.{exc.quantity}: at {when} the lift-off model finds no contact "
            f"zone to carry the loads{found}")


def _force_too_small(prefix: str, force: float, when: str, how: str, found: str) -> str:
    """The message of a force whose contact the lift-off model does not find although the
    moment or tilt given with it is 0: under a shaped punch (a crown) so small a force
    presses a zone narrower than the model resolves. It named the moment or the tilt, and
    asked for a smaller eccentricity or tilt than 0."""
    return (f"{prefix}loading.force: P = {force:.6g} N/m at {when}, {how}, leaves the "
            f"lift-off model no contact zone to carry it{found}: under this punch shape so "
            "small a force touches over less than the model resolves; a larger force there "
            "is answered")


def reword_refused_lift_off(scene: Scene, info: dict[str, Any]) -> None:
    """Say in the scene's terms (:func:`not_carried`) why the lift-off model refused the
    loads of an ``"auto"`` answer left in full contact (``info["unilateral_refused"]`` and
    the message, which the solver wrote with its dimensionless time)."""
    load = info.pop("unilateral_refused_load", None)
    refused = info.get("unilateral_refused")
    if load is None or not isinstance(refused, str):
        return
    reason = not_carried(scene, LoadNotCarried(refused, load["quantity"], load["time"],
                                               detail=load.get("detail", "")))
    info["unilateral_refused"] = reason
    if isinstance(info.get("message"), str):
        info["message"] = info["message"].replace(refused, reason)
