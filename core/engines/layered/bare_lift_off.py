"""Lift-off on the bare base: the contact zone of a punch without coating layers.

On a bare elastic base the pressure under a punch edge that touches is inverse-square-root
singular. Where the punch lifts off, the base leaves it smoothly: at the zone's free end
the pressure vanishes like the square root of the distance (the end is where the
singular coefficient is zero), while the end at the punch's corner keeps its singularity.

On a zone ``[c, d]`` of the punch (``t = x / a``), centred at ``x0 = (c + d) / 2`` with
half-width ``b = (d - c) / 2``, the base's equation (:mod:`core.engines.layered.solve`)

    (1 / pi) int_c^d k(lam (t - s)) q*(s) ds = delta* + alpha t - g*(t)

is, in ``sigma = (t - x0) / b``, that of a narrower punch of half-width ``b a`` (the
base's kernel depends on the distance alone):

    (1 / pi) int_{-1}^{1} k(lam b (sigma - s')) q*(s') ds'
        = (delta* + alpha x0) / b + alpha sigma - g*(x0 + b sigma) / b,

so the unit responses of that punch (:func:`core.engines.layered.solve.layered_response`,
the whole punch's kernel table) answer any zone: its settlement ``delta' = (delta* +
alpha x0) / b``, tilt ``alpha' = alpha``, force ``P' = P* / b`` and moment about ``x0``
``M' = (M* - x0 P*) / b^2``. Any two of the four given fix ``delta', alpha'`` (a 2 x 2
solve); the zone's free end is the root of the singular coefficient there
(``sqrt(1 - sigma^2) q*`` at ``sigma = -1`` or ``+1``), found by a scan and Brent's
method. Where the punch's heel (or toe) lifts, one end is free and the other corner
touches; where both corners lift (a crown pressed lightly), both ends are free, and the
zone's middle and half-width are the root of both coefficients (Powell's hybrid method,
from Hertz's half-width on a half-space, ``b = sqrt(2 R P* / pi)`` with ``R`` the crown's
radius at the gap's lowest point, or from the best of a scan of zones). From a nearby
zone (the last time-grid point's on a creeping base; the zone with all the modes for
the one with half of them) secant steps (:func:`_secant_end`) or Broyden's method from
its Jacobian (:func:`_broyden`) find the ends in a few layered solves, the bracketing
methods above taking over where they fail. A creeping or
aging bare base is answered on the elastic zone where the loads keep their ratio
(:mod:`core.engines.layered.answer`), and on the elastic zones of its crept loads where
the zone grows (:mod:`core.engines.layered.bare_growing_zone`).

The error: the zone's own mode truncation (``truncation_errors`` of
:mod:`core.engines.layered.solve`, as a full-contact solve estimates it) and the zone's
end, found again with half the modes: the answers' change between the two ends,
extrapolated as the modes' (``MAX_RATIO``). Under a gap of its own (a creeping base's
memory, :mod:`core.engines.layered.bare_growing_zone`), where that estimate is over a tenth
of tol, the ends are found with a quarter of the modes too, and the ratio of the two changes
(at least 1/2, ``LEAST_RATIO``) extrapolates them (``RATIO_SHARE``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from core.engines.layered.cache import LAYERED_TABLE, stack_key
from core.engines.layered.galerkin import COARSE_TOL, MAX_MODES, table_degree
from core.engines.layered.solve import (
    COARSE_ERROR_FLOOR,
    ERROR_FLOOR,
    MAX_RATIO,
    Gap,
    LayeredResponse,
    geometric_tail,
    layered_response,
    truncation_errors,
)
from core.kernel import RegularPartTable
from core.work import check_work

__all__ = ["BareLiftOff", "TWO_FREE_ENDS", "ZoneAnswer", "bare_lift_off", "bare_table",
           "lift_off_zone", "zone_displacement"]

_NAMES = ("settlement", "tilt", "force", "moment")
#: Zone ends tried before Brent's method, as shares of the way from the lifting corner
#: to the other (the root lies between the last two with opposite signs).
SCAN = np.linspace(0.0, 1.0, 17)[1:-1]
#: The zone's end is found to this many half-widths (far below what the modes resolve).
END_TOL = 1e-13
#: Secant steps from a nearby end (the last time-grid point's, or the same zone's with
#: all the modes) before the end is bracketed and found by Brent's method instead.
SECANT_STEPS = 10
#: Broyden's steps from a nearby zone with two free ends before Powell's method instead,
#: and the last step's size (relative) at which it has converged (as Powell's xtol).
BROYDEN_STEPS = 12
BROYDEN_XTOL = 1e-14
#: The forward-difference step of the first Jacobian of the two ends' coefficients.
JACOBIAN_STEP = 1e-7
#: How far past 1 a point's |sigma| (its place in a zone, ``(x - centre) / half``) is
#: still the zone's end, in roundings of the subtraction and the division: ``(1 + (1 +
#: |centre|) / half)`` of them (measured: up to 5 roundings for half-widths down to 0.05,
#: 25 below 0.03).
ROUNDINGS_OF_AN_END = 2.0
#: The second point of the secant for the zone with half the modes: this far from the
#: end found with all of them [half-widths] (their ends differ by ~1e-10 and less).
COARSE_STEP = 1e-8
#: A gap of its own (``lift_off_zone``) doubles the modes only while the zone's error
#: estimate falls below this share of the last one.
STALLED = 0.5
#: Why a zone with two free ends was not answered.
TWO_FREE_ENDS = ("loading: the punch lifts off the bare base at both corners and no contact "
                 "zone with two free ends was found for these loads (the crown's contact "
                 "would reach a corner or vanish)")
#: Under a gap of its own, a zone's estimates (of its answer and of its ends, from the
#: change with half the modes, ``MAX_RATIO / (1 - MAX_RATIO)`` times it) above this share of
#: tol are measured again from the change of half against a quarter of the modes too (a
#: third search of the ends, so only where the fixed ratio's estimate counts).
RATIO_SHARE = 0.1
#: ... and that ratio is taken at least this large: the estimate is then at least the last
#: change itself. Where the gap has a kink inside the zone the changes need not fall
#: steadily: a heel under ``0.005 t^2 + 0.002 (t - 0.8)_+^2.5`` (128 modes) changed its end
#: by 3.3e-7 from 64 modes, after ~3.5e-6 from 32 to 64 (a ratio of ~0.09), and was 1.2e-7
#: off the end with 512 modes; the measured ratio alone read 3.4e-8.
LEAST_RATIO = 0.5
#: Both free ends are taken when their singular coefficients are below this share of the
#: pressure's scale (the zone's force over its half-width).
TWO_ENDS_TOL = 1e-10
#: The same for a gap that carries a creeping base's memory (``lift_off_zone``).
MEMORY_ENDS_TOL = 1e-8
#: In the search for two free ends a zone more than twice as wide as the punch (log of
#: its half-width [half-widths]) is given these scaled coefficients (O(1) near a root):
#: no root lies there, and its layered solve would not be finite.
FARTHEST_LOG_HALF_WIDTH = float(np.log(2.0))
OUTSIDE_COEFFICIENT = 1e3
#: Zone middles and half-widths tried when no first zone is known (or Powell's method
#: from it failed): the best of them starts it again.
SCAN_MIDDLES = np.linspace(-0.9, 0.9, 19)
SCAN_HALF_WIDTHS = np.geomspace(0.002, 0.9, 12)


@dataclass(frozen=True)
class ZoneAnswer:
    """The answer on one zone: its ends ``lo``, ``hi`` [-], which end is free (``free``:
    -1 the lower, +1 the upper, 2 both, 0 none), the narrower punch's unit ``response`` and its
    settlement ``delta`` and tilt ``alpha`` (its own units), the four quantities of the
    whole punch (``values``), its ``error`` [-] relative and the end's uncertainty
    ``end_error`` [half-widths]."""

    lo: float
    hi: float
    free: int
    response: LayeredResponse
    delta: float
    alpha: float
    values: dict[str, float]
    error: float
    end_error: float
    #: With two free ends: the Jacobian of their singular coefficients in the zone's
    #: middle and log half-width where they were found (a nearby zone starts from it).
    jacobian: np.ndarray | None = None

    @property
    def centre(self) -> float:
        return 0.5 * (self.lo + self.hi)

    @property
    def half(self) -> float:
        return 0.5 * (self.hi - self.lo)

    def pressure(self, x: np.ndarray, corner: float) -> np.ndarray:
        """``q*`` at points ``x`` of [-1, 1] (0 off the zone); within ``1 - corner`` of the
        punch's corner the value there is held (q is infinite at the corner)."""
        x = np.clip(np.asarray(x, dtype=float), -corner, corner)
        s = (x - self.centre) / self.half
        out = np.zeros(x.shape)
        inside = (s > -1.0) & (s < 1.0)
        si = s[inside]
        regular = self.response.regular_part(si, np.array([self.delta]),
                                             np.array([self.alpha]))[:, 0]
        out[inside] = regular / np.sqrt((1.0 - si) * (1.0 + si))
        return out


def _zone(free: int, end: float) -> tuple[float, float]:
    """The zone whose free end (``free`` -1: lower, +1: upper) is at ``end``."""
    return (end, 1.0) if free < 0 else (-1.0, end)


def _kinematics(response: LayeredResponse, x0: float, b: float, given: dict[str, float],
                level: int = 0) -> tuple[float, float, dict[str, float]]:
    """The narrower punch's settlement and tilt (its units) from two of the whole punch's
    quantities, and all four of those."""
    c = response.coefficients if level == 0 else response.coarser[level - 1]
    force = np.pi * c[0]            # P' = force . (1, delta', alpha')
    moment = 0.5 * np.pi * c[1]     # M' about x0
    # each whole-punch quantity as const + row . (delta', alpha')
    rows = {"settlement": (0.0, np.array([b, -x0])),
            "tilt": (0.0, np.array([0.0, 1.0])),
            "force": (b * force[0], b * force[1:]),
            "moment": (b * b * moment[0] + b * x0 * force[0],
                       b * b * moment[1:] + b * x0 * force[1:])}
    names = [n for n in _NAMES if n in given]
    matrix = np.array([rows[n][1] for n in names])
    rhs = np.array([given[n] - rows[n][0] for n in names])
    delta, alpha = np.linalg.solve(matrix, rhs)
    values = {n: float(rows[n][0] + rows[n][1] @ (delta, alpha)) for n in _NAMES}
    return float(delta), float(alpha), values


@dataclass
class _Zones:
    """Unit responses of the zones met while one end is sought (a zone's response is
    built once)."""

    half_width: float
    base: tuple[float, float, float]   # H [m], E [Pa], nu
    gap: Gap
    modes: int
    table: RegularPartTable
    tol: float

    def __post_init__(self) -> None:
        self._kept: dict[tuple[float, float], LayeredResponse] = {}

    def sub_gap(self, x0: float, b: float) -> Gap:
        gap = self.gap
        on_zone = getattr(gap, "on_zone", None)
        if on_zone is not None:
            # a creeping base's memory reads the zone it is asked for (bare_growing_zone)
            gap = on_zone(x0 - b, x0 + b)
        if callable(gap):
            return lambda s: np.asarray(gap(x0 + b * np.asarray(s)), dtype=float) / b
        return None  # a constant gap is a settlement: no pressure of its own

    def keep(self, lo: float, hi: float, response: LayeredResponse) -> None:
        """Keep ``response`` as the zone ``(lo, hi)``'s (built for other loads)."""
        self._kept[(lo, hi)] = response

    def response(self, lo: float, hi: float) -> LayeredResponse:
        found = self._kept.get((lo, hi))
        if found is None:
            x0, b = 0.5 * (lo + hi), 0.5 * (hi - lo)
            thickness, modulus, poisson = self.base
            found = layered_response(b * self.half_width, [], thickness, modulus, poisson,
                                     self.sub_gap(x0, b), modes=self.modes,
                                     table=self.table, tol=self.tol)
            self._kept[(lo, hi)] = found
        return found

    def intensity(self, free: int, end: float, given: dict[str, float],
                  level: int = 0) -> float:
        """``sqrt(1 - sigma^2) q*`` at the free end of the zone ending there (its sign:
        > 0 the zone is too short, < 0 too long)."""
        lo, hi = _zone(free, end)
        x0, b = 0.5 * (lo + hi), 0.5 * (hi - lo)
        response = self.response(lo, hi)
        delta, alpha, _ = _kinematics(response, x0, b, given, level)
        return float(response.regular_part(np.array([float(free)]), np.array([delta]),
                                           np.array([alpha]), level=level)[0, 0])


def _secant_end(f: Callable[[float], float], x0: float, x1: float, lo: float, hi: float,
                rising: float) -> float | None:
    """The root of ``f`` in ``(lo, hi)`` where it rises in the direction ``rising``
    (+1 toward larger x, -1 toward smaller: the zone's end, f < 0 toward the lifting
    corner) by secant steps from ``x0`` and ``x1``, kept inside the bracket of the points
    of opposite signs once there is one (bisected where a step leaves it), to a last
    step of ``END_TOL``; None when the steps stall, leave ``(lo, hi)`` or end on a root
    crossed the other way (the caller brackets the root instead). The point returned is
    the last one evaluated (its zone's response is kept), within the last step of the
    root, or the midpoint of a bracket narrower than ``2 END_TOL``.
    """
    f0, f1 = f(x0), f(x1)
    below = above = None  # the latest points where f < 0 and f > 0
    for x, fx in ((x0, f0), (x1, f1)):
        if fx < 0.0:
            below = x
        elif fx > 0.0:
            above = x
    for _ in range(SECANT_STEPS):
        if f1 == f0:
            return None
        slope = (f1 - f0) / (x1 - x0)
        if slope * rising <= 0.0:
            return None  # near a root crossed the other way (or a turning point)
        if f1 == 0.0:
            return x1
        x2 = x1 - f1 / slope
        bisected = below is not None and above is not None and not (
            min(below, above) < x2 < max(below, above))
        if bisected:
            x2 = 0.5 * (below + above)
        if not lo < x2 < hi:
            return None
        if bisected and abs(above - below) <= 2.0 * END_TOL:
            return x2
        if not bisected and abs(x2 - x1) <= END_TOL:
            return x1
        x0, f0, x1, f1 = x1, f1, x2, f(x2)
        if f1 < 0.0:
            below = x1
        elif f1 > 0.0:
            above = x1
    return None


def _free_end(zones: _Zones, free: int, given: dict[str, float], level: int,
              near: float | None = None, second: float | None = None) -> float:
    """The free end of the zone (``free`` -1: the lower end lifts, +1: the upper);
    ``near``: an end found for nearby loads, from which secant steps start (a creeping
    base asks one zone per time-grid point, each near the last; the zone with half the
    modes is next to the one with all of them), with ``second`` as the other first point
    (default: ``COARSE_STEP`` away); where they fail, an end is bracketed about ``near``
    and found by Brent's method."""
    # here, not at the top: scipy.optimize brings scipy.fft and scipy.special, which a
    # solve that lifts off nothing need not load (tests/cli/test_cold_start.py)
    from scipy.optimize import brentq

    corner = float(free)                 # the lifting corner
    other = -float(free)

    def f(end: float) -> float:
        return zones.intensity(free, end, given, level)

    def root(a: float, b: float) -> float:
        return float(brentq(f, a, b, xtol=END_TOL, rtol=4 * np.finfo(float).eps))

    if near is not None and -1.0 < near < 1.0:
        # From a nearby end the secant converges in a few zones (a zone is a layered
        # solve): a crown on the creeping bare layer asked ~6 of Brent's bracketed
        # search per end.
        if second is None or not -1.0 < second < 1.0 or abs(second - near) <= END_TOL:
            second = near + COARSE_STEP * (other - corner) / 2
        found = _secant_end(f, near, second, -1.0, 1.0, rising=other - corner)
        if found is not None:
            return found
        # f < 0 toward the lifting corner, > 0 toward the other: widen a bracket about it
        width = 1e-3
        while width < 0.5:
            a = float(np.clip(near - width * (other - corner) / 2, min(corner, other),
                              max(corner, other)))
            b = float(np.clip(near + width * (other - corner) / 2, min(corner, other),
                              max(corner, other)))
            if a != b and f(a) < 0.0 < f(b):
                return root(a, b)
            width *= 8.0
    if f(corner) >= 0.0:
        raise ValueError(f"free: the corner at t = {corner:g} does not lift off")
    previous = corner
    for share in SCAN:
        end = corner + share * (other - corner)
        if f(end) > 0.0:
            return root(previous, end)
        previous = end
    raise ValueError("loading: no contact zone carries these loads on the bare base (the "
                     "singular pressure at the free end keeps its sign over the punch)")


@dataclass(frozen=True)
class BareLiftOff:
    """The lift-off answer at each load value: per value its :class:`ZoneAnswer`."""

    zones: list[ZoneAnswer]

    def quantity(self, name: str) -> np.ndarray:
        return np.array([z.values[name] for z in self.zones])

    def pressure(self, x: np.ndarray, corner: float) -> np.ndarray:
        """``q*`` (len(x), values)."""
        return np.stack([z.pressure(x, corner) for z in self.zones], axis=1)


def bare_lift_off(half_width: float, base: tuple[float, float, float], gap: Gap,
                  given: dict[str, np.ndarray], free: np.ndarray, modes: int, tol: float,
                  full_error: float = 0.0,
                  solved: dict[tuple, ZoneAnswer] | None = None) -> BareLiftOff:
    """The zone, the pressure and the four quantities of a punch lifting off the bare
    elastic base, at each value of the given loads.

    ``half_width`` a [m]; ``base`` its thickness H [m], modulus E [Pa] and Poisson ratio;
    ``gap`` g* as in :func:`core.engines.layered.solve.layered_response`; ``given`` two
    of delta*, alpha, P*, M* (arrays over the values); ``free`` per value -1 (the lower
    end lifts), +1 (the upper), 2 (both: a crown pressed lightly) or 0 (full contact
    holds: the whole punch's zone, whose
    error is ``full_error``, the full-contact solve's); ``modes`` the full-contact
    solve's; ``tol`` the accuracy asked for; ``solved``: the zones already found for
    other calls on the same punch, base, gap and tol (by corner and values; updated).
    """
    table = bare_table(half_width, base, tol)
    out: list[ZoneAnswer] = []
    solved = {} if solved is None else solved
    last: dict[int, ZoneAnswer] = {}  # the last zone found, per corner lifting
    before: dict[int, ZoneAnswer] = {}  # and the one before it
    for k in range(len(free)):
        # a creeping base asks one zone per time-grid point: the solve's CPU bound applies
        check_work("finding the contact zone of a punch lifting off the bare base")
        values = {n: float(np.asarray(v)[k]) for n, v in given.items()}
        if free[k] == 0:  # full contact holds at this value: the whole punch's zone
            zones = _Zones(half_width, base, gap, modes, table, tol)
            response = zones.response(-1.0, 1.0)
            delta, alpha, four = _kinematics(response, 0.0, 1.0, values)
            out.append(ZoneAnswer(-1.0, 1.0, 0, response, delta, alpha, four, full_error,
                                  0.0))
            continue
        # to 13 digits: the same crept load reached through other sums (a halved time grid)
        key = (int(free[k]), *sorted((n, float(f"{v:.13g}")) for n, v in values.items()))
        if key not in solved:
            solved[key] = _solve_one(half_width, base, gap, values, int(free[k]), modes,
                                     table, tol, near=last.get(int(free[k])),
                                     before=before.get(int(free[k])))
        out.append(solved[key])
        if last.get(int(free[k])) is not solved[key]:
            if int(free[k]) in last:
                before[int(free[k])] = last[int(free[k])]
            last[int(free[k])] = solved[key]
    return BareLiftOff(out)


def bare_table(half_width: float, base: tuple[float, float, float], tol: float
               ) -> RegularPartTable:
    """The bare base's regular part ``k(s) + ln|s|`` tabulated to ``2 a / H`` for a solve
    to ``tol`` (kept: :data:`core.engines.layered.cache.LAYERED_TABLE`)."""
    thickness, modulus, poisson = base
    degree = table_degree(tol)
    table, _ = LAYERED_TABLE.get_or_compute(
        (stack_key(half_width, [], thickness, modulus, poisson), degree),
        lambda: RegularPartTable(2 * half_width / thickness, [], thickness, modulus, poisson,
                                 degree=degree))
    return table


def lift_off_zone(half_width: float, base: tuple[float, float, float], gap: Gap,
                  given: dict[str, float], free: int, modes: int, tol: float,
                  near: ZoneAnswer | None = None,
                  before: ZoneAnswer | None = None) -> ZoneAnswer:
    """The zone answer of one set of loads under a gap of its own (a gap that changes from
    one call to the next, as the memory of a creeping base makes it).

    As :func:`bare_lift_off` at one value (``given``: two of delta*, alpha, P*, M* as
    numbers; ``free`` -1, +1, 2 or 0: full contact, the whole punch's answer with its
    truncation error), with ``near`` and ``before`` the answers of the last two calls
    (other gaps, other loads): the search for the ends starts from theirs, and no
    response of theirs is reused.
    """
    table = bare_table(half_width, base, tol)
    if free == 0:
        zones = _Zones(half_width, base, gap, modes, table, tol)
        response = zones.response(-1.0, 1.0)
        delta, alpha, four = _kinematics(response, 0.0, 1.0, given)
        return ZoneAnswer(-1.0, 1.0, 0, response, delta, alpha, four,
                          _own_error(response, delta, alpha, tol), 0.0)
    if near is not None and near.free != free:
        near = before = None
    if before is not None and before.free != free:
        before = None
    return _solve_one(half_width, base, gap, given, free, modes, table, tol, near=near,
                      before=before, same_gap=False)


def _own_error(response: LayeredResponse, delta: float, alpha: float, tol: float) -> float:
    """A zone's own truncation error [-] at its settlement and tilt (its units), as the
    full-contact solve estimates it."""
    floor = COARSE_ERROR_FLOOR if tol >= COARSE_TOL else ERROR_FLOOR
    kinematics = {"settlement": np.array([delta]), "tilt": np.array([alpha])}
    return float(max(truncation_errors(response, kinematics,
                                       response.complete(kinematics), floor).values()))


def zone_displacement(zone: ZoneAnswer, x: np.ndarray, table: RegularPartTable) -> np.ndarray:
    """The bare base's surface displacement ``(1 / pi) int k(lam (x - s)) q*(s) ds`` [-]
    under the zone's pressure at points ``x`` of [-1, 1], on the zone and off it.

    On the zone it is ``delta* + alpha x - g*`` (the equation solved); off it, minus that,
    the gap the base leaves under the punch. In the zone's ``sigma = (x - x0) / b`` the
    pressure is ``sum c_n T_n(sigma) / sqrt(1 - sigma^2)``: its logarithmic part in closed
    form, ``ln 2 c_0 + sum c_n T_n(sigma) / n`` on the zone and ``c_0 (ln 2 - ln(|sigma| +
    sqrt(sigma^2 - 1))) + sum c_n sign(sigma)^n (|sigma| - sqrt(sigma^2 - 1))^n / n`` off
    it; the regular part by Gauss-Chebyshev quadrature on the nodes of the zone's solve;
    times ``b`` (the zone's equation is the whole punch's divided by it).
    """
    x = np.asarray(x, dtype=float)
    b, response = zone.half, zone.response
    sigma = (x - zone.centre) / b
    c = response.coefficients @ np.array([1.0, zone.delta, zone.alpha])
    n = np.arange(1, c.size)
    size = np.abs(sigma)
    # A zone's end computes as |sigma| a rounding above 1 on some machines (fused
    # multiply-add or not); the outside form's sqrt(sigma^2 - 1) turns that 1e-16 into
    # 1e-8 (measured: 4.9e-10 of the settlement at x = 1 on the heel's zone).
    rounding = ROUNDINGS_OF_AN_END * np.finfo(float).eps * (1.0 + (1.0 + abs(zone.centre)) / b)
    inside = size <= 1.0 + rounding
    # the bare base's L_inf is 1 (core.kernel.symbol_at_infinity)
    log_part = np.empty(sigma.shape)
    theta = np.arccos(np.clip(sigma[inside], -1.0, 1.0))
    log_part[inside] = c[0] * np.log(2.0) + np.cos(np.outer(theta, n)) @ (c[1:] / n)
    if np.any(~inside):
        out = size[~inside]
        ratio = out - np.sqrt((out - 1.0) * (out + 1.0))   # 1 / (|s| + sqrt(s^2 - 1))
        powers = (np.sign(sigma[~inside])[:, None] * ratio[:, None]) ** n[None, :]
        log_part[~inside] = c[0] * (np.log(2.0) + np.log(ratio)) + powers @ (c[1:] / n)
    nodes = np.cos(np.pi * (np.arange(response.nodes) + 0.5) / response.nodes)
    density = response.regular_part(nodes, np.array([zone.delta]), np.array([zone.alpha]))[:, 0]
    kernel = table(response.lam * np.abs(sigma[:, None] - nodes[None, :])) \
        - np.log(response.lam)
    return b * (log_part + kernel @ density / response.nodes)


def _coarser_ends(zones: _Zones, free: int, given: dict[str, float], level: int,
                  start: tuple[float, float], jacobian: np.ndarray | None,
                  ends_tol: float) -> tuple[float, float]:
    """The zone's ends found with fewer modes (``level`` 1: half, 2: a quarter) from the
    ends ``start`` (``jacobian``, ``ends_tol``: those of two free ends' search)."""
    if free == 2:
        lo, hi, _ = _two_free_ends(zones, given, level=level, guess=start, jacobian=jacobian,
                                   keep_jacobian=False, ends_tol=ends_tol)
        return lo, hi
    return _zone(free, _free_end(zones, free, given, level=level,
                                 near=start[0] if free < 0 else start[1]))


def _change(zones: _Zones, given: dict[str, float], level: int, ends: tuple[float, float],
            than: dict[str, float], scale: dict[str, float]
            ) -> tuple[float, dict[str, float]]:
    """The largest change from ``than`` of an unknown of the answer on the zone ``ends``
    with fewer modes (``level``), relative to ``scale``'s kinematics or statics, and that
    answer."""
    kin = max(abs(scale["settlement"]), abs(scale["tilt"]), 1e-300)
    stat = max(abs(scale["force"]), abs(scale["moment"]), 1e-300)
    lo, hi = ends
    _, _, coarse = _kinematics(zones.response(lo, hi), 0.5 * (lo + hi), 0.5 * (hi - lo),
                               given, level=level)
    return max(abs(than[n] - coarse[n]) / (kin if n in ("settlement", "tilt") else stat)
               for n in _NAMES if n not in given), coarse


def _solve_one(half_width: float, base: tuple[float, float, float], gap: Gap,
               given: dict[str, float], free: int, modes: int, table: RegularPartTable,
               tol: float, near: ZoneAnswer | None = None,
               before: ZoneAnswer | None = None, same_gap: bool = True) -> ZoneAnswer:
    """The zone answer at one value of the loads (``near``: one for nearby loads, the
    same corners lifting, where its ends are looked for first; ``before``: the one
    before it, through which the end is extrapolated; ``same_gap``: whether theirs was
    this gap, so that the nearby zone's response serves)."""
    last = None
    while True:
        zones = _Zones(half_width, base, gap, modes, table, tol)
        if same_gap and near is not None and near.response.modes == modes:
            # a zone's response does not depend on the loads: the nearby one's serves
            zones.keep(near.lo, near.hi, near.response)
        jacobian = None
        if free == 2:
            guess = second = None
            if near is not None:
                guess, jacobian = (near.lo, near.hi), near.jacobian
                if before is not None and before.free == 2:
                    second = (2.0 * near.lo - before.lo, 2.0 * near.hi - before.hi)
            # a gap of its own (a creeping base's memory, interpolated) is smooth to ~1e-9
            # of itself: its ends' coefficients vanish only to that
            ends_tol = TWO_ENDS_TOL if same_gap else max(TWO_ENDS_TOL, MEMORY_ENDS_TOL)
            lo, hi, jacobian = _two_free_ends(zones, given, level=0, guess=guess,
                                              jacobian=jacobian, second=second,
                                              ends_tol=ends_tol)
        else:
            start = second = None
            if near is not None:
                start = near.lo if free < 0 else near.hi
                if before is not None and before.free == free:
                    second = 2.0 * start - (before.lo if free < 0 else before.hi)
            end = _free_end(zones, free, given, level=0, near=start, second=second)
            lo, hi = _zone(free, end)
            ends_tol = TWO_ENDS_TOL  # (asked of two free ends only)
        x0, b = 0.5 * (lo + hi), 0.5 * (hi - lo)
        response = zones.response(lo, hi)
        delta, alpha, values = _kinematics(response, x0, b, given)
        own = _own_error(response, delta, alpha, tol)
        # the ends': the answers on the ends found with half the modes
        clo, chi = _coarser_ends(zones, free, given, 1, (lo, hi), jacobian, ends_tol)
        change, coarse = _change(zones, given, 1, (clo, chi), values, values)
        end_change = max(abs(lo - clo), abs(hi - chi))
        extrapolate = MAX_RATIO / (1.0 - MAX_RATIO)
        error = max(own, extrapolate * change)
        # the ends are found to END_TOL: no estimate below it (the ends with half the
        # modes, sought from these, may not move at all)
        end_error = max(extrapolate * end_change, END_TOL)
        if not same_gap and max(error, end_error) > RATIO_SHARE * tol:
            # A gap of its own converges more slowly in the modes than a punch's shape:
            # where the fixed ratio's estimate counts, the changes of half against a
            # quarter of the modes measure the ratio, as the layered solve's own estimate
            # does (``truncation_errors`` of :mod:`core.engines.layered.solve`): on the
            # heel that recedes and grows again (tests/engines/test_bare_lift_off.py) the
            # fixed one read 2.6e-3, this one 1.7e-4, against ends off by 2e-7 to 2.4e-6.
            try:
                qlo, qhi = _coarser_ends(zones, free, given, 2, (clo, chi), jacobian,
                                         ends_tol)
            except ValueError:
                # a quarter of the modes finds no zone end: the fixed ratio's estimate,
                # which asks nothing of them, stands
                pass
            else:
                change0, _ = _change(zones, given, 2, (qlo, qhi), coarse, values)
                end_change0 = max(abs(clo - qlo), abs(chi - qhi))
                error = max(own, float(geometric_tail(change, change0, LEAST_RATIO)))
                end_error = max(float(geometric_tail(end_change, end_change0, LEAST_RATIO)),
                                END_TOL)
        answer = ZoneAnswer(lo, hi, free, response, delta, alpha, values, float(error),
                            float(end_error), jacobian)
        if error <= 0.5 * tol or 2 * modes > MAX_MODES:
            return answer
        if not same_gap and last is not None and error > STALLED * last.error:
            # a gap that is not smooth (a creeping base's memory of where the zone has
            # been) stops the modes' gain: the better of the last two answers, as it is
            return answer if error < last.error else last
        last = answer
        modes *= 2


def _hertz_guess(gap: Gap, given: dict[str, float]) -> tuple[float, float] | None:
    """A first zone for a crown lifting at both corners where the force is given: Hertz's
    on a half-space, ``b = sqrt(2 R P* / pi)`` (``R`` the radius at the gap's lowest point)
    about the resultant (the moment given) or the punch's deepest point (the tilt given);
    None without a given force."""
    if given.get("force", 0.0) <= 0 or not callable(gap):
        return None
    t = np.linspace(-1.0, 1.0, 2001)
    g = np.asarray(gap(t), dtype=float)
    k = int(np.clip(np.argmin(g), 1, t.size - 2))
    h = t[1] - t[0]
    curvature = (g[k - 1] - 2 * g[k] + g[k + 1]) / (h * h)
    b = np.sqrt(2 * given["force"] / (np.pi * curvature)) if curvature > 0 else 0.5
    if "moment" in given:
        x0 = given["moment"] / given["force"]
    else:  # the tilted punch's deepest point
        x0 = float(t[np.argmax(given["tilt"] * t - g)])
    b = float(np.clip(b, 1e-3, 0.95))
    x0 = float(np.clip(x0, -1 + b, 1 - b))
    return x0 - b, x0 + b


def _broyden(f: Callable[[np.ndarray], np.ndarray], v: np.ndarray, jacobian: np.ndarray,
             inside: Callable[[np.ndarray], bool]) -> tuple[np.ndarray, np.ndarray] | None:
    """The root of ``f`` (two equations in two unknowns) by Broyden's method from ``v``
    with a first ``jacobian`` (a nearby root's), to a last step of ``BROYDEN_XTOL``
    relative; (the root, the Jacobian updated) or None when it does not converge within
    ``BROYDEN_STEPS`` or a step leaves the punch (``inside``)."""
    fv = f(v)
    jac = np.array(jacobian, dtype=float)
    for _ in range(BROYDEN_STEPS):
        try:
            step = -np.linalg.solve(jac, fv)
        except np.linalg.LinAlgError:
            return None
        if not np.all(np.isfinite(step)):
            return None
        if np.max(np.abs(step)) <= BROYDEN_XTOL * max(1.0, float(np.max(np.abs(v)))):
            return v, jac  # the last point evaluated: within the step of the root
        moved = v + step
        if not inside(moved):
            return None
        f_moved = f(moved)
        # Broyden's good update: the secant condition along the step
        jac = jac + np.outer(f_moved - fv - jac @ step, step) / float(step @ step)
        v, fv = moved, f_moved
    return None


def _two_free_ends(zones: _Zones, given: dict[str, float], level: int,
                   guess: tuple[float, float] | None = None,
                   jacobian: np.ndarray | None = None,
                   second: tuple[float, float] | None = None,
                   keep_jacobian: bool = True, ends_tol: float = TWO_ENDS_TOL
                   ) -> tuple[float, float, np.ndarray | None]:
    """The zone of a punch lifting at both corners: both ends' singular coefficients zero
    (``guess`` a first zone, else :func:`_hertz_guess`, else the best of a scan), with the
    Jacobian of the coefficients there when Broyden's method found it. With
    ``jacobian`` (a nearby zone's) Broyden's method starts from ``second`` (the guess
    extrapolated; default the guess), else Powell's hybrid method from the guess; then
    (``keep_jacobian``) the Jacobian is made by forward differences, two more zones."""
    from scipy.optimize import root  # here: see _free_end

    def within(v: np.ndarray) -> bool:
        if not np.all(np.isfinite(v)) or v[1] > 0.0:
            return False
        x0, b = float(v[0]), float(np.exp(v[1]))
        return x0 - b >= -1.0 and x0 + b <= 1.0

    def coefficients(v: np.ndarray) -> np.ndarray:
        if not np.all(np.isfinite(v)) or v[1] > FARTHEST_LOG_HALF_WIDTH:
            # a root finder's step to a zone far wider than the punch (its layered solve
            # overflowed the node count) is sent back: no root lies there
            return np.full(2, OUTSIDE_COEFFICIENT)
        x0, b = float(v[0]), float(np.exp(v[1]))
        response = zones.response(x0 - b, x0 + b)
        delta, alpha, values = _kinematics(response, x0, b, given, level)
        ends = response.regular_part(np.array([-1.0, 1.0]), np.array([delta]),
                                     np.array([alpha]), level=level)[:, 0]
        return ends / max(abs(values["force"]) / b, 1e-300)

    def solved(start: np.ndarray) -> np.ndarray | None:
        found = root(coefficients, start, method="hybr", options={"xtol": 1e-14})
        if within(found.x) and np.max(np.abs(coefficients(found.x))) <= ends_tol:
            return found.x
        return None

    def unknowns(zone: tuple[float, float]) -> np.ndarray:
        return np.array([0.5 * (zone[0] + zone[1]), np.log(0.5 * (zone[1] - zone[0]))])

    found, updated = None, None
    if guess is not None and jacobian is not None:
        # from a nearby zone (the last time-grid point's, or this one's with all the
        # modes) Broyden's method needs ~2 zones where Powell's asked ~6 (a zone is a
        # layered solve: a Hertz crown on a creeping layer, 674 solves of 5.6 zones)
        # (an extrapolated zone that closes up is no start)
        start = unknowns(second if second is not None and second[1] > second[0]
                         and within(unknowns(second)) else guess)
        broyden = _broyden(coefficients, start, jacobian, within)
        if broyden is not None and np.max(np.abs(coefficients(broyden[0]))) <= ends_tol:
            found, updated = broyden
    first = guess if guess is not None else _hertz_guess(zones.gap, given)
    if found is None and first is not None:
        found = solved(unknowns(first))
    if found is None:
        # the zones within the punch, scanned: the smallest coefficients start it again
        best, start = np.inf, None
        for b in SCAN_HALF_WIDTHS:
            for x0 in SCAN_MIDDLES[np.abs(SCAN_MIDDLES) <= 1.0 - b]:
                v = np.array([x0, np.log(b)])
                size = float(np.max(np.abs(coefficients(v))))
                if size < best:
                    best, start = size, v
        found = solved(start) if start is not None else None
    if found is None:
        raise ValueError(TWO_FREE_ENDS)
    if updated is None and keep_jacobian:
        updated = _jacobian(coefficients, found)
    x0, b = float(found[0]), float(np.exp(found[1]))
    return x0 - b, x0 + b, updated


def _jacobian(f: Callable[[np.ndarray], np.ndarray], v: np.ndarray) -> np.ndarray:
    """``f``'s Jacobian at ``v`` by forward differences (the first of Broyden's)."""
    fv = f(v)
    jac = np.empty((fv.size, v.size))
    for i in range(v.size):
        h = JACOBIAN_STEP * max(1.0, abs(float(v[i])))
        moved = v.copy()
        moved[i] += h
        jac[:, i] = (f(moved) - fv) / h
    return jac
