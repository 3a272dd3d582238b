"""A punch lifting off the bare base that creeps or ages while its contact zone grows.

Without coating the base's equation is ``(I - V) F q*(., t) = delta*(t) + alpha(t) x - g*``
on the zone (:mod:`core.engines.layered.bare_creep`; ``V`` acts on time alone, ``F`` on
space alone, and they commute). So ``Q = (I - V) q*`` solves, at each time, the *elastic*
contact problem (:mod:`core.engines.layered.bare_lift_off`) with the given kinematics as
they are and the given force and moment replaced by ``(I - V) P*`` and ``(I - V) M*``
(the force and moment of ``Q``). Where the zone never recedes, every point in contact
stays in contact, ``q* = (I - V)^-1 Q`` vanishes where ``Q`` always did, and the answer is
that of the elastic zones in turn (Graham's theorem for a contact zone that does not
shrink; the hereditary integral of Lee and Radok for a growing Hertz contact). A zone
that recedes (the heel lifting further as the base creeps) breaks it: the points left
behind keep a pressure history the elastic zones do not carry.

A zone that only recedes is the other side of the same symmetry. With ``r = (I - V)^-1 1``
(the base's relaxation of a unit settlement, which must stay > 0: checked on the grid,
else refused) and the given kinematics relaxed,
``delta~ = (I - V)^-1 delta*``, ``alpha~ = (I - V)^-1 alpha``, take ``q*(., t) = r(t) q_e``
where ``q_e`` is the elastic answer with the gap ``g*`` of the loads ``delta~ / r``, ``alpha~ /
r``, ``P* / r``, ``M* / r`` (the two given ones; a flat punch needs no ``r``: its answer is
homogeneous in the loads). On the zone at ``t`` every point has touched since loading, so
there ``F q*(., tau) = delta_r + alpha_r x - r g*`` at every earlier ``tau`` too (``delta_r =
r delta_e``, ``alpha_r = r alpha_e``), and ``(I - V)`` of it is ``delta* + alpha x - g*`` with
the settlement and tilt ``(I - V) delta_r``, ``(I - V) alpha_r`` (given or not). Outside it
the gap is ``(I - V)`` of ``r`` times the elastic gaps, ``u(t) - int K u``, which stays >= 0
where ``K <= 0`` (a base that creeps: checked on the grid, else refused). No pressure is
then integrated in time; only ``r``, the kinematics and their relaxations are, as below.

A zone that grows and recedes in turn (Ting's problem: the answer depends on when each
point was reached and left) is marched (:func:`_marched`). With ``W = F q*`` and ``s >= 0``
the true separation (0 on the zone), ``(I - V) W = delta* + alpha x - g* + s`` at every
point, so on the zone at ``t``, where ``s(t) = 0``,
``F q*(t) = delta~ + alpha~ x - r g* + S`` with ``S = ((I - V)^-1 - I) s``: the separations
of earlier times only. Each grid point is one elastic zone under the gap ``r g* - S``
(:func:`core.engines.layered.bare_lift_off.lift_off_zone`), the given force and moment as
they are, the given kinematics relaxed, the unknown ones ``(I - V)`` of the zone's; the
separation off it is the true one (a share ``1 - L`` of the elastic one, ``L`` the
step's own weight), read from the zone's displacement
(:func:`core.engines.layered.bare_lift_off.zone_displacement`). ``S`` is kept at fixed
points by :class:`_Memory`. Where its estimate (the zones' own error and the time steps')
is over tol, the turn is refused as before, saying why.

In time: the grids of :func:`core.time.time_grid` (every output time a
grid point), one elastic lift-off solve per grid point. ``V`` of a kernel ``b(tau) + sum_r
a_r(tau) exp(-rate_r (t - tau))`` integrates its exponentials exactly against the
histories taken linear between grid points (the trapezoid rule erred by 1 % at ``rate h ~
1``, enough to make a growing zone seem to recede), and a point that a free end reaches
at ``tau_x`` gets its pressure like ``sqrt(tau - tau_x)``, so there the history is taken
as that root times a linear function (:func:`_step_weights`). The grids are halved and the
outputs (the four histories and q* over the last zone) extrapolated as the unilateral
creep stepping does (:mod:`core.contact.creep`): with two grids the finer plain outputs'
difference / 3 is the estimate, with three or more the last two extrapolations'
difference / 7 for the histories and / 3 for q* (the onsets fall anywhere in the steps),
until it meets ``tol / TIME_SHARE`` or :data:`MAX_HALVINGS` is reached (then the answer
says so).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.linalg import solve_triangular

from core.creep import stepping_kernel
from core.engines.layered.bare_lift_off import (
    BareLiftOff,
    ZoneAnswer,
    bare_lift_off,
    bare_table,
    lift_off_zone,
    zone_displacement,
)
from core.engines.layered.solve import (
    ERROR_FLOOR,
    PRESSURE_REACH,
    LayeredResponse,
    layered_response,
)
from core.time import exponential_moments, time_grid
from core.work import check_work

__all__ = ["GrowingZone", "RECEDES", "RELEASES", "UNRELAXED", "ZoneTurns", "flat_punch",
           "solve_growing_zone"]

#: Nominal steps of the first time grid (every output time is a grid point as well).
FIRST_STEPS = 16
#: Grid halvings at most (each doubles the elastic solves).
MAX_HALVINGS = 4
#: The time stepping aims this many times below tol (its Richardson estimate, as the
#: other creep paths take theirs).
TIME_SHARE = 3.0
#: A zone end may move back by this many half-widths between grid points and still count
#: as not receding (the ends are found to ~1e-13; their modes' error is far smaller).
RECEDE_SLACK = 1e-9
#: A grid step this short [relative] is the two sides of a load's jump (``time_grid``).
JUMP_STEP = 1e-9
#: Why a growing-zone answer was not given.
RECEDES = ("the contact zone would recede as the base creeps (a point that touched "
           "leaves the punch) and also grow")
#: Why a zone that only recedes was not given (the kernel releases creep somewhere).
RELEASES = ("the creep kernel K(t, tau) is positive somewhere on the time grid: a receding "
            "zone's lifted points could close onto the punch again")
#: Why a receding zone was not given (the base's relaxation of a unit settlement is not
#: positive on the grid, which a creeping base's always is).
UNRELAXED = ("the base's relaxation (I - V)^-1 1 is not positive on the time grid: a "
             "receding zone is not answered there")

_NAMES = ("settlement", "tilt", "force", "moment")
_STATIC = ("force", "moment")


@dataclass(frozen=True)
class GrowingZone:
    """The answer at the output times: the four histories (dimensionless), the zone per
    output time ``(lo, hi)``, ``pressure(x, corner)`` (len(x), times) its q*, the
    estimates ``time_error`` (relative, the kernel fit's included), ``error`` (the zones'
    own, relative), ``end_error`` [half-widths], and ``steps`` of the finest grid."""

    histories: dict[str, np.ndarray]
    zones: list[tuple[float, float]]
    pressure: Any
    time_error: float
    fit_error: float
    error: float
    end_error: float
    steps: int
    modes: int
    nodes: int


def _trapezoid(grid: np.ndarray) -> np.ndarray:
    """Weights ``T`` of the trapezoid rule: ``int_1^{t_i} f = sum_j T_ij f_j``."""
    n = grid.size
    h = np.diff(grid)
    weights = np.zeros((n, n))
    for i in range(1, n):
        weights[i, :i] += 0.5 * h[:i]
        weights[i, 1:i + 1] += 0.5 * h[:i]
    return weights


def _linear_weights(rates: np.ndarray, h: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(early, late)`` (rates, steps): ``int_0^h exp(-rate (h - s)) g(s) ds = early
    g(0) + late g(h)`` for ``g`` linear over a step of length ``h``, from the moments
    ``mu_k(rate h)`` of :func:`core.time.exponential_moments` (``late = h mu_1``, ``early
    = h (mu_0 - mu_1)``)."""
    mu = exponential_moments(np.asarray(rates, dtype=float)[:, None] * h[None, :], 2)
    return h * (mu[..., 0] - mu[..., 1]), h * mu[..., 1]


def _exponential_weights(grid: np.ndarray, rate: float) -> np.ndarray:
    """Weights ``C`` with ``int_1^{t_i} exp(-rate (t_i - tau)) g(tau) dtau = sum_j C_ij g_j``
    for ``g`` linear between the grid points, the exponential integrated exactly."""
    early, late = _linear_weights(np.array([rate]), np.diff(grid))
    early, late = early[0], late[0]
    n = grid.size
    # decay from the end of step k (grid point k) to grid point i >= k
    decay = np.exp(-rate * np.clip(grid[:, None] - grid[None, 1:], 0.0, None))
    decay = np.tril(decay, -1)  # rows i, columns k - 1 for k = 1..n-1: i >= k
    weights = np.zeros((n, n))
    weights[:, :-1] += decay * early[None, :]
    weights[:, 1:] += decay * late[None, :]
    return weights


def _volterra(kernel: Any, grid: np.ndarray) -> np.ndarray:
    """``V`` on ``grid``: ``(V f)_i = sum_j V_ij f_j`` for ``f`` linear between the grid
    points.

    A kernel ``b(tau) + sum_r a_r(tau) exp(-rate_r (t - tau))`` has its exponentials
    integrated exactly against ``a_r f`` (the trapezoid rule on ``exp(-rate (t - tau))``
    erred by 1 % at ``rate h ~ 1``, where the stepping's steps are; a constant load is then
    exact) and ``b f`` by the trapezoid rule; any other kernel by the trapezoid rule."""
    if hasattr(kernel, "rates") and hasattr(kernel, "factors"):
        b, a = kernel.factors(grid)
        volterra = _trapezoid(grid) * np.asarray(b, dtype=float)[None, :]
        for rate, amplitude in zip(np.asarray(kernel.rates, dtype=float),
                                   np.asarray(a, dtype=float), strict=True):
            volterra += _exponential_weights(grid, float(rate)) * amplitude[None, :]
        values = volterra
    else:
        values = np.asarray(kernel(grid[:, None], grid[None, :]), dtype=float)
        values = _trapezoid(grid) * np.tril(np.broadcast_to(values, (grid.size, grid.size)))
    if not np.all(np.isfinite(values)):
        raise ValueError("kernel: K(t, tau) is not finite on the time grid")
    return values


def _free_corners(response: LayeredResponse, given: dict[str, np.ndarray],
                  share: float) -> np.ndarray:
    """Per value of ``given`` which corner the full-contact answer pulls at: -1, +1, 2
    (both) or 0 (none): where ``sqrt(1 - t^2) q*`` is below ``-share`` times its largest
    size, as the full-contact answer is read for lift-off."""
    four = response.complete(given)
    theta = np.linspace(0.0, np.pi, 8 * response.modes + 1)
    regular = response.regular_part(np.cos(theta), four["settlement"], four["tilt"])
    pulls = share * np.max(np.abs(regular), axis=0)
    lower, upper = regular[-1] < -pulls, regular[0] < -pulls
    return np.where(lower & upper, 2, np.where(lower, -1, 0) + np.where(upper, 1, 0))


#: Gauss-Legendre points of the product rule where q* rises from a swept point's onset.
_GAUSS = np.polynomial.legendre.leggauss(16)


def _kernel_parts(kernel: Any, grid: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """``(rates, amplitudes)`` of ``K = b + sum_r a_r exp(-rate_r (t - tau))`` on the grid,
    ``b`` as the part of rate 0: shapes (R + 1,), (R + 1, grid); None for another kernel."""
    if not (hasattr(kernel, "rates") and hasattr(kernel, "factors")):
        return None
    b, a = kernel.factors(grid)
    rates = np.concatenate([[0.0], np.asarray(kernel.rates, dtype=float)])
    amplitudes = np.vstack([np.broadcast_to(np.asarray(b, dtype=float), grid.shape),
                            np.asarray(a, dtype=float).reshape(-1, grid.size)])
    return rates, amplitudes


def _onsets(grid: np.ndarray, lo: np.ndarray, hi: np.ndarray, x: np.ndarray) -> np.ndarray:
    """When each point ``x`` enters the growing zone ``[lo, hi]`` (per grid point): the
    first grid time if it lies in the first zone, ``inf`` if never, else the time the end
    crossing it reaches it, on the cubic through the end's four nearest grid values (q*
    rises like the root of the time since: an onset off by ``d`` puts q* beside it off by
    ``d / (2 sqrt(t - onset))``; linear, ``d ~ h^2`` left q* converging like ``h^1.5``)."""
    inside = (x[:, None] > lo[None, :]) & (x[:, None] < hi[None, :])
    onset = np.full(x.shape, np.inf)
    for m in np.flatnonzero(inside.any(axis=1)):
        k = int(np.argmax(inside[m]))
        if k == 0 or grid[k] - grid[k - 1] <= JUMP_STEP * max(1.0, abs(grid[k])):
            # in the first zone, or reached as a given load jumps: its pressure starts at
            # once, not like a root of the time since, and is taken linear as the rest
            onset[m] = grid[0]
            continue
        end = lo if x[m] <= lo[k - 1] else hi
        near = np.arange(max(0, min(k - 2, grid.size - 4)), min(grid.size, max(k - 2, 0) + 4))
        if np.any(np.diff(grid[near]) <= JUMP_STEP * max(1.0, abs(grid[k]))):
            near = near[:0]  # the two sides of a jump among them: the linear crossing
        h = grid[k] - grid[k - 1]
        share = (x[m] - end[k - 1]) / (end[k] - end[k - 1])
        t = grid[k - 1] + h * float(np.clip(share, 0.0, 1.0))
        if near.size == 4:
            centre, scale = grid[k - 1], h
            cubic = np.polynomial.Polynomial.fit((grid[near] - centre) / scale,
                                                 end[near] - x[m], 3, domain=[-1, 1],
                                                 window=[-1, 1])
            slope = cubic.deriv()
            s_ = (t - centre) / scale
            for _ in range(8):  # Newton from the linear crossing
                step = cubic(s_) / slope(s_) if slope(s_) != 0 else 0.0
                s_ = float(np.clip(s_ - step, 0.0, 1.0))
            t = centre + scale * s_
        onset[m] = t
    return onset


def _step_weights(grid: np.ndarray, rates: np.ndarray, onset: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Weights ``(early, late)`` (points, rates, steps) of the product rule for ``int
    exp(-rate (t_j - tau)) g(tau) dtau`` over each step ``j``: ``g`` linear between the grid
    points, or, after a point's onset ``tau_x``, ``g = sqrt(tau - tau_x) psi`` with ``psi``
    linear (constant over the step of the onset). A point swept by a free end gets its
    pressure like the square root of the time since: interpolated linearly, its
    hereditary integral converged like ``h^1.5`` (q* off by 2e-4 after 376 steps of a
    Hertz contact growing on a creeping base); with the root taken out, like ``h^2``."""
    h = np.diff(grid)
    early, late = _linear_weights(rates, h)
    count = onset.size
    early = np.broadcast_to(early, (count,) + early.shape).copy()
    late = np.broadcast_to(late, (count,) + late.shape).copy()
    swept = np.isfinite(onset) & (onset > grid[0])
    nodes, weights = _GAUSS
    for m in np.flatnonzero(swept):
        tau_x = onset[m]
        steps = np.flatnonzero(grid[1:] > tau_x)
        start = np.maximum(grid[steps], tau_x)
        end = grid[steps + 1]
        u0, u1 = np.sqrt(start - tau_x), np.sqrt(end - tau_x)
        mid, half = 0.5 * (u0 + u1), 0.5 * (u1 - u0)
        u = mid[:, None] + half[:, None] * nodes[None, :]      # (steps, nodes)
        tau = tau_x + u * u
        # dtau = 2 u du, and the root sqrt(tau - tau_x) = u
        base = 2.0 * u * u * (half[:, None] * weights[None, :])
        rising = (tau - grid[steps][:, None]) / h[steps][:, None]
        onset_step = grid[steps] <= tau_x
        fading = np.where(onset_step[:, None], 0.0, 1.0 - rising)
        rising = np.where(onset_step[:, None], 1.0, rising)
        below = np.sqrt(np.maximum(grid[steps] - tau_x, 0.0))
        for r, rate in enumerate(rates):
            decay = np.exp(-rate * (end[:, None] - tau)) * base
            late[m, r, steps] = (decay * rising).sum(axis=1) / u1
            with np.errstate(divide="ignore", invalid="ignore"):
                early[m, r, steps] = np.where(onset_step, 0.0,
                                              (decay * fading).sum(axis=1) / below)
        before = np.flatnonzero(grid[1:] <= tau_x)
        early[m, :, before] = 0.0
        late[m, :, before] = 0.0
    return early, late


def _relaxed(grid: np.ndarray, parts: tuple[np.ndarray, np.ndarray], values: np.ndarray,
             onset: np.ndarray) -> np.ndarray:
    """``(I - V)^-1`` of ``values`` (points, grid) over the grid: each point's q* from its
    elastic pressures, marched step by step (the exponentials as states)."""
    rates, amplitudes = parts
    early, late = _step_weights(grid, rates, onset)
    h = np.diff(grid)
    out = np.zeros(values.shape)
    out[:, 0] = values[:, 0]
    states = np.zeros((values.shape[0], rates.size))
    for i in range(1, grid.size):
        states = (states * np.exp(-rates * h[i - 1])[None, :]
                  + early[:, :, i - 1] * amplitudes[None, :, i - 1] * out[:, i - 1, None])
        diagonal = (late[:, :, i - 1] * amplitudes[None, :, i]).sum(axis=1)
        out[:, i] = (values[:, i] + states.sum(axis=1)) / (1.0 - diagonal)
        states = states + late[:, :, i - 1] * amplitudes[None, :, i] * out[:, i, None]
    return out


@dataclass(frozen=True)
class _Grid:
    """One time grid's answer: the grid, ``A = I - V`` on it, the kernel's parts on it
    (None: not a sum of exponentials), the elastic zones at its points, the four
    histories on it, whether q* is the zones' own pressure (``own``: a zone that
    recedes, or one marched with the memory of its separations) and, for a zone that
    recedes, the scale ``r`` of its q* (None: 1)."""

    grid: np.ndarray
    index: np.ndarray
    relax: np.ndarray
    parts: tuple[np.ndarray, np.ndarray] | None
    lifted: BareLiftOff
    histories: dict[str, np.ndarray]
    own: bool = False
    relaxation: np.ndarray | None = None

    def pressure(self, x: np.ndarray, corner: float) -> np.ndarray:
        """q* at ``x`` on every grid point (len(x), grid): ``(I - V)^-1`` of the elastic
        zones' pressures, point by point (:func:`_relaxed`); the zones' own where ``own``
        (a receding zone's times ``r``)."""
        q_elastic = self.lifted.pressure(x, corner)
        if self.own:
            return q_elastic if self.relaxation is None else q_elastic * self.relaxation
        if self.parts is None:
            return solve_triangular(self.relax, q_elastic.T, lower=True).T
        lo = np.array([z.lo for z in self.lifted.zones])
        hi = np.array([z.hi for z in self.lifted.zones])
        onset = _onsets(self.grid, lo, hi, np.clip(np.asarray(x, dtype=float), -corner,
                                                   corner))
        return _relaxed(self.grid, self.parts, q_elastic, onset)


def _load_values(loads: dict[str, Any], grid: np.ndarray) -> dict[str, np.ndarray]:
    """The given loads (callables of dimensionless time, or constants) on ``grid``."""
    return {name: np.broadcast_to(np.asarray(load(grid) if callable(load) else load,
                                             dtype=float), grid.shape).copy()
            for name, load in loads.items()}


def flat_punch(gap: Any) -> bool:
    """Whether the punch is flat (``g* = 0``: no relaxation scale is needed)."""
    return not callable(gap) and np.ndim(gap) == 0 and float(gap) == 0.0


def _on_grid(half_width: float, base: tuple[float, float, float], gap: Any, kernel: Any,
             loads: dict[str, Any], response: LayeredResponse, grid: np.ndarray,
             index: np.ndarray, modes: int, tol: float, share: float,
             solved: dict[tuple, Any], receding: bool = False) -> _Grid:
    volterra = _volterra(kernel, grid)
    relax = np.eye(grid.size) - volterra
    relaxation = None
    if receding:
        if np.any(volterra > RECEDE_SLACK * np.max(np.abs(volterra), initial=0.0)):
            raise ValueError(RELEASES)
        if not flat_punch(gap):
            relaxation = solve_triangular(relax, np.ones(grid.size), lower=True)
            if not np.all(relaxation > 0.0):
                raise ValueError(UNRELAXED)
    values = _load_values(loads, grid)
    given = {}
    for name, value in values.items():
        if not receding:
            # growing: the force and moment of Q = (I - V) q*, the kinematics as they are
            given[name] = relax @ value if name in _STATIC else value
            continue
        # receding: q* / r is the elastic answer of the relaxed kinematics and the given
        # force and moment, all divided by r
        relaxed = value if name in _STATIC else solve_triangular(relax, value, lower=True)
        given[name] = relaxed if relaxation is None else relaxed / relaxation
    free = _free_corners(response, given, share)
    lifted = bare_lift_off(half_width, base, gap, given, free, modes, tol, solved=solved)
    _check_monotone(lifted, receding, grid)
    if not receding:
        _check_no_pull(_Grid(grid, index, relax, _kernel_parts(kernel, grid), lifted, {}),
                       share)
    histories = {}
    scale = 1.0 if relaxation is None else relaxation
    for name in _NAMES:
        if name in loads:
            histories[name] = values[name]
        elif receding and name in _STATIC:  # the force and moment of q* = r q_e
            histories[name] = scale * lifted.quantity(name)
        elif receding:  # the kinematics of r q_e crept: delta* = (I - V) (r delta_e)
            histories[name] = relax @ (scale * lifted.quantity(name))
        elif name in _STATIC:  # P* = (I - V)^-1 P_Q
            histories[name] = solve_triangular(relax, lifted.quantity(name), lower=True)
        else:
            histories[name] = lifted.quantity(name)
    return _Grid(grid, index, relax, _kernel_parts(kernel, grid), lifted, histories,
                 receding, relaxation)


#: Chebyshev-Lobatto points across the punch, and across the stretch its zone's free ends
#: sweep, where the march keeps the memory of the separations (:func:`_memory_points`).
COARSE_POINTS = 129
BAND_POINTS = 1025
#: The stretch is widened by this share of its length (or of the narrowest zone's
#: half-width) on each side.
BAND_MARGIN = 0.25
#: Before the ends are known, the stretch reaches this far [half-widths] (at least the first
#: zone's half-width) either side of the first zone's free ends.
FIRST_BAND = 0.05
#: Marches of one grid, each with the stretch its ends swept in the last, at most.
BAND_TRIES = 3
#: Gauss-Legendre points of a step's integral of a point's separation (its 3/2 power where
#: the point's contact starts or ends taken out by ``u^2`` substitution).
_STEP_GAUSS = np.polynomial.legendre.leggauss(12)
#: Distances to a zone end [half-widths] below which a point's coefficient ``s / d^(3/2)`` is
#: not read (its separation is rounding there).
NEAR_END = 1e-6
#: A marched zone's pressure below ``-SIGN_SLACK tol`` times its largest, or a separation
#: below that share of the largest displacement, would need a second contact zone: refused.
SIGN_SLACK = 1.0
#: Why a marched zone was not given.
SECOND_ZONE = ("the memory of the creeping base would open a second contact zone or close "
               "a gap inside the zone (one zone per punch is followed)")


def _memory_points(band: tuple[float, float]) -> np.ndarray:
    """Where the march keeps its memory: ``COARSE_POINTS`` Chebyshev-Lobatto points of the
    punch and ``BAND_POINTS`` of ``band``, the stretch its zone's free ends sweep (the
    memory changes on the scale of the ends' motion there; elsewhere the points touch
    throughout or never)."""
    def lobatto(lo: float, hi: float, count: int) -> np.ndarray:
        return 0.5 * (lo + hi) - 0.5 * (hi - lo) * np.cos(np.pi * np.arange(count)
                                                           / (count - 1))
    points = np.sort(np.clip(np.concatenate([lobatto(-1.0, 1.0, COARSE_POINTS),
                                             lobatto(band[0], band[1], BAND_POINTS)]),
                             -1.0, 1.0))
    # the two sets share points (rounded apart): one of each, or the splines through them
    # would turn on steps of 1e-16
    return points[np.concatenate([[True], np.diff(points) > 1e-12])]


def _first_band(zone: ZoneAnswer) -> tuple[float, float]:
    """The stretch about the first zone's free ends, ``max(FIRST_BAND, its half-width)``
    either side (the whole punch where it touches fully)."""
    if zone.free == 0:
        return -1.0, 1.0
    reach = max(FIRST_BAND, zone.half)
    lo = zone.lo - reach if zone.free in (-1, 2) else zone.hi - reach
    hi = zone.hi + reach if zone.free in (1, 2) else zone.lo + reach
    return max(-1.0, lo), min(1.0, hi)


def _band(zones: Sequence[tuple[float, float]], free: Sequence[int]) -> tuple[float, float]:
    """The stretch of the punch the free ends of ``zones`` sweep, widened by
    ``BAND_MARGIN`` of its length (at least of the narrowest zone's half-width)."""
    ends = [z[0] for z, f in zip(zones, free, strict=True) if f in (-1, 2)] + \
        [z[1] for z, f in zip(zones, free, strict=True) if f in (1, 2)]
    if not ends:
        return -1.0, 1.0
    lo, hi = min(ends), max(ends)
    smallest = min(0.5 * (z[1] - z[0]) for z in zones)
    margin = BAND_MARGIN * max(hi - lo, smallest)
    return max(-1.0, lo - margin), min(1.0, hi + margin)


def _distance(x: np.ndarray, zone: tuple[float, float]) -> np.ndarray:
    """How far ``x`` lies off the zone ``(lo, hi)`` [-] (<= 0 on it): the separation grows
    like its 3/2 power from the zone's free ends."""
    return np.maximum(zone[0] - x, x - zone[1])


class _Memory:
    """The memory of the separations at fixed points (:func:`_memory_points`; see the
    module's notes).

    Per point ``x`` it keeps ``Y = (I - V)^-1 s`` as the kernel's exponential states
    ``state_r = int a_r(tau) exp(-rate_r (t - tau)) Y dtau`` and ``S = V Y = sum_r state_r``,
    the memory the gap carries. Over a step the part ``S`` of ``Y`` is taken linear in
    time; the separation ``s = C d^(3/2)`` with ``d`` the point's distance off the zone
    (linear in time between the two zones: where it changes sign the point's contact
    starts or ends within the step, where ``s`` vanishes like the 3/2 power of the time)
    and the coefficient ``C`` as :meth:`record` says. Linear in ``s`` itself, the memory
    summed over the grid kinks at every past end (a ``(lo - x)^(3/2)`` a step, ~h^2.5
    each); integrated with the power, it is twice differentiable in ``x`` and a cubic
    spline carries it to the points a zone's gap is read at.
    """

    def __init__(self, grid: np.ndarray, parts: tuple[np.ndarray, np.ndarray],
                 points: np.ndarray) -> None:
        self.grid = grid
        self.rates, self.amplitudes = parts
        self.points = points
        count = self.points.size
        self.states = np.zeros((count, self.rates.size))
        self.memory = np.zeros(count)       # S at the last recorded step
        self.coefficient = np.zeros(count)  # C = s / d^(3/2) there (0 on the zone)
        self.zone: tuple[float, float] | None = None
        self.step_n = 0
        self._smooth = np.zeros(count)
        self._late = 0.0

    def begin(self, n: int) -> None:
        """Start step ``n``: the part of the memory that does not depend on its zone."""
        self.step_n = n
        if n == 0:
            self._smooth = np.zeros(self.points.size)
            self._late = 0.0
            return
        h = self.grid[n] - self.grid[n - 1]
        early, late = _linear_weights(self.rates, np.array([h]))
        a0, a1 = self.amplitudes[:, n - 1], self.amplitudes[:, n]
        self._decayed = self.states * np.exp(-self.rates * h)[None, :] \
            + (early[:, 0] * a0)[None, :] * self.memory[:, None]
        self._smooth = self._decayed.sum(axis=1)
        self._late_r = late[:, 0] * a1
        self._late = float(self._late_r.sum())
        self._splines()

    def _integrals(self, n: int, d0: np.ndarray, d1: np.ndarray) -> dict[str, np.ndarray]:
        """The integrals (points, rates) ``int a_r(tau) exp(-rate_r (t_n - tau)) w d(tau)^(3/2)
        dtau`` over step ``n`` where ``d > 0`` (``d`` linear from ``d0`` to ``d1``, ``a_r``
        linear), with ``w`` the weight of each of ``C``'s values in its model over the step
        (:meth:`record`): ``"C0"`` at its start, ``"C1"`` at its end.

        Where ``d`` moves, in ``sigma = |theta - theta*|`` from its zero ``theta*`` (in the step
        or beyond it) as ``sigma = u^2``: ``d^(3/2) dtheta`` is then ``u^3 2 u du``, smooth, and
        Gauss's rule in ``u`` exact to rounding whether the end passes the point within the
        step or near it (in ``theta`` the power's root at or just beyond the step's end left
        1e-6 errors with 12 points, a kink in the memory at each end's place)."""
        t0, t1 = self.grid[n - 1], self.grid[n]
        h = t1 - t0
        a0, a1 = self.amplitudes[:, n - 1], self.amplitudes[:, n]
        g, wg = _STEP_GAUSS
        g, wg = 0.5 * (g + 1.0), 0.5 * wg
        change = d1 - d0
        moving = np.abs(change) > 1e-14 * np.maximum(np.abs(d0), np.abs(d1))
        with np.errstate(divide="ignore", invalid="ignore"):
            zero = np.where(moving, -d0 / change, 0.0)
        falling = change < 0.0
        # sigma's range off the zone within the step (empty where the point touches)
        low = np.where(falling, np.maximum(zero - 1.0, 0.0), np.maximum(-zero, 0.0))
        high = np.where(falling, zero, 1.0 - zero)
        high = np.where(moving, np.maximum(high, low), 0.0)
        u_low, u_high = np.sqrt(low), np.sqrt(high)
        u = u_low[:, None] + (u_high - u_low)[:, None] * g[None, :]
        sigma = u * u
        theta = np.where(falling[:, None], zero[:, None] - sigma, zero[:, None] + sigma)
        jac = 2.0 * u * (u_high - u_low)[:, None] * wg[None, :]
        d = np.abs(change)[:, None] * sigma
        # a point the end does not move past: d constant over the step
        still = ~moving & (d0 > 0.0)
        theta = np.where(still[:, None], g[None, :], theta)
        jac = np.where(still[:, None], wg[None, :], np.where(moving[:, None], jac, 0.0))
        d = np.where(still[:, None], d0[:, None], d)
        theta = np.clip(theta, 0.0, 1.0)
        base = h * jac * np.maximum(d, 0.0) ** 1.5                        # (points, G)
        amp = a0[None, None, :] + theta[:, :, None] * (a1 - a0)[None, None, :]
        decay = np.exp(-self.rates[None, None, :] * h * (1.0 - theta)[:, :, None])
        core = base[:, :, None] * amp * decay                               # (points, G, R)
        # C constant where the point's contact starts within the step (its value at the
        # step's start) or ends (at its end); linear off the zone throughout
        onset = ((d0 > 0.0) & (d1 <= 0.0))[:, None]
        offset = ((d0 <= 0.0) & (d1 > 0.0))[:, None]
        # off the zone throughout, C's values at the step's ends lean to the other where
        # the point is near the end (within the end's move over the step), so that the
        # model joins those of the points the end passes: C = C0 where the contact starts,
        # C = C1 where it ends (the memory twice differentiable across the end)
        reach = np.abs(change)[:, None]
        with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
            w0 = np.where(d0[:, None] > 0.0, 1.0 / (1.0 + (reach / d0[:, None]) ** 3), 0.0)
            w1 = np.where(d1[:, None] > 0.0, 1.0 / (1.0 + (reach / d1[:, None]) ** 3), 0.0)
        weights = {"C0": np.where(onset, 1.0, np.where(offset, 0.0,
                                                       w0 * (1.0 - theta) + (1.0 - w1) * theta)),
                   "C1": np.where(onset, 0.0, np.where(offset, 1.0,
                                                       (1.0 - w0) * (1.0 - theta) + w1 * theta))}
        return {name: (core * np.clip(w, 0.0, 1.0)[:, :, None]).sum(axis=1)
                for name, w in weights.items()}

    def _splines(self) -> None:
        """Step ``n``'s interpolants (cubic splines: twice differentiable, so a zone's
        coefficients move smoothly with its ends): the memory known before the step, one
        across the punch (split at the last zone's ends, where the memory is only twice
        differentiable, the two sides' splines disagreed by a few % and the zones'
        coefficients jumped as a Gauss point crossed there), and ``C`` off the last zone on
        each side."""
        from scipy.interpolate import CubicSpline  # here: see bare_lift_off._free_end

        lo, hi = self.zone
        distance = _distance(self.points, self.zone)
        self._smooth_spline = CubicSpline(self.points, self._smooth)
        self._coefficient_splines = []
        for pick in (self.points < lo, self.points > hi):
            usable = np.flatnonzero(pick & (distance > NEAR_END))
            self._coefficient_splines.append(None if usable.size < 3 else CubicSpline(
                self.points[usable], self.coefficient[usable]))

    def _coefficient_at(self, x: np.ndarray) -> np.ndarray:
        """The last step's ``C`` at points ``x``: off its zone interpolated, on it
        extrapolated from the side nearer ``x`` (``C`` is smooth off the zone, the 3/2 power
        divided out)."""
        lo, hi = self.zone
        out = np.zeros(x.shape)
        middle = 0.5 * (lo + hi)
        for pick, spline in zip((x < middle, x >= middle), self._coefficient_splines,
                                strict=True):
            if spline is not None and np.any(pick):
                out[pick] = spline(x[pick])
        return out

    def on_zone(self, zone: tuple[float, float], x: np.ndarray) -> np.ndarray:
        """``S`` at points ``x`` of the zone ``zone`` [-] (at step ``n`` with that zone):
        the memory the gap carries there."""
        x = np.asarray(x, dtype=float)
        n = self.step_n
        if n == 0:
            return np.zeros(x.shape)
        # the part that does not depend on the step's zone (one spline: _splines)
        smooth = self._smooth_spline(x)
        d0 = _distance(x, self.zone)
        onset = d0 > 0.0
        if np.any(onset):
            # points the zone reaches within the step: their separation's integral up to
            # where the end passes them (the end taken linear in time)
            d1 = _distance(x[onset], zone)
            parts = self._integrals(n, d0[onset], d1)
            smooth[onset] += self._coefficient_at(x[onset]) * parts["C0"].sum(axis=1)
        return smooth / (1.0 - self._late)

    def record(self, zone: tuple[float, float], elastic_gap: np.ndarray) -> np.ndarray:
        """Step ``n`` answered on ``zone``: ``elastic_gap`` the base's displacement at the
        points less the crept punch's ``delta~ + alpha~ x - r g*`` there (what the memory and
        the separation share, ``S + s``). Returns the separations there.

        Over the step ``s = C d^(3/2)`` (:meth:`_integrals`): ``C`` is ``s / d^(3/2)`` at an
        end of the step where the point is off the zone there (at the step's end unknown
        with ``s``: one linear equation per point), constant where the point's contact
        starts or ends within the step, and off the zone throughout linear between its two
        values, each leaning to the other within the end's move of the step from the end
        (so that the models join where the end passes and the memory stays twice
        differentiable there; ``s / d^(3/2)`` from a separation that vanishes is mostly
        the step's error)."""
        n = self.step_n
        d1 = _distance(self.points, zone)
        off1 = d1 > NEAR_END
        separation = np.zeros(self.points.size)
        coefficient = np.zeros(self.points.size)
        if n == 0:
            separation[d1 > 0.0] = elastic_gap[d1 > 0.0]
            coefficient[off1] = separation[off1] / d1[off1] ** 1.5
            self.states = np.zeros_like(self.states)
            self.memory = np.zeros(self.points.size)
        else:
            d0 = _distance(self.points, self.zone)
            parts = self._integrals(n, d0, d1)
            c0 = np.where(d0 > NEAR_END, self.coefficient, self._coefficient_at(self.points))
            late = self._late
            fixed = (c0[:, None] * parts["C0"]).sum(axis=1)
            per_s = np.zeros(self.points.size)
            per_s[off1] = parts["C1"][off1].sum(axis=1) / d1[off1] ** 1.5
            # elastic_gap = S + s, S = (smooth + fixed + per_s s) / (1 - late) off the zone
            separation[off1] = ((elastic_gap[off1] - (self._smooth[off1] + fixed[off1])
                                 / (1.0 - late)) / (1.0 + per_s[off1] / (1.0 - late)))
            coefficient[off1] = separation[off1] / d1[off1] ** 1.5
            # a point barely off the zone at the step's end keeps its C
            nearly = ~off1 & (d1 > 0.0)
            c1 = np.where(off1, coefficient, c0)
            separation[nearly] = c1[nearly] * d1[nearly] ** 1.5
            integral = c0[:, None] * parts["C0"] + c1[:, None] * parts["C1"]
            memory = (self._smooth + integral.sum(axis=1)) / (1.0 - late)
            self.states = self._decayed + self._late_r[None, :] * memory[:, None] + integral
            self.memory = memory
        self.coefficient = coefficient
        self.zone = zone
        return separation


def _own_gap(gap: Any, t: np.ndarray) -> np.ndarray:
    """The punch's gap ``g*`` at ``t`` (None or a number: constant)."""
    return (np.asarray(gap(t), dtype=float) if callable(gap)
            else np.full(np.shape(t), float(gap or 0.0)))


class _MarchStopped(ValueError):
    """The march refused a step (the message says why), with the zones found before it
    (and the refused one, where it was found)."""

    def __init__(self, reason: str, zones: list[ZoneAnswer]) -> None:
        super().__init__(reason)
        self.zones = zones


def _march(half_width: float, base: tuple[float, float, float], gap: Any, kernel: Any,
           loads: dict[str, Any], grid: np.ndarray, index: np.ndarray, modes: int,
           tol: float, share: float, band: tuple[float, float] | None
           ) -> tuple[_Grid, tuple[float, float]]:
    """:func:`_marched` with its memory dense where the ends went: marched again with the
    band the ends swept (at most ``BAND_TRIES`` times) until they stay within it. Returns
    the answer and its band."""
    for attempt in range(BAND_TRIES):
        try:
            answer = _marched(half_width, base, gap, kernel, loads, grid, index, modes, tol,
                              share, band)
            zones = answer.lifted.zones
        except _MarchStopped as stopped:
            if attempt == BAND_TRIES - 1 or len(stopped.zones) < 2:
                raise ValueError(str(stopped)) from None
            answer, zones = None, stopped.zones
        used = _first_band(zones[0]) if band is None else band
        swept = _band([(z.lo, z.hi) for z in zones], [z.free for z in zones])
        if answer is not None and used[0] <= swept[0] and swept[1] <= used[1]:
            return answer, used
        band = (min(used[0], swept[0]), max(used[1], swept[1]))
    return answer, band  # the last try held (a stopped last try raised above)


@dataclass(frozen=True)
class _MemoryGap:
    """The gap of one step of the march, ``r g* - S`` [-]: the punch's own gap relaxed and
    the memory ``S`` of the separations (:class:`_Memory`), which depends on the zone it is
    read for (:meth:`on_zone`; called directly: the whole punch's)."""

    gap: Any
    relaxation: float
    memory: _Memory

    def own(self, t: np.ndarray) -> np.ndarray:
        return self.relaxation * _own_gap(self.gap, np.asarray(t, dtype=float))

    def on_zone(self, lo: float, hi: float) -> Any:
        def gap(t: np.ndarray) -> np.ndarray:
            t = np.asarray(t, dtype=float)
            flat = t.ravel()
            return (self.own(flat) - self.memory.on_zone((lo, hi), flat)).reshape(t.shape)
        return gap

    def __call__(self, t: np.ndarray) -> np.ndarray:
        return self.on_zone(-1.0, 1.0)(t)


def _marched(half_width: float, base: tuple[float, float, float], gap: Any, kernel: Any,
             loads: dict[str, Any], grid: np.ndarray, index: np.ndarray, modes: int,
             tol: float, share: float, band: tuple[float, float] | None) -> _Grid:
    """The zone that grows and recedes in any order, marched over ``grid`` (see the
    module's notes): at each grid point one elastic zone under the gap ``r g* - S``, its
    given kinematics relaxed, its force and moment as given. The memory is kept densely
    over ``band`` (None: about the first zone's free ends, :data:`FIRST_BAND`); a refusal
    on the way is :class:`_MarchStopped`, with the zones found before it."""
    thickness, modulus, poisson = base
    parts = _kernel_parts(kernel, grid)
    if parts is None:
        raise ValueError(RECEDES)
    volterra = _volterra(kernel, grid)
    relax = np.eye(grid.size) - volterra
    inverse = solve_triangular(relax, np.eye(grid.size), lower=True)
    relaxation = inverse.sum(axis=1)
    values = _load_values(loads, grid)
    given = {name: value if name in _STATIC else inverse @ value
             for name, value in values.items()}
    table = bare_table(half_width, base, tol)
    memory = points = None
    zones: list[ZoneAnswer] = []
    near = before = None
    for k in range(grid.size):
        check_work("following the contact zone of a punch on the bare base that creeps, "
                   "step by step")
        if k == 0:
            # the first zone has no memory: it sets the band where none is given
            memory = _Memory(grid, parts, np.zeros(0))
        elif k == 1:
            if band is None:
                band = _first_band(zones[0])
            memory = _Memory(grid, parts, _memory_points(band))
            points = memory.points
            memory.begin(0)
            replay = zones[0]
            displacement = zone_displacement(replay, points, table)
            memory.record((replay.lo, replay.hi), displacement - (
                replay.values["settlement"] + replay.values["tilt"] * points
                - relaxation[0] * _own_gap(gap, points)))
        memory.begin(k)
        step_gap = _MemoryGap(gap, float(relaxation[k]), memory)
        step_loads = {name: float(value[k]) for name, value in given.items()}
        whole = layered_response(half_width, [], thickness, modulus, poisson, step_gap,
                                 modes=modes, table=table, tol=tol)
        free = int(_free_corners(whole, {name: np.array([v]) for name, v in
                                         step_loads.items()}, share)[0])
        try:
            zone = lift_off_zone(half_width, base, step_gap, step_loads, free, modes, tol,
                                 near, before)
        except ValueError as exc:
            raise _MarchStopped(str(exc), zones) from None
        # the pressure's sign is its regular part's (finite at a corner that touches)
        q = zone.response.regular_part(np.cos(np.linspace(0.0, np.pi, 4 * modes + 1)),
                                       np.array([zone.delta]), np.array([zone.alpha]))
        if k > 0:
            displacement = zone_displacement(zone, points, table)
            elastic_gap = displacement - (zone.values["settlement"] + zone.values["tilt"]
                                          * points - step_gap.own(points))
            last = memory.zone
            separation = memory.record((zone.lo, zone.hi), elastic_gap)
            size = max(float(np.max(np.abs(displacement))),
                       abs(zone.values["settlement"]) + abs(zone.values["tilt"]))
            # within twice the end's move of the step the separation is the memory's
            # model's (its step error, large beside a separation that vanishes there)
            now = _distance(points, (zone.lo, zone.hi))
            far = now > 2.0 * np.abs(now - _distance(points, last))
            if np.min(separation[far], initial=0.0) < -SIGN_SLACK * tol * size:
                at = points[far][int(np.argmin(separation[far]))]
                raise _MarchStopped(f"{SECOND_ZONE}: the base would press the punch at "
                                    f"x = {at:.4g} a, off the zone [{zone.lo:.4g}, "
                                    f"{zone.hi:.4g}] a, at t = {grid[k]:.4g}", zones + [zone])
        if np.min(q) < -SIGN_SLACK * tol * np.max(np.abs(q)):
            raise _MarchStopped(f"{SECOND_ZONE}: the pressure would pull inside the zone "
                                f"[{zone.lo:.4g}, {zone.hi:.4g}] a at t = {grid[k]:.4g}",
                                zones + [zone])
        zones.append(zone)
        before, near = near, zone
    lifted = BareLiftOff(zones)
    histories = {}
    for name in _NAMES:
        if name in loads:
            histories[name] = values[name]
        elif name in _STATIC:  # the zones' own: q* is the true pressure
            histories[name] = lifted.quantity(name)
        else:  # the zones' kinematics are the relaxed ones: delta* = (I - V) delta~
            histories[name] = relax @ lifted.quantity(name)
    return _Grid(grid, index, relax, None, lifted, histories, own=True)


class ZoneTurns(ValueError):
    """:data:`RECEDES`: the zone of a trial (growing or receding) turned between the grid
    times ``between`` (dimensionless), where that trial stops holding (``detail``: why the
    march step by step did not answer it either)."""

    def __init__(self, between: tuple[float, float], detail: str = "") -> None:
        super().__init__(RECEDES + (f"; followed step by step, {detail}" if detail else ""))
        self.between = between

    def because(self, detail: str) -> ZoneTurns:
        """The same turn, refused for ``detail`` (the march's own reason)."""
        return ZoneTurns(self.between, detail)


#: Why a growing zone was not given: its q* pulls at a corner in contact.
PULLS = ("the growing zone's pressure pulls at a corner in contact as the base creeps: "
         "the zone recedes there")
#: Where a growing zone's q* is read for its sign beside a corner in contact [half-widths
#: from the corner]: its singular part is positive there wherever the corner presses.
PULL_REACH = 1e-3


def _check_no_pull(answer: _Grid, share: float) -> None:
    """Refuse (ValueError :data:`PULLS`) a growing zone whose q* = ``(I - V)^-1 Q`` is
    below ``-share`` times its largest size beside a corner it touches: ``Q >= 0`` on the
    elastic zones of the crept loads does not make q* so. A ramped moment on an aging bare
    base, the crept eccentricity lagging the given one, kept the whole base in contact
    while q* at the heel reached -841 kPa (an audit; the zone recedes instead, and the
    receding answer holds)."""
    x = np.array([-1.0 + PULL_REACH, 1.0 - PULL_REACH])
    q = answer.pressure(x, 1.0 - PULL_REACH)
    touching = np.array([[z.lo <= -1.0 for z in answer.lifted.zones],
                         [z.hi >= 1.0 for z in answer.lifted.zones]])
    size = float(np.max(np.abs(q), initial=0.0))
    if np.any(touching & (q < -share * size)):
        raise ValueError(PULLS)


def _check_monotone(lifted: BareLiftOff, receding: bool, grid: np.ndarray) -> None:
    """Refuse (:class:`ZoneTurns`) a zone that recedes from one grid point to the next
    (that grows, when ``receding``)."""
    lo = np.array([z.lo for z in lifted.zones])
    hi = np.array([z.hi for z in lifted.zones])
    sign = -1.0 if receding else 1.0
    turned = (sign * np.diff(lo) > RECEDE_SLACK) | (sign * np.diff(hi) < -RECEDE_SLACK)
    if np.any(turned):
        k = int(np.argmax(turned))
        raise ZoneTurns((float(grid[k]), float(grid[k + 1])))


def _outputs(answer: _Grid, nodes: np.ndarray, corner: float) -> dict[str, np.ndarray]:
    out = {name: answer.histories[name][answer.index] for name in _NAMES}
    out["q"] = answer.pressure(nodes, corner)[:, answer.index]
    return out


def _reason(refused: ValueError) -> str:
    """A march's refusal, without the field its message names (the caller's names it)."""
    text = str(refused)
    return text.split(": ", 1)[1] if text.startswith("loading: ") else text


def _extrapolated(fine: np.ndarray, coarse: np.ndarray) -> np.ndarray:
    """Richardson's ``(4 fine - coarse) / 3`` of the outputs of a grid and its halving."""
    return (4.0 * fine - coarse) / 3.0


def _differences(a: dict[str, np.ndarray], b: dict[str, np.ndarray]) -> tuple[float, float]:
    """The largest relative differences (of the kinematics and the statics; of q*)."""
    def relative(names: tuple[str, ...]) -> float:
        size = max(max(float(np.max(np.abs(a[n]))) for n in names), 1e-300)
        return max(float(np.max(np.abs(a[n] - b[n]))) for n in names) / size
    return max(relative(("settlement", "tilt")), relative(_STATIC)), relative(("q",))


def solve_growing_zone(half_width: float, base: tuple[float, float, float], gap: Any,
                       kernel: Any, loads: dict[str, Any], times: np.ndarray,
                       response: LayeredResponse, modes: int, tol: float,
                       corner: float, lift_off_share: float,
                       jumps: Sequence[float] = (), march: bool = False) -> GrowingZone:
    """The punch lifting off the bare base that creeps or ages, its zone growing.

    ``half_width`` a [m]; ``base`` its thickness [m], modulus at loading [Pa] and Poisson
    ratio; ``gap`` g*; ``kernel`` the creep kernel of ``V``; ``loads`` two of delta*,
    alpha, P*, M* (callables of dimensionless time, or constants); ``times`` the output
    times (>= 1); ``response`` the whole punch's unit responses (its full-contact
    answer, which tells the corners that lift); ``modes`` its modes; ``tol`` [-];
    ``corner`` where q* is held near a corner in contact (its value is infinite there);
    ``lift_off_share`` how far below zero, relative, the full-contact pressure at a corner
    means that corner lifts; ``jumps`` the times where a given load jumps or kinks (each
    grid holds both sides of them).
    A zone that only recedes instead is answered too, its q* ``r`` times an elastic one;
    one that grows and recedes in turn (or recedes where the kernel or ``r`` would not
    let its lifted points stay off) is marched step by step with the memory of its
    separations (see above); ``march``: march whatever the zone does and answer with the
    march's estimates, met or not (to check the march against the paths above, where
    those answer, and against itself at a finer tol).
    Raises :class:`ZoneTurns` (:data:`RECEDES`) where the march does not meet ``tol``
    (its message says why), or ValueError where the kernel is not finite on the grid.
    """
    stepping, fit_error = stepping_kernel(kernel, float(times[-1]), 0.5 * tol)
    # a halved grid holds the points of the last: where their crept loads are the same
    # (constant or linear loads, given kinematics), their zones are found once
    solved: dict[tuple, Any] = {}
    plain: list[dict[str, np.ndarray]] = []
    extrapolations: list[dict[str, np.ndarray]] = []
    grids: list[_Grid] = []
    time_error = np.inf
    nodes = None
    mode = "growing"
    band = None

    def on_grid(grid: np.ndarray, index: np.ndarray) -> _Grid:
        nonlocal band
        if mode == "marching":
            answer, band = _march(half_width, base, gap, stepping, loads, grid, index,
                                  modes, tol, lift_off_share, band)
            return answer
        return _on_grid(half_width, base, gap, stepping, loads, response, grid, index,
                        modes, tol, lift_off_share, solved, mode == "receding")

    turned: ZoneTurns | None = None  # the refusal of a march that does not meet tol
    if march:
        mode, turned = "marching", ZoneTurns((float(times[0]), float(times[-1])))
    for level in range(MAX_HALVINGS + 1):
        grid, _, index = time_grid(times, FIRST_STEPS, level, jumps)
        try:
            grids.append(on_grid(grid, index))
        except ValueError as growing:
            if turned is not None:
                raise turned.because(_reason(growing)) from None
            if level > 0 or mode != "growing":
                raise
            # the zone recedes (or the growing trial's crept loads found no zone: the
            # receding one's are other loads); elastic zones of the same loads found so
            # far are reused (solved)
            mode = "receding"
            try:
                grids.append(on_grid(grid, index))
            except ValueError as other:
                if not isinstance(growing, ZoneTurns):
                    if str(other) == RECEDES and str(growing) != RECEDES:
                        # it grows after all: the growing trial's own refusal says why
                        raise growing from None
                    raise
                # the zone grows and recedes (or recedes where the kernel or r would not
                # let a receding zone's lifted points stay off): marched step by step; the
                # turn is the refusal where that does not meet tol either
                # (the trial that held longer turned last)
                turned = other if isinstance(other, ZoneTurns) and \
                    other.between > growing.between else growing
                mode = "marching"
                try:
                    grids.append(on_grid(grid, index))
                except ValueError as failed:
                    raise turned.because(_reason(failed)) from None
        if turned is not None and not march:
            # the zones' own error does not fall as the grid is halved: over tol, no
            # halving helps (the turning heel of tests/engines/test_bare_lift_off.py at
            # tol 1e-4, marched anyway: the largest zone estimate 1.7e-4, 4.7e-4, 4.9e-5,
            # 4.8e-5, 7.3e-5 on grids of 27 to 417 points, while the 90th percentile fell
            # from 1.5e-4 to 5e-6; the worst zone's end, found with 16 to 512 modes,
            # wandered by 7e-5 half-widths while its settlement agreed to 3e-6)
            spatial = max(z.error for z in grids[-1].lifted.zones)
            if spatial > 0.5 * tol:
                raise turned.because(f"the zones' own estimated error {spatial:.1e} is over "
                                     f"half of tol {tol:.1e}")
            ends = max(grids[-1].lifted.zones[i].end_error for i in grids[-1].index)
            if ends > tol:
                raise turned.because(f"its zone ends' estimated error {ends:.1e} half-widths "
                                     f"is over tol {tol:.1e}")
        if nodes is None:
            # q* is compared where the zones lie (a growing zone's last, largest one; a
            # receding zone's first; the widest of a marched one), densely: the points an
            # end sweeps get or lose their pressure as it passes, less smoothly in time
            zones_now = grids[-1].lifted.zones
            largest = (max(zones_now, key=lambda z: z.half) if mode == "marching" else
                       zones_now[0 if mode == "receding" else -1])
            lo, hi = largest.lo, largest.hi
            if mode == "marching":
                # where q's error is read (PRESSURE_REACH): a corner's infinite pressure
                # would make the nodes' largest q, and any error beside it, look small
                lo, hi = max(lo, -PRESSURE_REACH), min(hi, PRESSURE_REACH)
            nodes = 0.5 * (lo + hi) + 0.5 * (hi - lo) * np.cos(
                np.linspace(0.0, np.pi, 4 * modes + 1)[1:-1])
        plain.append(_outputs(grids[-1], nodes, corner))
        if level > 0:
            extrapolations.append({name: _extrapolated(plain[-1][name], plain[-2][name])
                                   for name in plain[-1]})
        if level == 1:
            # the extrapolated outputs are reported with the finer plain ones' error,
            # |fine - coarse| / 3 (order 2), which bounds theirs
            time_error = max(_differences(plain[-1], plain[-2])) / 3.0
        elif level > 1:
            # two extrapolations: the histories at order 3 (as core.contact.creep
            # measured); q* at order 2 only, as the onsets fall anywhere in the steps of
            # each grid (its extrapolations' differences fell 4.8-9.3x a halving, and the
            # error at the densest points a crown's ends reach was 0.96x the difference / 7)
            histories, pressure = _differences(extrapolations[-1], extrapolations[-2])
            # a marched answer's histories carry the separations' memory, whose points
            # an end sweeps converge less smoothly: order 2 only, as q*
            time_error = max(histories / (3.0 if mode == "marching" else 7.0),
                             pressure / 3.0)
        if time_error <= tol / TIME_SHARE:
            break
    if turned is not None and not march and time_error + fit_error > tol / 2:
        raise turned.because(f"its time steps' estimated error {time_error + fit_error:.1e} "
                             f"is over tol {tol:.1e} after {MAX_HALVINGS} halvings")
    fine, coarse = grids[-1], grids[-2]
    extrapolated = _extrapolated
    histories = {name: extrapolations[-1][name] for name in _NAMES}
    for name in loads:  # given: kept exactly as given
        histories[name] = plain[-1][name]

    def pressure(x: np.ndarray, held: float) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        return extrapolated(fine.pressure(x, held)[:, fine.index],
                            coarse.pressure(x, held)[:, coarse.index])

    zones_fine = [fine.lifted.zones[i] for i in fine.index]
    zones_coarse = [coarse.lifted.zones[i] for i in coarse.index]
    # the zones at an output time depend on the statics' history only through (I - V) P*:
    # their ends are extrapolated too where both grids lift the same corners (an aging
    # kernel's a_r(tau) P* taken linear left the finer grid's ends 1.3e-7 off, their
    # difference / 3), with the finer grid's error as their estimate
    end_shift = max(max(abs(f.lo - c.lo), abs(f.hi - c.hi))
                    for f, c in zip(zones_fine, zones_coarse, strict=True)) / 3.0
    zones = [(float(_extrapolated(f.lo, c.lo)), float(_extrapolated(f.hi, c.hi)))
             if f.free == c.free else (f.lo, f.hi)
             for f, c in zip(zones_fine, zones_coarse, strict=True)]
    error = max(max(z.error for z in fine.lifted.zones), ERROR_FLOOR)
    end_error = max(z.end_error for z in zones_fine) + end_shift
    if turned is not None and not march and end_error > tol:
        raise turned.because(f"its zone ends' estimated error {end_error:.1e} half-widths "
                             f"is over tol {tol:.1e}")
    return GrowingZone(histories, zones, pressure,
                       float(time_error + fit_error), float(fit_error), float(error),
                       float(end_error), int(fine.grid.size - 1),
                       max(z.response.modes for z in zones_fine),
                       max(z.response.nodes for z in zones_fine))
