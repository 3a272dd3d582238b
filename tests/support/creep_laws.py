"""What a bare creeping base must follow: a standard linear solid's creep law as a scene
field with its creep and relaxation functions in closed form, an aging base's creep
function, Lee and Radok's pressure of a Hertz contact growing on that solid, and the
answer of a zone that only recedes computed apart from the solver's time grids, and the
heel whose zone recedes and closes again with a look at the engine's call that answers it
(tests/scene/test_uncoated_scene.py, tests/engines/test_bare_lift_off.py,
benchmarks/bare_lift_off.py)."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np

from core.engines.layered.bare_lift_off import BareLiftOff, bare_lift_off


def turning_scene(tol: float, times: Any = None) -> dict:
    """The creeping ``bare_layer`` (H = a) under 500 kN/m and a moment from 300 up to 400
    kN m/m at 100 days and back down by 365: the heel lifts further as the base creeps,
    then closes again (Ting's problem; twelve log-spaced output times by default)."""
    from core.presets import read_preset

    d = read_preset("bare_layer")
    d["loading"] = {"force": 5e5, "moment": {
        "kind": "table", "points": [[0.0, 3e5], [100.0, 4e5], [365.0, 3e5]],
        "interpolation": "linear"}}
    d["solver"] = {"tol": tol}
    d["base"]["thickness"] = 1.0
    d["base"]["creep"] = dict(CREEP)
    d["times"] = {"end": 365.0, "count": 12, "spacing": "log"} if times is None else times
    return d


@contextmanager
def growing_zone_calls() -> Iterator[dict]:
    """Within the block, the arguments (``args``, ``kwargs``) and the answer (``answer``)
    of the engine's last creeping lift-off solve as the scene's solve called it
    (:func:`core.engines.layered.bare_growing_zone.solve_growing_zone`), to call it again
    with other options."""
    from core.engines.layered import answer

    seen: dict = {}
    solve_zone = answer.solve_growing_zone

    def spy(*args: Any, **kwargs: Any) -> Any:
        seen["args"], seen["kwargs"] = args, kwargs
        seen["answer"] = solve_zone(*args, **kwargs)
        return seen["answer"]

    answer.solve_growing_zone = spy
    try:
        yield seen
    finally:
        answer.solve_growing_zone = solve_zone


#: Non-aging exponential creep: J(t) = 1 / E + c (1 - exp(-r t)) (a standard linear solid),
#: its relaxation in closed form R(t) = E (1 + E c exp(-r (1 + E c) t)) / (1 + E c).
CREEP = {"model": "exponential", "modulus": 3.0e10, "compliance": 3.0e-11, "rate": 0.05}


def laws(times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``E J(t)`` and ``R(t) / E`` of :data:`CREEP` at ``times`` [days after loading]: how a
    bare base's kinematics grow under given forces and its forces relax under given
    kinematics (the correspondence principle)."""
    e_c = CREEP["modulus"] * CREEP["compliance"]
    growth = 1 + e_c * (1 - np.exp(-CREEP["rate"] * times))
    relaxation = (1 + e_c * np.exp(-CREEP["rate"] * (1 + e_c) * times)) / (1 + e_c)
    return growth, relaxation


def aging_growth(result) -> np.ndarray:
    """``E(tau0) J(t, tau0)`` at the output times of ``result`` (a ``SceneSolution``): how
    the kinematics of a bare aging base grow under constant given forces."""
    scene = result.scene
    tau0 = scene.age_at_loading
    e0 = float(np.asarray(scene.creep.modulus(tau0)))
    return 1 + e0 * np.asarray(scene.creep.compliance(tau0 + result.times, tau0))


def lee_radok_pressure(x: np.ndarray, days: np.ndarray, b0: float, peak: float) -> np.ndarray:
    """The pressure [Pa] of a Hertz contact (elastic half-width ``b0`` [m], pressure ``peak
    sqrt(1 - x^2 / b0^2)`` [Pa] at loading) growing under a constant force on the standard
    linear solid of :data:`CREEP` (Lee and Radok's hereditary integral, by quadrature):
    ``q(x, t) = C int R(t - tau) / E d sqrt(b(tau)^2 - x^2)`` with ``b(tau)^2 = b0^2 E
    J(tau)``, ``C = peak / b0``, integrated in ``s = sqrt(b^2 - x^2)`` (smooth there)."""
    from scipy.integrate import quad

    e_c = CREEP["modulus"] * CREEP["compliance"]
    rate = CREEP["rate"]

    def relaxation(lag: float) -> float:  # R(lag) / E
        return (1 + e_c * np.exp(-rate * (1 + e_c) * lag)) / (1 + e_c)

    def grown(days_: float) -> float:  # b(t)^2
        return b0 * b0 * (1 + e_c * (1 - np.exp(-rate * days_)))

    def reached(square: float) -> float:  # the time b^2 reaches ``square``
        return -np.log(1 - (square / (b0 * b0) - 1) / e_c) / rate

    out = np.zeros((x.size, days.size))
    for i, xi in enumerate(x):
        for k, t in enumerate(days):
            top = grown(t) - xi * xi
            if top <= 0:
                continue
            start = max(b0 * b0 - xi * xi, 0.0)
            value = relaxation(t) * np.sqrt(start)  # the jump at loading
            value += quad(lambda s, t=t, xi=xi: relaxation(t - reached(xi * xi + s * s)),
                          np.sqrt(start), np.sqrt(top), epsabs=0.0, epsrel=1e-11, limit=200)[0]
            out[i, k] = peak / b0 * value
    return out


#: Chebyshev points of :func:`receding_reference` over the output times' span (81 moved
#: its histories by at most 4.9e-10 and q by 4e-13 on the receding cases of
#: tests/engines/test_bare_lift_off.py, 49 by 2.7e-8).
REFERENCE_POINTS = 65


def receding_reference(result, full_first: bool = False) -> dict:
    """A punch whose zone only recedes on a creeping bare base, computed apart from the
    solver's time grids (core/engines/layered/bare_growing_zone.py gives the argument):
    ``r = (I - V)^-1 1`` and the given kinematics relaxed, ``(I - V)^-1``, by Chebyshev
    collocation at :data:`REFERENCE_POINTS` times with ``V`` by composite 16-point
    Gauss-Legendre on 24 panels with the scene's exact kernel; at those times the elastic
    lift-off answers of the relaxed loads divided by ``r`` (tol 1e-10), times ``r``; the
    unknown kinematics ``(I - V)`` of theirs by the same quadrature of their interpolant,
    the unknown force and moment from elastic answers at the output times themselves.
    The heel lifts from loading on, or (``full_first``) the punch touches fully until the
    heel starts to lift: the elastic kinematics then kink at that time, found by
    bisection, and are interpolated on either side of it apart (one interpolant over the
    whole span of a moment ramp from 0 read 1.4e-6 with 65 points, 9.9e-7 with 129, the
    split one 1.8e-8 with 33 or 65).
    Returns the four histories (dimensionless) at the output times, the elastic answers
    there (``elastic``, a ``BareLiftOff``) and ``r`` there (``scale``)."""
    scene = result.scene
    problem = scene.dimensionless
    base = (scene.base_thickness, problem.modulus_at_loading, scene.base_poisson)
    times = np.asarray(problem.times, dtype=float)
    # from loading (dimensionless time 1), where the base starts to creep
    first, last = 1.0, float(times[-1])
    chebyshev = np.polynomial.chebyshev
    degree = REFERENCE_POINTS - 1

    def points(lo: float, hi: float) -> np.ndarray:
        # (clipped: rounding must not put the first point of the lifting side before it)
        return np.clip(0.5 * (lo + hi) + 0.5 * (hi - lo) * np.cos(
            np.pi * np.arange(REFERENCE_POINTS) / degree), lo, hi)

    def interpolant(at: np.ndarray, values: np.ndarray):
        return chebyshev.Chebyshev.fit(at, values, degree, domain=[at[-1], at[0]])

    samples = points(first, last)
    nodes, weights = np.polynomial.legendre.leggauss(16)

    def memory(t: float, f, lo: float = first, hi: float | None = None) -> float:
        """int_lo^hi K(t, tau) f(tau) dtau (``hi`` default ``t``)."""
        edges = np.linspace(lo, t if hi is None else hi, 25)
        tau = (0.5 * (edges[:-1] + edges[1:])[:, None]
               + 0.5 * np.diff(edges)[:, None] * nodes[None, :]).ravel()
        w = (0.5 * np.diff(edges)[:, None] * weights[None, :]).ravel()
        k = np.ravel(np.asarray(problem.kernel(np.full(tau.shape, t), tau), dtype=float))
        return float(np.sum(w * k * f(tau)))

    basis = [interpolant(samples, np.eye(REFERENCE_POINTS)[j]) for j in range(REFERENCE_POINTS)]
    relax = np.eye(REFERENCE_POINTS) - np.array(
        [[memory(t, b) if t > first else 0.0 for b in basis] for t in samples])

    def load(name: str, at: np.ndarray) -> np.ndarray:
        value = problem.loads[name]
        return np.ravel(value(at) if callable(value) else np.full(at.shape, value))

    gap = None if not callable(problem.g) and float(problem.g) == 0.0 else problem.g
    r = interpolant(samples, np.linalg.solve(relax, np.ones(REFERENCE_POINTS)))
    given = {}  # the relaxed given loads over r, as functions of time
    for name in problem.loads:
        values = load(name, samples)
        relaxed = values if name in ("force", "moment") else np.linalg.solve(relax, values)
        given[name] = interpolant(samples, relaxed / r(samples))

    def elastic_at(at: np.ndarray, lifting: bool) -> Any:
        loads = {name: f(at) for name, f in given.items()}
        return bare_lift_off(scene.half_width, base, gap, loads,
                             np.full(at.size, -1 if lifting else 0), 32, 1e-10)

    def lifts(t: float) -> bool:
        try:
            elastic_at(np.array([t]), True)
        except ValueError:  # the heel's corner does not lift at these loads
            return False
        return True

    onset = first
    if full_first:
        lo, hi = first, last
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if lifts(mid) else (mid, hi)
        onset = hi
    pieces = [(lo, hi, lo >= onset) for lo, hi in ((first, onset), (onset, last)) if hi > lo]
    fits = []
    for lo, hi, lifting in pieces:
        at = points(lo, hi)
        zones = elastic_at(at, lifting)
        fits.append({name: interpolant(at, r(at) * zones.quantity(name))
                     for name in ("settlement", "tilt")})
    at_times = times >= onset
    elastic = elastic_at(times, True) if at_times.all() else \
        BareLiftOff(elastic_at(times[~at_times], False).zones
                    + elastic_at(times[at_times], True).zones)
    scale = r(times)
    histories = {}
    for name in ("settlement", "tilt", "force", "moment"):
        if name in problem.loads:
            histories[name] = load(name, times)
        elif name in ("force", "moment"):  # r times the elastic one, at each time itself
            histories[name] = scale * elastic.quantity(name)
        else:  # crept: (I - V) of r times the elastic one, piece by piece
            values = []
            for t in times:
                k = len(pieces) - 1 if t >= onset else 0
                value = float(fits[k][name](t))
                for (lo, hi, _), fit in zip(pieces, fits, strict=True):
                    if t > lo:
                        value -= memory(t, fit[name], lo, min(t, hi))
                values.append(value)
            histories[name] = np.array(values)
    return {"histories": histories, "elastic": elastic, "scale": scale}


def receding_errors(result, full_first: bool = False) -> dict[str, float]:
    """The errors of ``result`` (a ``SceneSolution`` of one punch on the bare base whose zone
    only recedes, heel lifting) against :func:`receding_reference`: the largest error of
    the settlement and tilt relative to the larger of the two, and of the force and moment
    likewise, as the solver's estimate reads them (``histories``), of q over ``|x| <=
    0.9 a`` relative to its largest there (``q``; the toe's corner, where q is infinite,
    left out) and of the zones' lower ends [half-widths] (``ends``)."""
    reference = receding_reference(result, full_first)
    a = result.scene.half_width
    # q / q* [Pa] at each output time
    scale = np.broadcast_to(result.scene.dimensionless.pressure_scale(result.times),
                            result.times.shape)
    got = {"settlement": result.settlement / a, "tilt": result.tilt,
           "force": result.force / (scale * a), "moment": result.moment / (scale * a * a)}
    exact = reference["histories"]

    def relative(names: tuple[str, str]) -> float:
        size = max(float(np.max(np.abs(exact[name]))) for name in names)
        return max(float(np.max(np.abs(got[name] - exact[name]))) for name in names) / size

    histories = max(relative(("settlement", "tilt")), relative(("force", "moment")))
    x = np.linspace(-0.9, 0.9, 37)
    q_exact = reference["elastic"].pressure(x, 1.0) * reference["scale"]
    q = float(np.max(np.abs(result.pressure(x * a) / scale - q_exact))
              / np.max(np.abs(q_exact)))
    lows = np.array([zones[0][0] for zones in result.contact_set])
    ends = float(np.max(np.abs(lows - [zone.lo for zone in reference["elastic"].zones])))
    return {"histories": histories, "q": q, "ends": ends}


def sparse_preset(name: str, contact: str, tol: float, count: int = 6) -> Any:
    """The preset ``name`` solved with ``count`` log-spaced output times over its 50 years
    (decades apart), ``contact`` and ``tol`` (``core.solve``)."""
    import copy

    import core

    scene = copy.deepcopy(core.load_scene(f"preset:{name}").to_dict())
    scene["times"] = {"end": 18262.5, "count": count, "spacing": "log"}
    scene["solver"] = {"tol": tol, "contact": contact}
    return core.solve(scene)
