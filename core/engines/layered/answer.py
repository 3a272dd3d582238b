"""The default answer for a uniform coating on an elastic base: the exact layered kernel.

When every coating layer has constant thickness, modulus and Poisson ratio, the base is
elastic (``{"model": "elastic"}``: no creep, no aging) and the punch shape is smooth,
:func:`core.scene.solve` answers with :func:`core.engines.layered.solve_layered` (the plane
-strain response of the whole stack, smooth or bonded interfaces) instead of the thin
(Winkler) layer: ``info["coating_model"] = "exact layered"``. The exact kernel solves the
same continuum problem as the resolved finite-element model of :mod:`core.coating.fem_check`, so
the model error it leaves is its own numerical error: ``info["model_error_estimate"]`` is
that estimate for the unknowns (``benchmarks/layered_kernel.py`` measures it against FE).

With no coating layers at all the stack's kernel is the base's own (``k_stack = k_pl``,
``L_inf = 1``): the same path solves the bare layer exactly, creeping or aging base
included (:mod:`core.engines.layered.bare_creep`), and its coating-model error is 0
(``info["coating_model"] = NO_COATING``). :func:`core.scene.scene_from_dict` refuses
a bare scene this path declines (the thin-layer model has no bare limit: ``m = 0``).

Where it does not apply the thin-layer model answers, with its measured error
(:mod:`core.coating.model`); :func:`layered_declines` says why:

- a creeping or aging base under a coating: the coating does not creep, so the stack's
  response is not the elastic one scaled by ``E(t)``; the thin-layer model with the map's
  error (read at the modulus at loading) answers (without coating it is: the bare base
  creeps by scalar Volterra equations, :mod:`core.engines.layered.bare_creep`);
- a coating that varies along ``x``;
- a punch shape with breakpoints: a jump (a step on an elastic solid has an infinite
  force in full contact: the thin layer's finite answer is the model's) or a kink (the
  pressure is log-singular there and the series converges slowly);
- a coating layer thinner than ``NODES_PER_THICKNESS a / MAX_NODES`` (2.3e-3 a), which
  would need more quadrature nodes than the cap (the thin-layer error is smallest there),
  or a stack whose kernel table would cost more than :data:`MAX_TABLE_COST` cosines
  (a base much thinner than the punch, ``a / H`` above ~10-20, under a thin coating);
- ``contact = "unilateral"``, or ``"auto"`` when the pressure comes out negative (lift-off:
  the unilateral solver of the thin-layer model answers).

Pressure: the top coating is an elastic solid at the punch corners, so ``q`` is singular
like ``1 / sqrt(a - |x|)`` there (not finite as in the thin-layer model).
``pressure(x)`` reports it on ``|x| <= a - h_1 / 2`` (``h_1`` the top layer's thickness)
and holds that value beyond: within half a layer of the corner the singular field is the
punch corner's, not the coating's.
"""

from __future__ import annotations

import math
import re
import time
from collections.abc import Sequence
from functools import lru_cache
from typing import Any

import numpy as np

from core.coating import model_error_estimate, tilt_share
from core.engines.layered.bare_creep import solve_bare_creep
from core.engines.layered.bare_growing_zone import flat_punch, solve_growing_zone
from core.engines.layered.bare_lift_off import bare_lift_off
from core.engines.layered.galerkin import MAX_MODES, MAX_NODES, default_modes, node_count
from core.engines.layered.solve import ERROR_FLOOR, solve_layered
from core.kernel import UniformLayer, table_cost
from core.problem import ContactSolution, accepts

__all__ = ["bare_creep_declines", "corner_reach", "layered_declines", "LiftOffNotAnswered",
           "solve_scene_layered", "thinnest_bare_base"]

#: Time samples of the load histories for the largest tilt between output times.
TILT_SAMPLES = 257
#: Most cosines the stack's kernel table may take (:func:`core.kernel.table_cost`):
#: measured 3.5e6 in 0.06 s of CPU (a / H = 20, h = a / 20), 1.6e7 in 0.32 s (a / H = 10,
#: h = 0.003 a), 2.2e7 in 0.21 s (a / H = 50, h = a / 20): ~1 s at the bound; beyond, the
#: thin layer answers (~0.1 s).
MAX_TABLE_COST = 5e7
#: Margin of :func:`core.problem.accepts`: the estimate extrapolates the geometric decay
#: of the Chebyshev modes over the whole tail (:func:`core.engines.layered.solve_layered`)
#: and is taken as it stands.
SUCCESS_MARGIN = 1.0
#: Without coating ``pressure(x)`` is reported on ``|x| <= a (1 - BARE_CORNER)`` and held
#: beyond: q is infinite at the corners, and there it is 22x its value at the centre
#: (flat punch, ``1 / sqrt(2 BARE_CORNER)``), which a plot of the punch width still shows.
BARE_CORNER = 1e-3
#: With coating, q is held within half the top layer's thickness of a corner, but never
#: over more than this share of the half-width: a top layer as thick as the punch is wide
#: held it over all of it (a 2 m layer under a half-width of 0.5 m: the reach -1, q
#: infinite everywhere; 1.8 m: q everywhere its value at x = -0.8 a, unflagged). A thin
#: coating (h <= 0.1 a) holds it over h / 2 as before.
MAX_CORNER_HOLD = 0.05
#: ``info["coating_model"]`` of a scene without coating layers (its coating-model error
#: is 0: there is no coating to model).
NO_COATING = "none (no coating)"
#: ``info["coating_model"]`` of a coated scene answered by the exact layered kernel.
EXACT_LAYERED = "exact layered"
#: A pressure below this share of its largest value is taken as lift-off.
LIFT_OFF_SHARE = 1e-9


@lru_cache(maxsize=64)
def _table_cost(largest_s: float, layers: tuple[UniformLayer, ...],
                base_thickness: float) -> float:
    """:func:`core.kernel.table_cost`, kept per stack: ~20 ms of a warm solve."""
    return table_cost(largest_s, layers, base_thickness)


def thinnest_bare_base(half_width: float) -> float:
    """The thinnest base [m] (of a punch of half-width ``half_width`` [m] without coating)
    whose kernel table stays within :data:`MAX_TABLE_COST` (``a / H`` ~88), to 0.1 %."""
    def affordable(thickness: float) -> bool:
        return _table_cost(2.0 * half_width / thickness, (), thickness) <= MAX_TABLE_COST

    thin, thick = half_width / 1e4, half_width
    for _ in range(40):       # bisection in log: the cost falls as the base thickens
        middle = math.sqrt(thin * thick)
        if affordable(middle):
            thick = middle
        else:
            thin = middle
        if thick / thin < 1.001:
            break
    return thick


def _constant(profile: Any) -> float:
    return float(np.asarray(profile(np.zeros(1)), dtype=float).ravel()[0])


def uniform_layers(scene: Any) -> list[UniformLayer]:
    return [UniformLayer(_constant(layer.thickness), _constant(layer.modulus),
                         _constant(layer.poisson), layer.interface)
            for layer in scene.coating]


def layered_declines(scene: Any, problem: Any) -> str | None:
    """Why the exact layered kernel does not answer this scene as an elastic one (None
    when it does; a bare creeping base is answered by :func:`solve_scene_layered` too, see
    :func:`bare_creep_declines`)."""
    if problem.kernel is not None or callable(problem.c) or problem.c != 1.0:
        return "the base creeps or ages"
    return bare_creep_declines(scene, problem)


def bare_creep_declines(scene: Any, problem: Any) -> str | None:
    """:func:`layered_declines` but for the base's creep and aging: why the layered path
    does not answer a scene whatever its base (None when it does). Without coating the
    creep is scalar Volterra equations over elastic unit responses
    (:mod:`core.engines.layered.bare_creep`)."""
    if scene.coating and (problem.kernel is not None or callable(problem.c)
                          or problem.c != 1.0):
        return "the base creeps or ages"
    if scene.contact not in ("auto", "full") and scene.coating:
        # without coating the lift-off is this path's own
        return "unilateral contact"
    if not all(getattr(p, "kind", None) == "constant" for layer in scene.coating
               for p in (layer.thickness, layer.modulus, layer.poisson)):
        return "the coating varies along x"
    layers = uniform_layers(scene)
    modes = default_modes(scene.half_width, layers)
    if modes > MAX_MODES or node_count(
            scene.half_width, layers, modes, base_thickness=scene.base_thickness) > MAX_NODES:
        return "the coating is thinner than the layered solve resolves"
    # the cost depends on the thicknesses alone: other moduli share the kept value
    shapes = tuple(UniformLayer(lay.thickness, 1.0, 0.0) for lay in layers)
    if _table_cost(2 * scene.half_width / scene.base_thickness, shapes,
                   scene.base_thickness) > MAX_TABLE_COST:
        return "the stack's kernel table would take too long (a thin base or coating)"
    if problem.breakpoints:
        # a jump has an infinite force in full contact, a kink a log-singular pressure
        # (the Chebyshev series converges like 1/n there: 1 % in q with 340 modes)
        return "the punch shape has breakpoints"
    return None


def corner_reach(layers: Sequence[UniformLayer], half_width: float) -> float:
    """``|t|`` [-] up to which ``pressure(x)`` is reported (held beyond): half the top
    layer's thickness from the corner, at most ``MAX_CORNER_HOLD`` of the half-width;
    ``BARE_CORNER`` without coating."""
    if not layers:
        return 1.0 - BARE_CORNER
    return 1.0 - min(0.5 * layers[0].thickness / half_width, MAX_CORNER_HOLD)


def _load_values(problem: Any, times: np.ndarray) -> dict[str, np.ndarray]:
    out = {}
    for name, load in problem.loads.items():
        values = load(times) if callable(load) else load
        out[name] = np.broadcast_to(np.asarray(values, dtype=float), times.shape).copy()
    return out


def solve_scene_layered(scene: Any, problem: Any) -> ContactSolution | None:
    """The scene's answer with the exact layered kernel (dimensionless, like
    :meth:`core.scene.pipeline.DimensionlessProblem.solve`), or None where it does not apply
    (:func:`layered_declines`) or, with ``contact = "auto"``, where the punch lifts off a
    coating (the thin layer's unilateral solver answers). A punch lifting off the bare base
    that creeps or ages where that is not answered raises :class:`LiftOffNotAnswered`."""
    if bare_creep_declines(scene, problem) is not None:
        return None
    start = time.perf_counter()
    layers = uniform_layers(scene)
    a = scene.half_width
    times = np.asarray(problem.times, dtype=float)
    creeping = problem.kernel is not None  # bare: the coating term c m q is 0
    # creeping: the unit responses of a unit settlement and a unit tilt, measured as such
    given = {"settlement": np.array([1.0, 0.0]), "tilt": np.array([0.0, 1.0])} \
        if creeping else _load_values(problem, times)
    answer = solve_layered(a, layers, scene.base_thickness, problem.modulus_at_loading,
                           scene.base_poisson, given,
                           gap=problem.g, breakpoints=problem.breakpoints, tol=problem.tol)
    response = answer.response
    history = solve_bare_creep(response, problem, times, problem.tol) if creeping else None
    if history is None:
        settlement, tilt, force, moment = (answer.settlement, answer.tilt, answer.force,
                                           answer.moment)

        def regular_part(t: np.ndarray) -> np.ndarray:
            return response.regular_part(t, answer.settlement, answer.tilt)
    else:
        settlement, tilt, force, moment = (history.settlement, history.tilt,
                                           history.force, history.moment)

        def regular_part(t: np.ndarray) -> np.ndarray:
            return history.regular_part(response, t)
    time_error = 0.0 if history is None else history.time_error
    error_estimate = answer.error_estimate + time_error
    # the sign of q is that of sqrt(1 - t^2) q, finite at the corners
    theta = np.linspace(0.0, np.pi, 8 * answer.modes + 1)
    regular = regular_part(np.cos(theta))
    scale = max(float(np.max(np.abs(regular))), 1e-300)
    lost = float(np.min(regular)) < -max(error_estimate, LIFT_OFF_SHARE) * scale
    if lost and scene.contact in ("auto", "unilateral"):
        if layers:
            return None  # the thin layer's unilateral solver answers
        clear = _held_clear(problem, times)
        if clear is not None:
            return _no_contact(scene, problem, times, clear, start)
        pulls = max(error_estimate, LIFT_OFF_SHARE) * scale
        if history is not None:
            return _bare_creep_lift_off(scene, problem, times, answer, regular_part, pulls,
                                        start)
        return _bare_lift_off(scene, problem, times, answer, regular_part, pulls, start)
    if history is None:
        dense = np.linspace(times[0], times[-1], TILT_SAMPLES)
        largest_tilt = float(np.max(np.abs(
            response.complete(_load_values(problem, dense))["tilt"])))
    else:  # the output times' (the stepping reports there)
        largest_tilt = float(np.max(np.abs(tilt)))
    edge = corner_reach(layers, a)

    def evaluate(x: np.ndarray) -> np.ndarray:
        t = np.clip(x, -edge, edge)
        return regular_part(t) / np.sqrt(1.0 - t * t)[:, None]

    unknowns = [n for n in ("settlement", "tilt", "force", "moment") if n not in problem.loads]
    numerical = error_estimate if history is not None else max(answer.errors[n]
                                                               for n in unknowns)
    if layers:
        thin = model_error_estimate(scene, tilt_share(a, a * answer.settlement, answer.tilt))
        model_error = {"estimate": float(numerical),
                       "force": float(answer.errors.get("force", numerical)),
                       "moment": float(answer.errors.get("moment", numerical)),
                       "where_m": 0.0, "model": EXACT_LAYERED,
                       "thin_layer_estimate": thin["estimate"]}
    else:
        # no coating, no coating model: the base's own kernel is the whole problem, and
        # the numerical estimate above is the only error
        model_error = _no_coating_model_error()
    flags = ["contact_lost"] if lost else []
    success = accepts(error_estimate, problem.tol, SUCCESS_MARGIN) and (
        history is None or history.success)
    if not success:
        flags.append("tol_not_met")
    if success:
        message = (f"exact layered kernel: estimated error {error_estimate:.1e} "
                   f"<= tol {problem.tol:.1e} with {answer.modes} modes")
    else:  # worded as the other engines word a missed tol
        message = (f"tol {problem.tol:.1e} not met: the exact layered kernel reached "
                   f"{answer.modes} modes with estimated error {answer.error_estimate:.1e}")
        if history is not None:
            message += (f"; time stepping: {history.message} (estimated error "
                        f"{history.time_error:.1e})")
    info = _info(scene, problem, history, start, evaluate(np.cos(theta[1:-1])),
                 error_estimate=error_estimate, spatial=answer.error_estimate,
                 success=success, flags=flags, message=message, modes=answer.modes,
                 nodes=response.nodes, stages=answer.stages, contact="full")
    info.update(max_abs_tilt=largest_tilt,
                coating_model=EXACT_LAYERED if layers else NO_COATING,
                layered_model_error=model_error)
    return ContactSolution(times.copy(), settlement, tilt, force, moment, info, None,
                           np.zeros((0, times.size)), np.ones(times.size), None, None,
                           _evaluate=evaluate, contact_set=[[(-1.0, 1.0)] for _ in times])


def _bare_lift_off(scene: Any, problem: Any, times: np.ndarray, answer: Any,
                   regular_part: Any, pulls: float, start: float) -> ContactSolution:
    """The answer of a punch lifting off the bare elastic base
    (:mod:`core.engines.layered.bare_lift_off`). ``pulls``: the value of ``sqrt(1 - t^2)
    q*`` below which a corner lifts."""
    loads = _load_values(problem, times)
    free = _free_corners(regular_part, pulls)
    lifted = bare_lift_off(scene.half_width, (scene.base_thickness,
                                              problem.modulus_at_loading, scene.base_poisson),
                           problem.g, loads, free, answer.modes, problem.tol,
                           full_error=answer.error_estimate)
    zones = [(z.lo, z.hi) for z in lifted.zones]
    # the full-contact solve's error is that of the times in full contact only
    error_estimate = max(max(z.error for z in lifted.zones), ERROR_FLOOR)
    quantities = {q: lifted.quantity(q) for q in ("settlement", "tilt", "force", "moment")}
    return _lifted_solution(scene, problem, times, answer, start, zones, quantities,
                            lambda x, edge: lifted.pressure(x, edge), error_estimate,
                            max(z.end_error for z in lifted.zones),
                            max(z.response.modes for z in lifted.zones),
                            max(z.response.nodes for z in lifted.zones))


def _free_corners(regular_part: Any, pulls: float) -> np.ndarray:
    """Per time which corner lifts: -1 the lower, +1 the upper, 2 both, 0 none."""
    ends = regular_part(np.array([-1.0, 1.0]))
    lower, upper = ends[0] < -pulls, ends[1] < -pulls
    return np.where(lower & upper, 2, np.where(lower, -1, 0) + np.where(upper, 1, 0))


#: Given loads whose ratio departs from the reference one by less than this share of
#: their size keep it (a creeping bare base keeps then its elastic zone).
RATIO_SHARE = 1e-12


def _proportional(problem: Any, times: np.ndarray) -> tuple[str, str, float] | None:
    """``(first, second, ratio)`` when the given loads are force and moment, or settlement
    and tilt, whose second is ``ratio`` times the first at every time (sampled at the
    output times and :data:`TILT_SAMPLES` between), else None."""
    given = sorted(problem.loads)
    if given not in (["force", "moment"], ["settlement", "tilt"]):
        return None
    first, second = ("force", "moment") if "force" in given else ("settlement", "tilt")
    sample = np.union1d(times, np.linspace(times[0], times[-1], TILT_SAMPLES))
    values = _load_values(problem, sample)
    a, b = values[first], values[second]
    k = int(np.argmax(np.abs(a)))
    if a[k] == 0.0:
        return None
    ratio = float(b[k] / a[k])
    size = max(float(np.max(np.abs(a))), float(np.max(np.abs(b))))
    if np.max(np.abs(b - ratio * a)) > RATIO_SHARE * size:
        return None
    return first, second, ratio


def _bare_creep_lift_off(scene: Any, problem: Any, times: np.ndarray, answer: Any,
                         regular_part: Any, pulls: float,
                         start: float) -> ContactSolution:
    """A punch lifting off the bare base that creeps or ages: a flat one under given loads
    that keep their ratio (force and moment: the eccentricity; settlement and tilt) here,
    any other as its zone grows or recedes (:func:`_bare_creep_growing_zone`, step by step
    where it does both in turn).

    With no coating the creep operator and the base's space operator commute
    (:mod:`core.engines.layered.bare_creep`), and on the zone the loads' common history
    then scales the whole answer's pressure: the free end, where its singular coefficient
    is zero at one time, stays there. So the zone is the elastic one of the loads' ratio
    (:mod:`core.engines.layered.bare_lift_off`), and the creep is the narrower punch's
    full-contact one on it (its loads ``P / b`` and ``(M - x0 P) / b^2``, or ``(delta +
    x0 alpha) / b`` and ``alpha``).
    """
    from types import SimpleNamespace

    kept = _proportional(problem, times) if flat_punch(problem.g) else None
    free = _free_corners(regular_part, pulls)
    corner = int(free[np.flatnonzero(free)[0]]) if np.any(free) else 0
    if kept is None or np.any((free != 0) & (free != corner)):
        # a curved punch (its gap does not creep) or loads whose ratio changes: the zone
        # moves
        return _bare_creep_growing_zone(scene, problem, times, answer, start)
    first, second, ratio = kept
    reference = {first: np.array([1.0]), second: np.array([ratio])}
    lifted = bare_lift_off(scene.half_width, (scene.base_thickness,
                                              problem.modulus_at_loading, scene.base_poisson),
                           None, reference, np.array([corner]), answer.modes, problem.tol)
    zone = lifted.zones[0]
    x0, b = zone.centre, zone.half
    loads = problem.loads

    def load(name: str) -> Any:
        value = loads[name]
        return value if callable(value) else (lambda tt, v=float(value): np.full(
            np.shape(tt), v))

    if first == "force":
        force, moment = load("force"), load("moment")
        narrower = {"force": lambda tt: force(tt) / b,
                    "moment": lambda tt: (moment(tt) - x0 * force(tt)) / (b * b)}
    else:
        settlement, tilt = load("settlement"), load("tilt")
        narrower = {"settlement": lambda tt: (settlement(tt) + x0 * tilt(tt)) / b,
                    "tilt": tilt}
    sub_problem = SimpleNamespace(loads=narrower, kernel=problem.kernel,
                                  time_breaks=problem.time_breaks)
    history = solve_bare_creep(zone.response, sub_problem, times, problem.tol)
    quantities = {"settlement": b * history.settlement - x0 * history.tilt,
                  "tilt": history.tilt, "force": b * history.force,
                  "moment": b * b * history.moment + b * x0 * history.force}

    def pressure(x: np.ndarray, edge: float) -> np.ndarray:
        x = np.clip(np.asarray(x, dtype=float), -edge, edge)
        s = (x - x0) / b
        out = np.zeros((x.size, times.size))
        inside = (s > -1.0) & (s < 1.0)
        si = s[inside]
        out[inside] = history.regular_part(zone.response, si) / np.sqrt(
            (1.0 - si) * (1.0 + si))[:, None]
        return out

    error_estimate = max(zone.error, ERROR_FLOOR) + history.time_error
    solution = _lifted_solution(scene, problem, times, answer, start,
                                [(zone.lo, zone.hi)] * times.size, quantities, pressure,
                                error_estimate, zone.end_error, zone.response.modes,
                                zone.response.nodes, history)
    return solution


class LiftOffNotAnswered(ValueError):
    """A punch lifting off the bare base that creeps or ages where its zone's motion is not
    answered (a zone that grows and recedes, a kernel that releases creep): the message is
    the reason, which :func:`core.scene.uncoated.lift_off_refusal` words for the scene;
    ``turns`` the dimensionless times between which the zone turned, if known."""

    def __init__(self, reason: str, turns: tuple[float, float] | None = None) -> None:
        super().__init__(reason)
        self.turns = turns


def _bare_creep_growing_zone(scene: Any, problem: Any, times: np.ndarray, answer: Any,
                             start: float) -> ContactSolution:
    """A punch lifting off the bare base that creeps or ages, its zone moving as it does
    (:mod:`core.engines.layered.bare_growing_zone`); :class:`LiftOffNotAnswered` where
    that motion is not answered."""
    from types import SimpleNamespace

    try:
        grown = solve_growing_zone(
            scene.half_width, (scene.base_thickness, problem.modulus_at_loading,
                               scene.base_poisson),
            problem.g, problem.kernel, problem.loads, times, answer.response, answer.modes,
            problem.tol, corner_reach([], scene.half_width), LIFT_OFF_SHARE,
            tuple(float(b) for b in problem.time_breaks))
    except ValueError as exc:
        reason = str(exc)
        if reason.startswith("loading:"):
            raise  # the loads no zone carries: a refusal of its own, naming its field
        # why the motion is not answered (a zone that grows and recedes, a kernel that
        # releases creep), without the engine's own name for what it checked
        raise LiftOffNotAnswered(re.sub(r"^[A-Za-z_.]+: ", "", reason),
                                 getattr(exc, "between", None)) from None
    history = SimpleNamespace(
        time_error=grown.time_error, fit_error=grown.fit_error, steps=grown.steps,
        success=bool(np.isfinite(grown.time_error)), message=(
            f"{grown.steps} steps (the creep kernel's exponentials integrated exactly), "
            f"Richardson over halved grids, an elastic zone at each"))
    return _lifted_solution(scene, problem, times, answer, start, grown.zones,
                            grown.histories, grown.pressure, grown.error + grown.time_error,
                            grown.end_error, grown.modes, grown.nodes, history)


def _lifted_solution(scene: Any, problem: Any, times: np.ndarray, answer: Any, start: float,
                     zones: list[tuple[float, float]], quantities: dict[str, np.ndarray],
                     pressure: Any, error_estimate: float, end_error: float, modes: int,
                     nodes: int, history: Any = None) -> ContactSolution:
    """The :class:`ContactSolution` of a punch lifting off the bare base (``zones`` its
    contact zone per time, ``pressure(x, edge)`` its q*, ``history`` the time stepping
    under creep, None elastic)."""
    success = accepts(error_estimate, problem.tol, SUCCESS_MARGIN) and (
        history is None or history.success)
    flags = [] if success else ["tol_not_met"]
    if success:
        message = (f"exact layered kernel, lifting off the bare base: estimated error "
                   f"{error_estimate:.1e} <= tol {problem.tol:.1e} with {modes} modes")
    else:
        message = (f"tol {problem.tol:.1e} not met: the exact layered kernel, lifting off the "
                   f"bare base, reached {modes} modes with estimated error "
                   f"{error_estimate:.1e}")
        if history is not None:
            message += (f"; time stepping: {history.message} (estimated error "
                        f"{history.time_error:.1e})")
    edge = corner_reach([], scene.half_width)

    def evaluate(x: np.ndarray) -> np.ndarray:
        return pressure(np.asarray(x, dtype=float), edge)

    time_error = 0.0 if history is None else history.time_error
    info = _info(scene, problem, history, start,
                 evaluate(np.cos(np.linspace(0.0, np.pi, 8 * modes + 1)[1:-1])),
                 error_estimate=error_estimate, spatial=error_estimate - time_error,
                 success=success, flags=flags, message=message, modes=modes, nodes=nodes,
                 stages=answer.stages, contact="unilateral")
    info.update(zone_end_error=float(end_error),
                max_abs_tilt=float(np.max(np.abs(quantities["tilt"]))),
                coating_model=NO_COATING, layered_model_error=_no_coating_model_error())
    return ContactSolution(times.copy(), quantities["settlement"], quantities["tilt"],
                           quantities["force"], quantities["moment"], info, None,
                           np.zeros((0, times.size)), np.ones(times.size), None, None,
                           _evaluate=evaluate, contact_set=[[zone] for zone in zones])


def _no_coating_model_error() -> dict[str, Any]:
    """``info["layered_model_error"]`` without coating: no coating to model, no error."""
    return {"estimate": 0.0, "force": 0.0, "moment": 0.0, "where_m": 0.0,
            "model": NO_COATING, "thin_layer_estimate": 0.0}


#: Points of [-1, 1] where :func:`_held_clear` compares the punch with the surface (the
#: gap's breakpoints added).
CLEAR_POINTS = np.linspace(-1.0, 1.0, 4001)


def _held_clear(problem: Any, times: np.ndarray) -> dict[str, np.ndarray] | None:
    """The settlement and tilt [-] at ``times`` when the given loads hold the punch clear
    of the bare surface at every one of them (a settlement given with a tilt, or with a
    moment of 0: no contact then carries no moment, and the punch stays level), else None.

    Clear: ``delta + alpha x - g(x) <= 0`` on the punch (settlement positive downward,
    ``g >= 0`` the gap). A coated base answers this with the flag ``no_contact``; the
    bare base's lift-off search took it for a crown whose zone could not be found."""
    loads = _load_values(problem, times)
    if "settlement" not in loads or not ({"tilt", "moment"} & set(loads)):
        return None
    delta = loads["settlement"]
    if "tilt" in loads:
        alpha = loads["tilt"]
    elif np.all(loads["moment"] == 0.0):
        alpha = np.zeros_like(delta)
    else:
        return None
    x = np.unique(np.concatenate([CLEAR_POINTS, np.clip(problem.breakpoints, -1.0, 1.0)]))
    g = problem.g(x) if callable(problem.g) else np.full(x.size, float(problem.g))
    reach = delta[:, None] + alpha[:, None] * x[None, :] - np.asarray(g, dtype=float)[None, :]
    if not np.all(np.max(reach, axis=1) <= 0.0):
        return None
    return {"settlement": np.array(delta, dtype=float), "tilt": np.array(alpha, dtype=float)}


def _no_contact(scene: Any, problem: Any, times: np.ndarray, clear: dict[str, np.ndarray],
                start: float) -> ContactSolution:
    """The answer of a punch held clear of the bare base at every output time
    (:func:`_held_clear`): no pressure, P = M = 0, an empty contact set (the scene's flag
    ``no_contact``); exact, so its estimated error is 0."""
    zero = np.zeros(times.size)
    message = ("no contact: the given settlement and tilt hold the punch clear of the bare "
               "base at every output time (q = 0, P = M = 0)")
    info = _info(scene, problem, None, start, np.zeros(1), error_estimate=0.0, spatial=0.0,
                 success=True, flags=[], message=message, modes=0, nodes=0, stages={},
                 contact="unilateral")
    info.update(max_abs_tilt=float(np.max(np.abs(clear["tilt"]), initial=0.0)),
                coating_model=NO_COATING, layered_model_error=_no_coating_model_error(),
                zone_end_error=0.0)

    def evaluate(x: np.ndarray) -> np.ndarray:
        return np.zeros((np.size(x), times.size))

    return ContactSolution(times.copy(), clear["settlement"], clear["tilt"], zero.copy(),
                           zero.copy(), info, None, np.zeros((0, times.size)),
                           np.ones(times.size), None, None, _evaluate=evaluate,
                           contact_set=[[] for _ in times])


def _info(scene: Any, problem: Any, history: Any, start: float, q_interior: np.ndarray, *,
          error_estimate: float, spatial: float, success: bool, flags: list[str],
          message: str, modes: int, nodes: int, stages: dict[str, Any],
          contact: str) -> dict[str, Any]:
    """The ``info`` keys every answer of this path carries (``q_interior``: q* inside the
    punch, for its extremes; ``history``: the time stepping under creep, None elastic)."""
    return {
        "error_estimate": float(error_estimate),
        "spatial_error_estimate": float(spatial),
        "time_error_estimate": 0.0 if history is None else float(history.time_error),
        "kernel_fit_error": 0.0 if history is None else history.fit_error,
        "seconds": time.perf_counter() - start,
        "flags": flags,
        "success": bool(success),
        "message": message,
        "n_modes": int(modes),
        "n_steps": 0 if history is None else history.steps,
        "n_nodes": int(nodes),
        "statement": scene.statement,
        "given": sorted(problem.loads),
        "min_pressure": float(np.min(q_interior)),
        "max_pressure": float(np.max(np.abs(q_interior))),
        "basis": "chebyshev",
        "element_ends": [],
        "method": "layered",
        "contact": contact,
        "stages": stages,
    }
