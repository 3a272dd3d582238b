"""The dimensional scene: one physical problem in SI units with time in days, and its solve.

A *scene* describes the punch, the coating layers, the aging base, the loading and the
output times (the schema is documented in ``core/SCENES.md``). :func:`scene_from_dict`
validates a JSON-like dict and builds a :class:`Scene`; :func:`solve` converts it to the
dimensionless problem of :func:`core.solver.solve_dimensionless` and the answer back to a
:class:`SceneSolution` in SI units.

The modules of :mod:`core.scene` say what each holds; :mod:`core.scene` is the public
path of their names.
"""

from __future__ import annotations

import os
import time
from collections.abc import Mapping
from typing import Any

import numpy as np

from core.contact import LOCATING_ZONE_ENDS, LoadNotCarried
from core.engines.layered import LiftOffNotAnswered, solve_scene_layered
from core.scene.files import load_scene
from core.scene.load_limits import check_loads_touch, not_carried, reword_refused_lift_off
from core.scene.model import Scene
from core.scene.punches import (
    PunchesScene,
    PunchesSolution,
    has_punches,
    punches_from_dict,
    solve_punches_scene,
)
from core.scene.results import SceneSolution, _check_finite
from core.scene.uncoated import lift_off_refusal
from core.scene.validate import scene_from_dict
from core.work import WorkLimitExceeded, one_blas_thread, work_bound


@one_blas_thread()
def solve(scene: Scene | PunchesScene | Mapping[str, Any] | str | os.PathLike
          ) -> SceneSolution | PunchesSolution:
    """Solve a scene (a :class:`Scene` or a scene dict, validated first; a scene file's
    path or ``"preset:NAME"`` is read by :func:`load_scene`, as the commands read it).

    Returns a :class:`SceneSolution` in SI units (m, rad, N/m, N, Pa; days after loading);
    a scene of several punches (``punches``, :mod:`core.scene.punches`) a
    :class:`core.scene.PunchesSolution`.
    """
    if isinstance(scene, (str, os.PathLike)):
        scene = load_scene(scene)
    if has_punches(scene):
        try:
            with work_bound():
                return solve_punches_scene(scene)
        except WorkLimitExceeded as exc:
            # the time stepping of the coupled modes, or their lift-off under creep
            # followed step by step, is what can run long
            raise ValueError(_costly_punches(scene, exc)) from None
    # CPU time of this thread [s] from the dict to the answer, validation included: what
    # the scene costs, whatever else the machine runs (info["seconds"] is the solver's
    # wall time)
    started = time.thread_time()
    scene = scene_from_dict(scene)
    # a load no contact can carry is refused in every contact mode, in the scene's units
    check_loads_touch(scene)
    problem = scene.dimensionless
    try:
        with np.errstate(all="ignore"), work_bound():
            try:
                answer = solve_scene_layered(scene, problem)
            except LiftOffNotAnswered as exc:
                turns = None if exc.turns is None else tuple(
                    float(problem.days_after_loading(t)) for t in exc.turns)
                raise ValueError(lift_off_refusal(str(exc), turns)) from None
            if answer is None and not scene.coating:
                # the thin layer has no bare limit (m = 0): nothing else answers
                raise ValueError(lift_off_refusal())
            result = SceneSolution(scene, problem,
                                   problem.solve() if answer is None else answer)
            reword_refused_lift_off(scene, result.info)
    except WorkLimitExceeded as exc:
        raise ValueError(_costly(scene, exc)) from None
    except LoadNotCarried as exc:
        raise ValueError(not_carried(scene, exc)) from None
    result.info["cpu_seconds"] = time.thread_time() - started
    _check_finite(result)
    return result


def _costly_punches(scene: PunchesScene | Mapping[str, Any], exc: WorkLimitExceeded) -> str:
    """:func:`_costly` for a scene of several punches: the first shaped punch where many
    zones were followed (``punches[k].shape``), else the first load that varies in time,
    named ``punches[k].loading.<quantity>`` (else ``punches``)."""
    subs = punches_from_dict(scene).scenes
    if exc.zones >= MANY_ZONES:
        shaped = [k for k, sub in enumerate(subs)
                  if getattr(sub.shape, "kind", None) != "constant"]
        if shaped:
            return (f"punches[{shaped[0]}].shape: {exc}; a shape that touches the coating "
                    "in fewer places (fewer waves or steps under the punch, a narrower "
                    "punch), a looser solver.tol, or solver.contact 'full' costs less")
    field = "punches"
    for k, sub in enumerate(subs):
        varying = [q for q, profile in sub.loading.items()
                   if getattr(profile, "kind", None) != "constant"]
        if varying:
            field = f"punches[{k}].loading.{varying[0]}"
            break
    return (f"{field}: {exc}; a smoother or shorter history of the loads, fewer or earlier "
            "output times, a looser solver.tol, or solver.contact 'full' costs less")


#: A solve stopped while it followed this many contact zones or more is said to be made
#: costly by the punch's shape (a punch whose shape is not constant): loads alone give a
#: flat or crowned punch one zone, a punch hollow in the middle two.
MANY_ZONES = 3


def _costly(scene: Scene, exc: WorkLimitExceeded) -> str:
    """The message of a solve stopped at its work bound, naming the field to change: the
    punch's shape where the ends of contact zones were being located, or many zones
    followed (a wavy punch touching at its crests: every zone's nodes in one dense
    system, every zone's ends corrected at every output time), else a load that varies
    in time (the usual cause: lift-off under creep follows it step by step), else the
    tolerance."""
    many = exc.doing.startswith(LOCATING_ZONE_ENDS) or exc.zones >= MANY_ZONES
    if many and getattr(scene.shape, "kind", None) != "constant":
        return (f"punch.shape: {exc}; a shape that touches the coating in fewer places "
                "(fewer waves or steps under the punch, a narrower punch), a looser "
                "solver.tol, or solver.contact 'full' costs less")
    varying = [q for q, profile in scene.loading.items()
               if getattr(profile, "kind", None) != "constant"]
    field = f"loading.{varying[0]}" if varying else "solver.tol"
    return (f"{field}: {exc}; a smoother or shorter history of the loads, fewer or "
            "earlier output times, a looser solver.tol, or solver.contact 'full' costs less")
