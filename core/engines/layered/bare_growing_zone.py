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
then integrated in time; only ``r``, the kinematics and their relaxations are, as below. A
zone that grows and later recedes (or recedes and later grows) is refused (Ting's problem:
the answer depends on when each point was left).

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
from core.engines.layered.bare_lift_off import BareLiftOff, bare_lift_off
from core.engines.layered.solve import ERROR_FLOOR, LayeredResponse
from core.time import exponential_moments, time_grid

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
           "leaves the punch) and also grow: the bare base's creep is solved while the zone "
           "only grows or only recedes")
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
    histories on it, and, for a zone that recedes, the scale ``r`` of its q* (None: 1)."""

    grid: np.ndarray
    index: np.ndarray
    relax: np.ndarray
    parts: tuple[np.ndarray, np.ndarray] | None
    lifted: BareLiftOff
    histories: dict[str, np.ndarray]
    receding: bool = False
    relaxation: np.ndarray | None = None

    def pressure(self, x: np.ndarray, corner: float) -> np.ndarray:
        """q* at ``x`` on every grid point (len(x), grid): ``(I - V)^-1`` of the elastic
        zones' pressures, point by point (:func:`_relaxed`); a receding zone's own, times
        ``r``."""
        q_elastic = self.lifted.pressure(x, corner)
        if self.receding:
            return q_elastic if self.relaxation is None else q_elastic * self.relaxation
        if self.parts is None:
            return solve_triangular(self.relax, q_elastic.T, lower=True).T
        lo = np.array([z.lo for z in self.lifted.zones])
        hi = np.array([z.hi for z in self.lifted.zones])
        onset = _onsets(self.grid, lo, hi, np.clip(np.asarray(x, dtype=float), -corner,
                                                   corner))
        return _relaxed(self.grid, self.parts, q_elastic, onset)


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
    values = {name: np.broadcast_to(np.asarray(load(grid) if callable(load) else load,
                                               dtype=float), grid.shape).copy()
              for name, load in loads.items()}
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


class ZoneTurns(ValueError):
    """:data:`RECEDES`: the zone of a trial (growing or receding) turned between the grid
    times ``between`` (dimensionless), where that trial stops holding."""

    def __init__(self, between: tuple[float, float]) -> None:
        super().__init__(RECEDES)
        self.between = between


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
                       jumps: Sequence[float] = ()) -> GrowingZone:
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
    A zone that only recedes instead is answered too, its q* ``r`` times an elastic one
    (see above).
    Raises ValueError (:data:`RECEDES`) where the zone grows and recedes,
    (:data:`RELEASES`) where a receding zone meets a kernel that is positive somewhere,
    (:data:`UNRELAXED`) where its ``r`` is not positive, or where the kernel is not
    finite on the grid.
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
    receding = False
    for level in range(MAX_HALVINGS + 1):
        grid, _, index = time_grid(times, FIRST_STEPS, level, jumps)
        try:
            grids.append(_on_grid(half_width, base, gap, stepping, loads, response, grid,
                                  index, modes, tol, lift_off_share, solved, receding))
        except ValueError as growing:
            if level > 0 or receding:
                raise
            # the zone recedes (or the growing trial's crept loads found no zone: the
            # receding one's are other loads); elastic zones of the same loads found so
            # far are reused (solved)
            receding = True
            try:
                grids.append(_on_grid(half_width, base, gap, stepping, loads, response,
                                      grid, index, modes, tol, lift_off_share, solved,
                                      receding))
            except ValueError as other:
                if str(other) == RECEDES and str(growing) != RECEDES:
                    # it grows after all: the growing trial's own refusal says why
                    raise growing from None
                if isinstance(other, ZoneTurns) and isinstance(growing, ZoneTurns) and \
                        growing.between > other.between:
                    # the zone grows, then recedes: the growing trial held until its turn
                    raise growing from None
                raise
        if nodes is None:
            # q* is compared where the zones lie (a growing zone's last, largest one; a
            # receding zone's first), densely: the points an end sweeps get or lose their
            # pressure as it passes, less smoothly in time
            largest = grids[-1].lifted.zones[0 if receding else -1]
            nodes = largest.centre + largest.half * np.cos(
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
            time_error = max(histories / 7.0, pressure / 3.0)
        if time_error <= tol / TIME_SHARE:
            break
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
    return GrowingZone(histories, zones, pressure,
                       float(time_error + fit_error), float(fit_error), float(error),
                       float(end_error), int(fine.grid.size - 1),
                       max(z.response.modes for z in zones_fine),
                       max(z.response.nodes for z in zones_fine))
