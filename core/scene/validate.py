"""Validation of a whole scene: :func:`scene_from_dict` checks a scene dict field by
field (the validators: :mod:`core.scene.schema`) and builds a :class:`Scene`, then
refuses the combinations the solver cannot handle in bounded work or in double
precision (too many breakpoints, an extreme coating compliance or gap, loads faster than
the time stepping, creep beyond real materials), naming the field to change.
"""

from __future__ import annotations

import copyreg
import json
import math
from collections.abc import Mapping
from dataclasses import replace
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np

from core import limits
from core.cache import StageCache, fingerprint
from core.coating import (
    DEFAULT_INTERFACE,
    DEFAULT_MODEL_TOL,
    INTERFACES,
    MODEL_TOL_RANGE,
    layer_compliance,
)
from core.creep import (
    MAX_CODE_DURATION,
    CodeCreep,
    Elastic,
    UserKernel,
    creep_model_from_spec,
    default_tolerance,
)
from core.problem import QUANTITIES, STATEMENTS
from core.profiles import Profile, profile_values
from core.scene import schema
from core.scene.at_loading import creeps
from core.scene.design import DesignLimits
from core.scene.load_rates import (
    CODE_STEPS_PER_PERIOD,
    STEPS_PER_PERIOD,
    check_step_limit,
)
from core.scene.model import Layer, Scene
from core.scene.schema import (
    _jsonable,
    _poisson,
    _profile,
    _spec_of,
    _text,
    _times,
    check_fields,
    migrate,
)
from core.scene.uncoated import check_uncoated
from core.validation import (
    MAX_MAGNITUDE,
    NumberTooLarge,
    bounded_list,
    finite_number,
    positive_number,
    refuse_first,
    show_value,
)

if TYPE_CHECKING:
    from core.scene.dimensionless import DimensionlessProblem


def scene_from_dict(d: Mapping[str, Any] | Scene) -> Scene:
    """Validate a scene dict (schema in ``core/SCENES.md``) and build a :class:`Scene`.

    Units: SI (m, Pa, N/m, N, rad), times in days. Every field is checked; a problem
    raises ``ValueError`` whose message starts with the full path of the field, e.g.
    ``coating[1].modulus: must be > 0, ...``. A :class:`Scene` is returned unchanged.
    """
    if isinstance(d, Scene):
        return d
    d = migrate(d)
    # a dict equal to one validated before but for its load values (a load slider, a
    # study over a load) is checked as a load change: its geometry, base and times are
    # not sampled and checked again
    key = _key_without_loads(d)
    loading = d.get("loading")
    if key is not None and isinstance(loading, Mapping):
        known = _VALIDATED.get(key)
        if known is not None and set(loading) == set(known.loading):
            return replace_loads(known, loading)
    scene = _validated(d)
    if key is not None:
        _VALIDATED.get_or_compute(key, lambda: scene)
    return scene


#: Scenes validated by :func:`scene_from_dict`, by :func:`_key_without_loads` of their dict.
_VALIDATED = StageCache("validated_scenes", max_items=32, max_bytes=64 * 2**20)


def _key_without_loads(d: Mapping[str, Any]) -> str | None:
    """The canonical JSON of a (migrated) scene dict without its ``loading``, or None if
    the dict is not plain JSON (numpy scalars, callables: such a dict is not memoised)."""
    try:
        return json.dumps({k: v for k, v in d.items() if k != "loading"}, sort_keys=True,
                          separators=(",", ":"))
    except (TypeError, ValueError, RecursionError):
        return None


def _modulus(spec: Any, path: str, domain: tuple[float, float]) -> Profile:
    """A layer's modulus profile, every value in :data:`~core.scene.schema.MODULUS_RANGE`
    [Pa]; below it, the message asks whether the value was given in MPa or GPa."""
    low, high = schema.MODULUS_RANGE
    try:
        return _profile(spec, path, "x", domain, lower=low, upper=high, inclusive=True)
    except ValueError as exc:
        text = str(exc)
        out = [below for below, rule in ((True, "must be >= "), (False, "must be <= "))
               if rule in text]  # (neither: a value not finite)
        raise ValueError(text + (_modulus_hint(out[0]) if out else "")) from None


def _modulus_hint(below: bool) -> str:
    """What a modulus below (``below``) or above the range most likely is."""
    return (" (moduli are in Pa: 800 MPa is 8e8, 33 GPa is 3.3e10)" if below
            else " (stiffer than any material)")


def _validated(d: dict[str, Any]) -> Scene:
    """:func:`scene_from_dict`'s checks of every field of the migrated dict ``d``."""
    if "punches" in d:
        raise ValueError("punches: a scene of several punches is read by "
                         "core.scene.punches_from_dict (core.solve takes either form)")
    check_fields(d, "", schema.required_fields("scene"),
                 (*schema.optional_fields("scene"), schema.SCHEMA_KEY))
    if schema.SCHEMA_KEY in d:
        # names the file's JSON Schema for editors; not part of the scene
        _text(d[schema.SCHEMA_KEY], schema.SCHEMA_KEY, allow_empty=True,
              most=limits.MAX_DESCRIPTION_CHARS)
    name = _text(d["name"], "name", allow_empty=False, most=limits.MAX_NAME_CHARS)
    description = _text(d.get("description", ""), "description", allow_empty=True,
                        most=limits.MAX_DESCRIPTION_CHARS)

    punch = check_fields(d["punch"], "punch", schema.required_fields("punch"),
                         schema.optional_fields("punch"))
    a = positive_number(punch["half_width"], "punch.half_width", unit="m")
    x_domain = (-a, a)
    shape_spec = punch.get("shape", 0.0)
    shape = _profile(shape_spec, "punch.shape", "x", x_domain)

    layers_spec = bounded_list(d["coating"], "coating", least=0, most=schema.MAX_LAYERS,
                               what="layers")
    layers = []
    for k, spec in enumerate(layers_spec):
        path = f"coating[{k}]"
        check_fields(spec, path, schema.required_fields("coating[k]"),
                     schema.optional_fields("coating[k]"))
        interface = spec.get("interface", DEFAULT_INTERFACE)
        if interface not in INTERFACES:
            raise ValueError(f"{path}.interface: must be 'smooth' or 'bonded', got "
                             f"{show_value(interface)}")
        layers.append(Layer(
            thickness=_profile(spec["thickness"], f"{path}.thickness", "x", x_domain,
                               lower=0.0),
            modulus=_modulus(spec["modulus"], f"{path}.modulus", x_domain),
            poisson=_profile(spec["poisson"], f"{path}.poisson", "x", x_domain,
                             lower=schema.POISSON_RANGE[0], upper=schema.POISSON_RANGE[1]),
            interface=interface,
        ))

    base = check_fields(d["base"], "base", schema.required_fields("base"))
    h_base = positive_number(base["thickness"], "base.thickness", unit="m")
    nu = _poisson(base["poisson"], "base.poisson")
    try:
        creep = creep_model_from_spec(base["creep"], field="base.creep")
    except NumberTooLarge:
        raise  # a ValueError that names the parameter (base.creep.modulus)
    except OverflowError:
        # an overflow in a creep computation, with no parameter to name
        raise ValueError("base.creep: a number is too large for a double (must be a finite "
                         "number)") from None
    if isinstance(creep, CodeCreep):
        # a design code's own range is said first (after the value's type, in a scene
        # file's words): "must be > 0" for 0 days let 0.5 through, which the code then
        # refused with its [1, 3650]
        finite_number(base["age_at_loading"], "base.age_at_loading")
        creep.age_at_loading_in_range(base["age_at_loading"], "base.age_at_loading")
    tau0 = positive_number(base["age_at_loading"], "base.age_at_loading",
                           unit="days")
    if tau0 > schema.MAX_AGE:
        raise ValueError(f"base.age_at_loading: must be <= {schema.MAX_AGE:g} days (about "
                         f"{schema.MAX_AGE / limits.DAYS_PER_YEAR:.0f} years: older, the age "
                         f"swamps the time steps after loading in double precision), got "
                         f"{tau0:g}")
    lam_lo, lam_hi = schema.LAM_RANGE
    if not math.isfinite(a / h_base) or not lam_lo <= a / h_base <= lam_hi:
        # both lengths said: the one changed may be the punch's (the page then still
        # names base.thickness, the field of the ratio's bound), and the ratio has no unit
        raise ValueError(f"base.thickness: the ratio punch.half_width / base.thickness = "
                         f"{a:g} m / {h_base:g} m = {a / h_base:.6g} must be in "
                         f"[{lam_lo:g}, {lam_hi:g}] (a thicker or thinner base, or a "
                         "narrower or wider punch)")

    times, times_spec = _times(d["times"], "times")
    if isinstance(creep, CodeCreep):
        # the design codes' kernel is fitted over 100 years of loading: past it the fit
        # would be read outside its range (named base.creep, in dimensionless ages)
        schema.check_last_time(float(times[-1]), schema.last_time_field(times_spec, len(times)),
                               MAX_CODE_DURATION, "100 years, the span a design code's creep "
                               "law is fitted for")

    loading = d["loading"]
    check_fields(loading, "loading", (), schema.optional_fields("loading"))
    given = frozenset(loading)
    if len(given) != 2:
        raise ValueError("loading: exactly two of settlement, tilt, force, moment are needed, "
                         "got " + (", ".join(q for q in QUANTITIES if q in given) or "none"))
    if given not in STATEMENTS:
        raise ValueError("loading: " + " and ".join(q for q in QUANTITIES if q in given)
                         + " is not one of the four statements (settlement+tilt, "
                         "settlement+moment, tilt+force, force+moment)")
    t_domain = (0.0, float(times[-1]))
    loads = {q: _profile(loading[q], f"loading.{q}", "t", t_domain)
             for q in QUANTITIES if q in given}
    # the solver's time is the age over tau0: times closer than its rounding would merge
    with np.errstate(over="ignore", invalid="ignore"):
        ages = (tau0 + times) / tau0
    if not np.all(np.isfinite(ages)):
        raise ValueError(f"base.age_at_loading: {tau0:g} days is too small against the output "
                         f"times (up to {float(times[-1]):g} days after loading): the age over "
                         "the age at loading overflows double precision")
    # (first: a span this short merges its times in the age over the age at loading
    # too, which blamed the age; and a last time whose age rounds to the age at
    # loading itself, 1e-15 days, was taken for t = 0 and answered)
    if creeps(d) and 0.0 < float(times[-1]) and ages[-1] - 1.0 < limits.MIN_CREEP_SPAN:
        # the time stepper's first steps are fractions of the span (the solver's bound)
        raise ValueError(f"{schema.last_time_field(times_spec, len(times))}: on a creeping "
                         f"base the last output time must be at least "
                         f"{limits.MIN_CREEP_SPAN * tau0:.3g} days after loading "
                         f"({limits.MIN_CREEP_SPAN:g} of the age at loading, {tau0:g} days), "
                         f"got {float(times[-1]):g}")
    if np.any(np.diff(ages) <= 0):
        i = int(np.argmax(np.diff(ages) <= 0)) + 1
        if times[i] - times[i - 1] > RESOLVED_TIMES * float(times[-1]):
            # the times are apart on their own scale: the age at loading swamps them
            raise ValueError(f"base.age_at_loading: {tau0:g} days is too large against the "
                             f"output times: times[{i - 1}] and times[{i}] ({times[i - 1]:g} "
                             f"and {times[i]:g} days after loading) cannot be told apart in "
                             "the age over the age at loading")
        raise ValueError(f"times[{i}]: too close to the time before it to be told apart at "
                         f"an age at loading of {tau0:g} days")

    solver = check_fields(d.get("solver", {}), "solver", (), schema.optional_fields("solver"))
    tol = finite_number(solver["tol"] if "tol" in solver else default_tol(creep, tau0),
                        "solver.tol")
    tol_lo, tol_hi = schema.TOL_RANGE
    if not tol_lo <= tol <= tol_hi:
        raise ValueError(f"solver.tol: must be in [{tol_lo:g}, {tol_hi:g}], "
                         f"got {show_value(tol)}")
    contact = solver.get("contact", "auto")
    if contact != "auto":
        from core.contact import CONTACT_MODELS

        if not isinstance(contact, str) or contact not in CONTACT_MODELS:
            raise ValueError(f"solver.contact: must be one of {', '.join(CONTACT_MODELS)}, "
                             f"got {show_value(contact)}")
    model_tol = solver_model_tol(solver)

    design = DesignLimits.from_dict(check_fields(d.get("limits", {}), "limits", (),
                                                 schema.optional_fields("limits")))

    data = {
        "schema_version": schema.SCHEMA_VERSION,
        "name": name,
        "description": description,
        "punch": {"half_width": a, "shape": _jsonable(_spec_of(shape, shape_spec))},
        "coating": [{"thickness": _jsonable(_spec_of(layer.thickness, s["thickness"])),
                     "modulus": _jsonable(_spec_of(layer.modulus, s["modulus"])),
                     "poisson": _jsonable(_spec_of(layer.poisson, s["poisson"])),
                     "interface": layer.interface}
                    for layer, s in zip(layers, layers_spec, strict=True)],
        "base": {"thickness": h_base, "poisson": nu, "age_at_loading": tau0,
                 "creep": _jsonable(creep.spec)},
        "loading": {q: _jsonable(_spec_of(loads[q], loading[q])) for q in loads},
        "times": _jsonable(times_spec),
        # the default contact model is left out, so existing scenes keep their keys
        "solver": ({"tol": tol, "model_tol": model_tol} if contact == "auto" else
                   {"tol": tol, "model_tol": model_tol, "contact": contact}),
    }
    if not design.empty:
        # a scene without limits keeps its keys (and its key)
        data["limits"] = design.to_dict()
    times.setflags(write=False)
    scene = Scene(name, description, a, shape, tuple(layers), h_base, nu, tau0, creep,
                  MappingProxyType(loads), times, tol, data, contact,
                  None if design.empty else design)
    _check_breakpoints(scene)
    _check_solvable(scene)
    check_uncoated(scene)
    _check_load_rates(scene)
    return scene


def solver_model_tol(solver: Mapping[str, Any]) -> float:
    """A scene's ``solver.model_tol`` [-] (the default when absent) from its ``solver``
    section, checked as :func:`scene_from_dict` checks it (``ValueError`` naming the
    field otherwise): the flag threshold of the coating model's error, which
    :func:`core.scene.model_error_evidence` reads without validating the whole scene."""
    model_tol = finite_number(solver.get("model_tol", DEFAULT_MODEL_TOL), "solver.model_tol")
    if not MODEL_TOL_RANGE[0] <= model_tol <= MODEL_TOL_RANGE[1]:
        raise ValueError(f"solver.model_tol: must be in [{MODEL_TOL_RANGE[0]:g}, "
                         f"{MODEL_TOL_RANGE[1]:g}], got {show_value(model_tol)}")
    return model_tol


def default_tol(creep: Any, age_at_loading: float) -> float:
    """The solver tolerance [-] of a scene that leaves ``solver.tol`` out.

    1e-6 (:data:`core.scene.schema.DEFAULT_TOL`), except with a design code's creep law
    (fib MC2010, Eurocode 2): the smallest of 1e-6, 1e-5, 1e-4, 1e-3 that its fit by
    exponentials can meet at this age at loading [day]
    (:func:`core.creep.default_tolerance`). ``creep``: the base's creep model, or its
    spec as in a scene file (``base.creep``).
    """
    if isinstance(creep, Mapping):
        creep = creep_model_from_spec(dict(creep), field="base.creep")
    if isinstance(creep, CodeCreep):
        return default_tolerance(creep, age_at_loading, field="base.age_at_loading")
    return schema.DEFAULT_TOL


def _check_load_rates(scene: Scene) -> None:
    """Refuse a load that varies faster than the time stepping can follow (an elastic
    base has no time stepping; a formula kernel's grid has its own point limit)."""
    if isinstance(scene.creep, Elastic):
        return
    general = isinstance(scene.creep, UserKernel)
    check_step_limit({f"loading.{q}": p for q, p in scene.loading.items()}, 0.0,
                     float(scene.times[-1]), scene.tol,
                     limits.MAX_KERNEL_GRID_POINTS if general else limits.MAX_TIME_STEPS,
                     "the time grid's limit" if general else "the time stepping's limit",
                     CODE_STEPS_PER_PERIOD if isinstance(scene.creep, CodeCreep)
                     else STEPS_PER_PERIOD)


def _x_profiles(scene: Scene) -> list[tuple[str, Profile]]:
    """The x-profiles of a scene with their field paths."""
    return [("punch.shape", scene.shape)] + [
        (f"coating[{k}].{name}", getattr(layer, name))
        for k, layer in enumerate(scene.coating) for name in ("thickness", "modulus", "poisson")]


def _check_breakpoints(scene: Scene) -> None:
    """Refuse more jumps and kinks across the punch than the solver can afford.

    Each breakpoint adds a graded cluster of quadrature panels (about 140 nodes), and the
    kernel operator is dense in the nodes: 16 breakpoints measured 2448 nodes, 1.9 s and
    360 MB for one solve, 40 breakpoints 9 s and 1.7 GB, a 10000-row table asked for a
    15 TiB matrix. A served explorer must not let one scene take the machine.
    """
    count = len(scene.breakpoints)
    if count <= schema.MAX_BREAKPOINTS:
        return
    a = scene.half_width
    path, most = max(((p, sum(1 for b in prof.breakpoints if -a < b < a))
                      for p, prof in _x_profiles(scene)), key=lambda item: item[1])
    raise ValueError(
        f"{path}: has {most} points where its value or slope jumps (table rows, step "
        f"breaks or formula switches), {count} in the whole scene, more than the "
        f"{schema.MAX_BREAKPOINTS} the solver allows: use fewer rows or breaks, a 'pchip' table "
        "(smooth between its end rows) or a smooth formula")


def _check_solvable(scene: Scene) -> None:
    """Refuse a scene whose dimensionless problem leaves double precision or the range the
    solver handles, naming the field to change.

    Every value may pass its own check (a coating modulus of 1e300 Pa is > 0) while the
    combination is not computable: ``m*`` underflows, a load over ``E a`` overflows, an
    aging term ``A / age^2`` is infinite at a tiny age at loading. Such scenes are far from
    physical sizes; refusing them here keeps NaN out of results and bounds the work.
    """
    with np.errstate(all="ignore"):
        problem = scene.dimensionless
        _check_base_modulus(scene, problem.modulus_at_loading)
        # m* and g on the samples depend on the geometry, E0 and nu alone: a geometry
        # that passed is not sampled again (a load change)
        key = fingerprint("solvable", scene._geometry_key, problem.modulus_at_loading,
                          problem.plane_factor)
        _SOLVABLE_GEOMETRIES.get_or_compute(key, lambda: _check_coefficients(scene, problem))
        _check_creep(scene, problem)
        _check_loads_scalable(scene, problem)


def _check_base_modulus(scene: Scene, e0: float) -> None:
    """Refuse a base whose modulus at loading ``e0`` [Pa] leaves
    :data:`~core.scene.schema.MODULUS_RANGE`, naming its creep model's field."""
    low, high = schema.MODULUS_RANGE
    if low <= e0 <= high:
        return
    raise ValueError(f"{_base_modulus_field(scene)}: the base's modulus at loading E0 is "
                     f"{e0:.6g} Pa, outside [{low:g}, {high:g}] Pa" + _modulus_hint(e0 < low))


def _base_modulus_field(scene: Scene) -> str:
    """The field that sets the base's modulus at loading: its creep model's ``modulus``,
    or Arutyunyan's ``modulus_final`` (its E0 is E_inf (1 - beta e^(-alpha tau0))); a
    design-code law gives E0 by its strength class: ``base.creep``."""
    creep = scene._data["base"]["creep"]
    names = [name for name in ("modulus", "modulus_final")
             if isinstance(creep, Mapping) and name in creep]
    return f"base.creep.{names[0]}" if names else "base.creep"


#: Geometries (with E0 and nu) whose m* and g passed :func:`_check_coefficients`.
_SOLVABLE_GEOMETRIES = StageCache("solvable_geometries", max_items=1024, max_bytes=2**20)


def _check_coefficients(scene: Scene, problem: DimensionlessProblem) -> bool:
    """Refuse ``m*`` or ``g`` out of range on the scene's samples; True if they pass."""
    with np.errstate(all="ignore"):
        a = scene.half_width
        x = scene.sample_x
        xs = x / a
        m = np.broadcast_to(problem.m(xs) if callable(problem.m) else problem.m, xs.shape)
        lo, hi = schema.M_STAR_RANGE
        # no coating: m* = 0 exactly, which the exact layered kernel solves
        refuse_first(bool(scene.coating) & (~np.isfinite(m) | (m < lo) | (m > hi)), lambda i: (
            f"{_m_star_field(scene, x[i])}: the coating compliance relative to the base, "
            f"m* = E0 sum_k (1 - "
            f"nu_k^2) h_k / E_k / (2 (1 - nu^2) a), is {m[i]:.3g} at x = {x[i]:.6g} m, "
            f"outside [{lo:g}, {hi:g}]: the layers are too stiff or soft, thin or thick "
            "against the base to be solved in double precision"))
        if callable(problem.g):
            g = problem.g(xs)

            def gap_message(i: int) -> str:
                # the field to change: the punch or the coating, whichever varies more
                f_range = float(np.ptp(profile_values(scene.shape, x)))
                h_range = float(np.ptp(scene.coating_thickness(x)))
                where = "punch.shape" if not f_range < h_range else "coating"
                return (f"{where}: the gap between the punch base and the coating surface "
                        f"is {g[i]:.3g} half-widths at x = {x[i]:.6g} m (at most "
                        f"{schema.MAX_GAP_RATIO:g}): far beyond the shallow contact of this model")

            refuse_first(~np.isfinite(g) | (np.abs(g) > schema.MAX_GAP_RATIO), gap_message)
    return True


def _m_star_field(scene: Scene, x: float) -> str:
    """The field to change when ``m*`` at ``x`` [m] is out of range: of the layer that
    weighs most there, its thickness when ``h_k / a`` is further from 1 than ``E0 / E_k``,
    else its modulus, or the base's when ``E0`` is further than ``E_k`` from engineering
    moduli (``TYPICAL_MODULUS``, on a log scale)."""
    with np.errstate(all="ignore"):
        at = np.array([float(x)])
        h = [float(profile_values(layer.thickness, at)[0]) for layer in scene.coating]
        e = [float(profile_values(layer.modulus, at)[0]) for layer in scene.coating]
        weights = [float(layer_compliance(hk, ek, profile_values(layer.poisson, at)[0],
                                          layer.interface))
                   for layer, hk, ek in zip(scene.coating, h, e, strict=True)]
        k = int(np.nanargmax(np.nan_to_num(weights, nan=-1.0, posinf=np.inf)))
        e0 = scene.modulus_at_loading()

        def spread(value: float) -> float:
            return abs(math.log10(value)) if 0.0 < value < math.inf else math.inf

        if spread(h[k] / scene.half_width) > spread(e0 / e[k]):
            return f"coating[{k}].thickness"
        if spread(e0 / TYPICAL_MODULUS) > spread(e[k] / TYPICAL_MODULUS):
            return _base_modulus_field(scene)
        return f"coating[{k}].modulus"


#: A modulus of engineering materials [Pa] (concrete ~3e10, polymers ~1e9): which of two
#: moduli whose ratio is out of range is the outlier (:func:`_m_star_field`).
TYPICAL_MODULUS = 1e10


def _check_loads_scalable(scene: Scene, problem: DimensionlessProblem) -> None:
    """Refuse a load whose dimensionless value leaves double precision: beyond
    ``MAX_MAGNITUDE``, or a load that is not zero in the scene but below its inverse once
    scaled (a force of 1e-320 N/m became P* = 0, which the solver then refused as "nothing
    presses it", after ``validate`` had passed the scene)."""
    ts = problem.times
    days = np.asarray(scene.times, dtype=float)
    with np.errstate(all="ignore"):
        for name, load in problem.loads.items():
            values = np.broadcast_to(load(ts) if callable(load) else load, ts.shape)
            refuse_first(~np.isfinite(values) | (np.abs(values) > MAX_MAGNITUDE),
                         lambda i, name=name: (
                             f"loading.{name}: cannot be scaled by the base modulus and the "
                             f"half-width in double precision at t = {scene.times[i]:.6g} "
                             "days after loading (the sizes in the scene are too far apart)"))
            small = np.abs(values) < 1.0 / MAX_MAGNITUDE
            if not small.any():
                continue  # (every load move of a slider: no second sampling)
            given = np.broadcast_to(profile_values(scene.loading[name], days), ts.shape)
            refuse_first((given != 0.0) & small,
                         lambda i, name=name, given=given: (
                             f"loading.{name}: {given[i]:.6g} {_unit('loading', name)} at t = "
                             f"{scene.times[i]:.6g} days after loading is too small against "
                             "the base modulus and the half-width to be solved in double "
                             "precision (give 0 for none)"))


#: Output times further apart than this share of the last one are apart on their own
#: scale: when the solver's time (the age over the age at loading) merges them, the age at
#: loading is named, not the times.
RESOLVED_TIMES = 1e-9


def _unit(section: str, name: str) -> str:
    """The unit of the field ``name`` of ``section`` in the scene file (its schema rule)."""
    return next(rule.unit for rule in schema.FIELDS[section] if rule.name == name)


#: Cached properties of a :class:`Scene` that do not depend on the loads: a scene with
#: other loads keeps those already computed (:func:`replace_loads`).
_GEOMETRY_CACHES = ("breakpoints", "_geometry_key", "sample_x", "_gap_parts", "gap_minimum",
                    "sample_extremes")


def replace_loads(scene: Scene, loads: Mapping[str, Any]) -> Scene:
    """``scene`` with some of its given loads replaced (``{"force": 2e5}``: quantity ->
    load spec, in N/m, N, m or rad as in the scene file), validated as
    :func:`scene_from_dict` validates the scene dict with those loads, with the same
    messages; only the loads are checked again (the rest was validated with ``scene``).
    A load the scene does not give is refused (another statement needs a new scene)."""
    for q in loads:
        if q not in scene.loading:
            raise ValueError(f"loading.{q}: not one of the scene's given loads "
                             f"({', '.join(scene.loading)}); change the statement with a "
                             "new scene")
    t_domain = (0.0, float(scene.times[-1]))
    profiles = dict(scene.loading)
    data = dict(scene._data)
    data["loading"] = dict(data["loading"])
    for q, spec in loads.items():
        profiles[q] = _profile(spec, f"loading.{q}", "t", t_domain)
        data["loading"][q] = _jsonable(_spec_of(profiles[q], spec))
    new = replace(scene, loading=MappingProxyType(profiles), _data=data)
    for name in _GEOMETRY_CACHES:
        if name in scene.__dict__:
            new.__dict__[name] = scene.__dict__[name]
    with np.errstate(all="ignore"):
        _check_loads_scalable(new, new.dimensionless)
    _check_load_rates(new)
    return new


def _check_creep(scene: Scene, problem: DimensionlessProblem) -> None:
    """The relative modulus and the creep kernel at the ages of the solve: finite, and for
    a kernel given as a formula, never positive (a positive ``K`` makes the compliance
    decrease in time)."""
    tau0 = scene.age_at_loading
    ts = problem.times
    c = np.broadcast_to(problem.c(ts) if callable(problem.c) else problem.c, ts.shape)
    refuse_first(~np.isfinite(c) | (c <= 0), lambda i: (
        f"base.creep: the modulus E(age) / E(age at loading) is {c[i]:.3g} at the age "
        f"{tau0 * ts[i]:.6g} days: the creep parameters or base.age_at_loading are "
        "too extreme for double precision"))
    kernel = problem.kernel
    if kernel is None:
        return
    # the output times and a few between, all pairs t >= tau
    grid = np.unique(np.concatenate([ts[np.linspace(0, ts.size - 1, min(ts.size, 17))
                                        .round().astype(int)],
                                     np.linspace(ts[0], ts[-1], 17)]))
    t_star, tau_star = np.meshgrid(grid, grid, indexing="ij")
    keep = t_star >= tau_star
    t_star, tau_star = t_star[keep], tau_star[keep]
    try:
        k = np.asarray(kernel(t_star, tau_star), dtype=float)
    except ValueError as exc:  # a formula kernel refuses its own non-finite values
        where = "base.creep.expr" if isinstance(scene.creep, UserKernel) else "base.creep"
        raise ValueError(f"{where}: {exc}") from None
    refuse_first(~np.isfinite(k), lambda i: (
        f"base.creep: the creep kernel K(t, tau) is {k[i]} at the ages t = "
        f"{tau0 * t_star[i]:.6g}, tau = {tau0 * tau_star[i]:.6g} days: the creep "
        "parameters or base.age_at_loading are too extreme for double precision"))
    user = isinstance(scene.creep, UserKernel)
    if user:
        # the shipped models are <= 0 by their coefficient checks; a formula is checked
        # on samples, with room for rounding of a kernel that is 0 somewhere
        scale = float(np.max(np.abs(k))) if k.size else 0.0
        refuse_first(k > 1e-9 * scale, lambda i: (
            f"base.creep.expr: K(t, tau) must be <= 0 (the base creeps), is "
            f"{k[i] / tau0:.3g} per day at the ages t = {tau0 * t_star[i]:.6g}, tau = "
            f"{tau0 * tau_star[i]:.6g} days: a positive kernel makes the compliance "
            "decrease in time"))
        # creep strain per elastic strain under a unit stress held from loading:
        # -int_1^t* K*(t*, s) ds, on points graded toward s = t* where a fast kernel lives
        u = np.concatenate([[0.0], np.geomspace(1e-12, 1.0, 400)])
        s = ts[-1] - (ts[-1] - ts[0]) * u
        line = np.asarray(kernel(np.full(s.shape, ts[-1]), s), dtype=float)
        phi = float(np.sum(0.5 * (line[1:] + line[:-1]) * (s[:-1] - s[1:])))
        phi = -phi
    else:
        phi = float(scene.modulus_at_loading()
                    * np.asarray(scene.creep.compliance(tau0 * ts[-1], tau0), dtype=float))
    if not phi <= schema.MAX_CREEP_COEFFICIENT:
        raise ValueError(
            f"{'base.creep.expr' if user else 'base.creep'}: the creep coefficient (creep "
            "strain over elastic strain under a stress held from loading to the last output "
            f"time) is {phi:.3g}, more than {schema.MAX_CREEP_COEFFICIENT:g}: far beyond real "
            "materials, and beyond what the time stepping can follow in reasonable time")


def _rebuilt(scene: Scene) -> tuple[Any, tuple[dict[str, Any]]]:
    """How a :class:`Scene` is copied and pickled: rebuilt from its canonical dict (its
    profiles are closures, which do not pickle; ``copy.deepcopy`` and ``pickle`` refused
    it), so that a scene goes to another process (``multiprocessing``, joblib) as a dict."""
    return scene_from_dict, (scene.to_dict(),)


copyreg.pickle(Scene, _rebuilt)
