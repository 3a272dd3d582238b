"""The model error of a scene's fast answer, against the resolved finite-element model.

:func:`check_scene` builds the resolved model of :mod:`core.coating.fem_check` for a scene's
geometry (punch shape, every coating layer with its profiles and interface, the base) with
the base elastic at the modulus of a chosen time, solves the scene's statement there with
the same two given values (with lift-off where the scene's own contact model lifts the
punch off there), and compares the fast answer of the same elastic problem: the
coating model that answers the scene itself (the exact layered kernel for a uniform
coating on an elastic base, else the thin layer, :mod:`core.engines.layered.answer`). With an
aging, creeping base this measures the thin-layer model's error at that modulus; creep
itself is not part of the check.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from core.coating import (
    NEGLIGIBLE_SHARE,
    CoatingStrip,
    Stack,
    solve_stack,
    solve_stack_contact,
    zone_ends_apart,
)
from core.engines.layered import layered_declines
from core.problem import QUANTITIES
from core.scene.contact_zone import narrowest_zone
from core.scene.evidence import checked_key
from core.scene.model import Scene
from core.scene.pipeline import solve
from core.scene.results import SceneSolution
from core.scene.validate import scene_from_dict

#: Pressure errors are measured on |x| <= this fraction of a (the edge singularities of
#: both answers are not comparable pointwise).
PRESSURE_REACH = 0.9


def fe_stack(scene: Scene, time: float = 0.0) -> Stack:
    """The :class:`core.coating.fem_check.Stack` of a scene, the base elastic at ``E(tau0 + time)``
    (``time`` in days after loading)."""
    modulus = float(np.asarray(scene.creep.modulus(scene.age_at_loading + time), dtype=float))
    return Stack(
        half_width=scene.half_width,
        coating=tuple(CoatingStrip(layer.thickness, layer.modulus, layer.poisson,
                                   layer.interface) for layer in scene.coating),
        base_thickness=scene.base_thickness, base_modulus=modulus,
        base_poisson=scene.base_poisson, shape=scene.shape, breakpoints=scene.breakpoints)


def elastic_scene(scene: Scene, time: float = 0.0, full_contact: bool = True) -> Scene:
    """The scene with its base elastic at ``E(tau0 + time)``, its two given loads held
    at their values at ``time`` [days after loading], in full contact (``full_contact``)
    or in the scene's own contact model."""
    d = scene.to_dict()
    modulus = float(np.asarray(scene.creep.modulus(scene.age_at_loading + time), dtype=float))
    d["base"]["creep"] = {"model": "elastic", "modulus": modulus}
    d["loading"] = {name: float(np.asarray(profile(np.array([time])), dtype=float).ravel()[0])
                    for name, profile in scene.loading.items()}
    d["times"] = [1.0]
    if full_contact:
        d["solver"]["contact"] = "full"
    return scene_from_dict(d)


def check_scene(scene: Scene | Mapping[str, Any], time: float = 0.0,
                level: int = 0) -> dict[str, Any]:
    """Model error of the fast answer against the resolved FE model at one time.

    ``time`` [days after loading] picks the base modulus and the given loads; ``level`` is
    the FE mesh level (:func:`core.coating.solve_stack`: 0 gives P to ~2e-4). Returns
    ``{"fast": {...}, "fe": {...}}`` (settlement [m], tilt [rad], force [N/m], moment [N]),
    ``"errors"``: signed relative errors of the four against the FE answer (each relative to
    its own FE value, or to 1e-3 of its pair's scale ``max(|delta|, a |alpha|)``, ``max(|P|,
    |M| / a)`` if that is larger: a centred load has no moment) and of
    the pressure (largest difference on ``|x| <= 0.9 a`` over the largest FE pressure
    there), ``"model_error"``: the largest error of the two unknowns, ``"estimate"``: the
    map's estimate that results carry, ``"scene_key"``: :func:`core.scene.checked_key` of
    the scene (which results the measurement applies to), ``"half_width_m"``,
    ``"fe_seconds"``, ``"fe_dofs"``.

    Where the scene's own contact model lifts the punch off at this modulus, both answers
    are of lift-off (the FE model's contact set by :func:`core.coating.solve_stack_contact`,
    started from the fast one's): ``"lift_off"`` then holds both contact sets [m], the FE
    ends' uncertainty [m], its sweeps and ``"fe_converged"`` (False: the FE contact set
    had not settled when its sweeps ran out, and the report is not evidence of the
    model's error, :func:`core.scene.model_error_evidence`), and ``errors["contact_ends"]``
    the largest distance between their zone ends [half-widths]; else ``"lift_off"`` is
    None. A time where the punch does not touch the coating is refused (ValueError naming
    ``time``): there is no contact to compare.
    """
    scene = scene_from_dict(scene)
    if not np.isfinite(time) or not 0.0 <= time <= float(scene.times[-1]):
        raise ValueError(f"time: must be in [0, {float(scene.times[-1]):g}] days after "
                         f"loading, got {time!r}")
    stack = fe_stack(scene, time)
    a = scene.half_width
    lifting = None
    if scene.contact != "full":
        # the scene's own contact model at this modulus: where the punch lifts off, both
        # models are compared with lift-off (in full contact they would answer another
        # problem than the scene's)
        lifting = solve(elastic_scene(scene, time, full_contact=False))
        if not any(lifting.contact_set[0]):
            raise ValueError(
                f"time: the punch does not touch the coating at t = {time:g} days after "
                "loading (flag no_contact: q = 0 everywhere), so there is no contact "
                "model to check; check a time where the punch presses")
        if narrowest_zone(lifting.contact_set, a) is None:  # in full contact at this modulus
            lifting = None
    if lifting is not None:
        fast = lifting
        given = {name: float(getattr(fast, name)[0]) for name in scene.loading}
        answer = solve_stack_contact(stack, given, level=level, start=fast.contact_set[0])
        fe, exact = answer.response, answer.state
    else:
        elastic = elastic_scene(scene, time)
        if not scene.coating or layered_declines(scene, scene.dimensionless) is None:
            # the exact layered kernel answers the scene itself (a bare base, creeping or
            # not)
            fast = solve(elastic)
        else:
            # the scene's own answer is the thin layer's (a creeping base, a varying
            # coating): check that model at this modulus, not the exact kernel its elastic
            # copy would get
            problem = elastic.dimensionless
            with np.errstate(all="ignore"):
                fast = SceneSolution(elastic, problem, problem.solve())
        fe = solve_stack(stack, level=level)
        given = {name: float(getattr(fast, name)[0]) for name in scene.loading}
        exact = fe.complete(given)
    quick = {name: float(getattr(fast, name)[0]) for name in QUANTITIES}
    kin = max(abs(exact["settlement"]), a * abs(exact["tilt"]))
    stat = max(abs(exact["force"]), abs(exact["moment"]) / a)
    scales = {"settlement": kin, "tilt": kin / a, "force": stat, "moment": stat * a}
    # each relative to itself (as the map measures them), unless it is tiny against its
    # pair (a moment of a centred load): then relative to the pair's scale
    errors = {}
    for name in QUANTITIES:
        scale = max(abs(exact[name]), NEGLIGIBLE_SHARE * scales[name])
        errors[name] = (quick[name] - exact[name]) / scale if scale > 0 else 0.0
    contact = None
    if lifting is not None:
        ends = zone_ends_apart(fast.contact_set[0], answer.contact)
        errors["contact_ends"] = ends / a
        contact = {"fast": [list(z) for z in fast.contact_set[0]],
                   "fe": [list(z) for z in answer.contact],
                   "fe_end_uncertainty": answer.end_moved, "fe_sweeps": answer.sweeps,
                   "fe_converged": answer.converged}
    x = np.linspace(-PRESSURE_REACH * a, PRESSURE_REACH * a, 181)
    q_fe = fe.pressure(x, exact["settlement"], exact["tilt"])
    q_fast = fast.pressure(x)[:, 0] if lifting is None else np.maximum(fast.pressure(x)[:, 0], 0)
    q_scale = float(np.max(np.abs(q_fe)))
    errors["pressure"] = float(np.max(np.abs(q_fast - q_fe)) / q_scale) if q_scale > 0 else 0.0
    # where q differs most [m] (beside an abrupt change of the coating the thin layer's q
    # jumps where the resolved one is smooth: 43 % at a 6x modulus step, the scalars 0.4 %)
    worst = int(np.argmax(np.abs(q_fast - q_fe)))
    pressure_at = float(x[worst])
    unknowns = [name for name in QUANTITIES if name not in scene.loading]
    return {
        "time_day": float(time),
        "fast": quick,
        "fe": exact,
        "errors": errors,
        "model_error": max(abs(errors[name]) for name in unknowns),
        "pressure_error_at_m": pressure_at,
        # the two pressures there [Pa] (a report's row read an error with empty values)
        "pressure_fast_Pa": float(q_fast[worst]),
        "pressure_fe_Pa": float(q_fe[worst]),
        "model_tol": scene.model_tol,
        "estimate": fast.info["model_error_estimate"],
        "coating_model": fast.info["coating_model"],
        "given": sorted(scene.loading),
        "contact_lost": fast.contact_lost,
        "lift_off": contact,
        "scene_key": checked_key(scene),
        "half_width_m": a,
        "fe_seconds": fe.seconds if lifting is None else answer.seconds,
        "fe_dofs": fe.dofs,
    }


def pressure_caution(report: Mapping[str, Any]) -> str:
    """What a check's pressure error means when it is over the scene's ``model_tol``
    ("" when it is not, or for a report without it): the model error weighs the unknown
    scalars only, and q is not among them."""
    error, tol = report["errors"]["pressure"], report.get("model_tol")
    if tol is None or not error > tol:
        return ""
    return (f"the fast answer's q differs from the resolved model's by "
            f"{100 * error:.2f} % at x = {report['pressure_error_at_m']:.4g} m (over "
            f"solver.model_tol {100 * tol:g} %): q there, its largest value and a pressure "
            "limit checked on it are not to be relied on (the thin layer's q is local: it "
            "follows the coating's compliance at each point, where the resolved layers "
            "spread the load; beside an abrupt change of the coating it jumps)")
