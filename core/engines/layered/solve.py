"""A rigid punch on uniform coating layers, solved with the exact layered kernel.

A rigid punch of half-width ``a`` and base shape ``f`` in full contact, settled by
``delta`` and tilted by ``alpha``, on the stack of :mod:`core.kernel.layered` (elastic
base of modulus E, Poisson nu):

    2 (1 - nu^2) / (pi E) int_{-a}^{a} k_stack((x - xi) / H) q(xi) dxi = delta + alpha x - g(x),

``g`` the gap (the punch shape less its lowest point: the coating's thickness is constant).
Dimensionless as in the model notes (``t = x / a``, ``q* = 2 (1 - nu^2) q / E``,
``delta* = delta / a``, ``g* = g / a``)::

    (1 / pi) int_{-1}^{1} k_stack(lam (t - s)) q*(s) ds = delta* + alpha t - g*(t).

``k_stack(lam d) = -L_inf ln|d| + K(d)`` with ``K(d) = R(lam d) - L_inf ln lam`` smooth
(``R`` the regular part, ``lam = a / H``). The top coating is a half-space at the punch
corners, so ``q`` has the inverse square-root singularity there: ``q*(t) = sum_n c_n T_n(t)
/ sqrt(1 - t^2)`` (Chebyshev, first kind). Galerkin with the same functions: the
logarithmic part is diagonal (``int -ln|t - s| T_n(s) / sqrt(1 - s^2) ds = pi T_n(t) / n``,
``pi ln 2`` for ``n = 0``), the smooth part by Gauss-Chebyshev quadrature, the gap's
moments ``G_m = int_0^pi g*(cos th) cos(m th) dth`` by Gauss-Legendre panels in ``th``
broken at the gap's breakpoints. Force and moment: ``P* = pi c_0``, ``M* = pi c_1 / 2``.

The problem is linear: one factorization gives the pressure for the gap alone, for a unit
settlement and for a unit tilt (:class:`LayeredResponse`); any two of ``delta, alpha, P,
M`` then give the other two (the four statements). The error estimate compares the answer
with the one of half the modes on the same nodes (the leading block of the same system)
and extrapolates the two last differences geometrically (:func:`solve_layered`).

:func:`core.engines.layered.flat_punch_stiffness` is the flat-punch special case in SI
units (force per unit settlement, moment per unit tilt), which the FE comparison
(``benchmarks/layered_kernel.py``) uses.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from core.engines.layered.cache import (
    CHEBYSHEV_ROWS,
    GAP_MOMENTS,
    LAYERED_OPERATOR,
    LAYERED_RESPONSE,
    LAYERED_TABLE,
    gap_key,
    stack_key,
)
from core.engines.layered.galerkin import (
    COARSE_TOL,
    MAX_MODES,
    default_modes,
    galerkin_matrix,
    gap_moments,
    node_count,
    table_degree,
)
from core.kernel import RegularPartTable, UniformLayer, symbol_at_infinity

__all__ = ["LayeredAnswer", "LayeredResponse", "layered_response", "solve_layered"]

#: Geometric extrapolation of the last two differences uses at most this ratio (a slower
#: decrease is not trusted: the estimate is then 9x the last difference).
MAX_RATIO = 0.9
#: Floor of the error estimate [-]: the symbol's conditioning at small u (~1e-16 / u^2
#: relative, tests/kernel/test_layered_kernel.py) and the kernel's ~1e-14; settled answers change
#: by ~1e-12 between mode counts (a flat punch, h = 0.02 a, H = 4 a: 1.5e-12 in q).
ERROR_FLOOR = 1e-12
#: The floor for ``tol >= COARSE_TOL``: the coarser table and quadrature, measured to
#: leave up to 2.3e-10 (:data:`core.engines.layered.galerkin.COARSE_NODES_PER_MODE`).
COARSE_ERROR_FLOOR = 5e-10
#: A gap: ``g*(t)`` [-] as a vectorized callable of ``t`` in [-1, 1], a number, or None.
Gap = Callable[[np.ndarray], np.ndarray] | float | None
#: Pressure errors are measured on ``|t| <= PRESSURE_REACH`` (the corner singularities).
PRESSURE_REACH = 0.9
_NAMES = ("settlement", "tilt", "force", "moment")


@dataclass(frozen=True)
class LayeredResponse:
    """The dimensionless pressure's Chebyshev coefficients for the gap alone, a unit
    settlement ``delta*`` and a unit tilt ``alpha`` (``coefficients``, shape (modes, 3)),
    and the same with the leading half and quarter of the modes (``coarser``: level 1
    and 2 of :meth:`complete`); ``lam = a / H``."""

    lam: float
    coefficients: np.ndarray
    coarser: tuple[np.ndarray, np.ndarray]
    nodes: int

    def _level(self, level: int) -> np.ndarray:
        return self.coefficients if level == 0 else self.coarser[level - 1]

    @property
    def modes(self) -> int:
        """The number of Chebyshev modes [-]."""
        return int(self.coefficients.shape[0])

    @staticmethod
    def _parts(coefficients: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return np.pi * coefficients[0], 0.5 * np.pi * coefficients[1]

    def complete(self, given: dict[str, np.ndarray], *,
                 level: int = 0) -> dict[str, np.ndarray]:
        """All four of ``delta*, alpha, P*, M*`` (arrays over times) from any two of them
        (``level`` 1, 2: with half, a quarter of the modes)."""
        force, moment = self._parts(self._level(level))
        rows = {"settlement": ((1.0, 0.0), 0.0), "tilt": ((0.0, 1.0), 0.0),
                "force": ((force[1], force[2]), force[0]),
                "moment": ((moment[1], moment[2]), moment[0])}
        names = [n for n in _NAMES if n in given]
        matrix = np.array([rows[n][0] for n in names])
        values = np.broadcast_arrays(*[np.asarray(given[n], dtype=float) for n in names])
        rhs = np.stack([v - rows[n][1] for n, v in zip(names, values, strict=True)])
        delta, alpha = np.linalg.solve(matrix, rhs.reshape(2, -1)).reshape((2,) + values[0].shape)
        return {"settlement": delta, "tilt": alpha,
                "force": force[0] + delta * force[1] + alpha * force[2],
                "moment": moment[0] + delta * moment[1] + alpha * moment[2]}

    def regular_part(self, t: np.ndarray, delta: np.ndarray, alpha: np.ndarray, *,
                     level: int = 0) -> np.ndarray:
        """``sqrt(1 - t^2) q*(t)`` at points ``t`` of [-1, 1] for settlements ``delta*`` and
        tilts ``alpha`` (arrays over times): shape (len(t), len(times)); finite at +-1, its
        sign is the pressure's."""
        c = self._level(level)
        weights = np.stack([np.ones_like(delta), delta, alpha])  # (3, T)
        return _chebyshev_rows(t, c.shape[0]) @ (c @ weights)


#: The most values (points x modes) of a point set whose Chebyshev rows are kept (2 MiB;
#: :data:`core.engines.layered.CHEBYSHEV_ROWS`).
_CHEBYSHEV_MOST_VALUES = 2**18


def _chebyshev_rows(t: np.ndarray, modes: int) -> np.ndarray:
    """``cos(k arccos t)`` for k < ``modes`` at the points ``t`` of [-1, 1] (clipped),
    shape (len(t), modes); the same values every time, kept for small point sets."""
    t = np.asarray(t, dtype=float)

    def rows() -> np.ndarray:
        return np.cos(np.outer(np.arccos(np.clip(t, -1, 1)), np.arange(modes)))

    if t.ndim != 1 or t.size * modes > _CHEBYSHEV_MOST_VALUES:
        return rows()
    return CHEBYSHEV_ROWS.get_or_compute((t.tobytes(), modes), rows)


def layered_response(half_width: float, layers: Sequence[UniformLayer],
                     base_thickness: float, base_modulus: float, base_poisson: float,
                     gap: Gap = None, breakpoints: Sequence[float] = (), *, modes: int,
                     table: RegularPartTable | None = None,
                     tol: float = 0.0) -> LayeredResponse:
    """The unit responses of a punch of half-width a [m] on ``layers`` (top first) over the
    base (H [m], E [Pa], nu), with ``modes`` Chebyshev modes.

    ``gap``: ``g*(t) = g(a t) / a`` [-] as a vectorized callable of ``t`` in [-1, 1], a
    number or None (flat punch); ``breakpoints`` in ``t`` where it may kink. ``table`` a
    :class:`RegularPartTable` of this stack reaching ``2 a / H`` (built when None).
    ``tol`` [-]: the accuracy the answer is for (:func:`node_count`, :func:`table_degree`;
    the finest rules by default).
    """
    if half_width <= 0 or not np.isfinite(half_width):
        raise ValueError(f"half_width: must be a finite positive number, got {half_width!r}")
    lam = half_width / base_thickness
    if table is None:
        table = RegularPartTable(2 * lam, layers, base_thickness, base_modulus, base_poisson,
                                 degree=table_degree(tol))
    n_nodes = node_count(half_width, layers, modes, tol=tol, base_thickness=base_thickness)
    matrix = _operator(half_width, layers, base_thickness, base_modulus, base_poisson,
                       modes, table, n_nodes)
    return _unit_responses(lam, matrix, gap, breakpoints, n_nodes)


def _operator(half_width: float, layers: Sequence[UniformLayer], base_thickness: float,
              base_modulus: float, base_poisson: float, modes: int,
              table: RegularPartTable, n_nodes: int) -> np.ndarray:
    """The Galerkin matrix of the stack on ``modes`` modes and ``n_nodes`` nodes
    (:func:`core.engines.layered.galerkin.galerkin_matrix`)."""
    lam = half_width / base_thickness
    l_inf = symbol_at_infinity(layers, base_modulus, base_poisson)
    return galerkin_matrix(lam, l_inf, table, modes, n_nodes)


def _unit_responses(lam: float, matrix: np.ndarray, gap: Gap, breakpoints: Sequence[float],
                    n_nodes: int, gap_id: str | None = None) -> LayeredResponse:
    """The responses to the gap, a unit settlement and a unit tilt on ``matrix``
    (``gap_id``: the gap's key, to reuse its moments)."""
    modes = matrix.shape[0]
    rhs = np.zeros((modes, 3))
    if callable(gap):
        moments = lambda: gap_moments(gap, breakpoints, modes)  # noqa: E731
        rhs[:, 0] = -np.pi * (moments() if gap_id is None
                              else GAP_MOMENTS.get_or_compute((gap_id, modes), moments))
    elif gap:
        rhs[0, 0] = -np.pi * np.pi * float(gap)
    rhs[0, 1] = np.pi * np.pi
    rhs[1, 2] = 0.5 * np.pi * np.pi
    blocks = (modes // 2, modes // 4)
    return LayeredResponse(lam, np.linalg.solve(matrix, rhs), tuple(
        np.linalg.solve(matrix[:n, :n], rhs[:n]) for n in blocks), n_nodes)


def cached_response(half_width: float, layers: Sequence[UniformLayer],
                     base_thickness: float, base_modulus: float, base_poisson: float,
                     gap: Gap, breakpoints: Sequence[float], modes: int,
                     keys: tuple[str, str], built: dict[str, float],
                     tol: float = 0.0, room: int = 0) -> LayeredResponse:
    """:func:`layered_response` through the caches of :mod:`core.engines.layered.cache` (``keys``:
    the stack's and the gap's): a repeat with other loads builds nothing. Adds the CPU
    seconds of what it builds to ``built`` (``operator``: the stack's table and Galerkin
    matrix; ``galerkin``: the unit responses). ``tol`` chooses the table's degree and the
    nodes (:func:`table_degree`, :func:`node_count`), which the keys then carry.

    The Galerkin matrix is built for ``max(modes, room)`` modes on the nodes those need
    and its leading block answers: a solve that doubles its modes within ``room`` reuses
    it (the leading block of the larger matrix is the smaller one, the same DCT rows).
    """
    stack, gap_id = keys
    degree = table_degree(tol)
    room = max(modes, room)
    n_nodes = node_count(half_width, layers, room, tol=tol, base_thickness=base_thickness)

    def timed(stage: str, compute: Callable[[], Any]) -> Callable[[], Any]:
        def run() -> Any:
            start = time.perf_counter()
            value = compute()
            built[stage] = built.get(stage, 0.0) + time.perf_counter() - start
            return value
        return run

    def response() -> LayeredResponse:
        table, _ = LAYERED_TABLE.get_or_compute((stack, degree), timed("operator", lambda: (
            RegularPartTable(2 * half_width / base_thickness, layers, base_thickness,
                             base_modulus, base_poisson, degree=degree))))
        matrix, _ = LAYERED_OPERATOR.get_or_compute(
            (stack, degree, room, n_nodes), timed("operator", lambda: (
                _operator(half_width, layers, base_thickness, base_modulus, base_poisson,
                          room, table, n_nodes))))
        return _unit_responses(half_width / base_thickness, matrix[:modes, :modes], gap,
                               breakpoints, n_nodes, gap_id)

    return LAYERED_RESPONSE.get_or_compute((stack, degree, modes, n_nodes, gap_id),
                                           timed("galerkin", response))[0]


@dataclass(frozen=True)
class LayeredAnswer:
    """The answer of :func:`solve_layered` (dimensionless, arrays over the load values):
    ``settlement`` delta*, ``tilt`` alpha, ``force`` P*, ``moment`` M*; ``response`` gives
    the pressure; ``error_estimate`` [-] the relative error of the unknowns and of q on
    ``|t| <= 0.9`` (as :func:`core.solver.solve_dimensionless` measures them);
    ``errors`` per quantity; ``modes``; ``stages``: per stage (``operator``, ``galerkin``,
    ``solve``) the seconds this call spent and whether it was ``cached``."""

    settlement: np.ndarray
    tilt: np.ndarray
    force: np.ndarray
    moment: np.ndarray
    response: LayeredResponse
    error_estimate: float
    errors: dict[str, float]
    modes: int
    stages: dict[str, dict[str, float | bool]] = field(default_factory=dict)


def _differences(response: LayeredResponse, given: dict[str, np.ndarray],
                 fine: dict[str, np.ndarray], level: int) -> dict[str, float]:
    """Relative differences of the answers of levels ``level`` and ``level - 1`` of the
    response, against the sizes of ``fine``: kinematics against ``max(|delta|,
    |alpha|)``, statics against ``max(|P|, |M|)``, q against its largest value on
    ``|t| <= 0.9``."""
    other = response.complete(given, level=level)
    better = response.complete(given, level=level - 1)
    kin = max(float(np.max(np.abs(fine["settlement"]))), float(np.max(np.abs(fine["tilt"]))))
    stat = max(float(np.max(np.abs(fine["force"]))), float(np.max(np.abs(fine["moment"]))))
    out = {}
    for name in _NAMES:
        scale = kin if name in ("settlement", "tilt") else stat
        diff = float(np.max(np.abs(other[name] - better[name])))
        out[name] = diff / scale if scale > 0 else diff
    t = PRESSURE_REACH * np.cos(np.linspace(0.0, np.pi, 91))
    q = response.regular_part(t, fine["settlement"], fine["tilt"])
    q_scale = float(np.max(np.abs(q / np.sqrt(1 - t * t)[:, None])))
    q_diff = response.regular_part(t, better["settlement"], better["tilt"], level=level - 1) \
        - response.regular_part(t, other["settlement"], other["tilt"], level=level)
    q_diff = float(np.max(np.abs(q_diff / np.sqrt(1 - t * t)[:, None])))
    out["pressure"] = q_diff / q_scale if q_scale > 0 else q_diff
    return out


def geometric_tail(last: Any, before: Any, least_ratio: float = 0.0) -> np.ndarray:
    """The error left after a change ``last`` [-] that followed a change ``before`` (the
    modes doubled each time): ``last r / (1 - r)``, ``r = last / before`` within
    [``least_ratio``, ``MAX_RATIO``] (``MAX_RATIO`` where ``before`` is 0). Elementwise."""
    last = np.asarray(last, dtype=float)
    before = np.asarray(before, dtype=float)
    measured = last / np.where(before > 0, before, 1.0)
    ratio = np.where(before > 0, np.clip(measured, least_ratio, MAX_RATIO), MAX_RATIO)
    return last * ratio / (1 - ratio)


def truncation_errors(response: LayeredResponse, given: dict[str, np.ndarray],
                      fine: dict[str, np.ndarray], floor: float) -> dict[str, float]:
    """The estimated error of each unknown and of q of ``response`` for the ``given``
    loads (``fine``: its answer, :meth:`LayeredResponse.complete`): ``d1 r / (1 - r)``
    from the differences ``d1`` of the answer with half the modes and ``d0`` of half
    against a quarter, ``r = min(d1 / d0, MAX_RATIO)``, at least ``floor``."""
    d1 = _differences(response, given, fine, level=1)
    d0 = _differences(response, given, fine, level=2)
    errors = {}
    for name in [n for n in _NAMES if n not in given] + ["pressure"]:
        errors[name] = max(float(geometric_tail(d1[name], d0[name])), floor)
    return errors


def solve_layered(half_width: float, layers: Sequence[UniformLayer], base_thickness: float,
                  base_modulus: float, base_poisson: float, given: dict[str, np.ndarray],
                  gap: Gap = None, breakpoints: Sequence[float] = (), *,
                  tol: float = 1e-6,
                  max_modes: int = MAX_MODES) -> LayeredAnswer:
    """Any of the four statements on a uniform stack, with an error estimate.

    ``given``: two of ``settlement`` delta* = delta / a, ``tilt`` alpha [rad], ``force``
    P* = 2 (1 - nu^2) P / (E a), ``moment`` M* = 2 (1 - nu^2) M / (E a^2) (numbers or
    arrays over times); the stack and ``gap`` as in :func:`layered_response`. Starts with
    :func:`default_modes` and doubles the modes (up to ``max_modes``) until the estimate is
    below ``tol / 2``. The estimate: ``d1 r / (1 - r)`` from the differences ``d1`` of the
    answer with half the modes and ``d0`` of half against a quarter, ``r = min(d1 / d0,
    MAX_RATIO)`` (the unknowns, and q on ``|t| <= 0.9``, over all the given values), at
    least :data:`ERROR_FLOOR` (:data:`COARSE_ERROR_FLOOR` for ``tol >= COARSE_TOL``). It
    measures the truncation of the modes; the quadrature (:func:`node_count`) and the
    stack's table (:func:`table_degree`) were measured to leave ~1e-13, or up to 2.3e-10 for
    ``tol >= COARSE_TOL``.
    """
    if len(given) != 2 or not set(given) <= set(_NAMES):
        raise ValueError(f"given: must be two of {', '.join(_NAMES)}, got {sorted(given)}")
    given = {k: np.atleast_1d(np.asarray(v, dtype=float)) for k, v in given.items()}
    keys = (stack_key(half_width, layers, base_thickness, base_modulus, base_poisson),
            gap_key(gap, breakpoints))
    modes = min(default_modes(half_width, layers), max_modes)
    # room for one doubling in the first Galerkin matrix: the default modes often fall
    # short once (uniform_flat at tol 1e-6: 85 modes, then 170), and the nodes of twice
    # the modes cost little more when the coating's thickness sets them
    room = min(2 * modes, max_modes)
    floor = COARSE_ERROR_FLOOR if tol >= COARSE_TOL else ERROR_FLOOR
    built: dict[str, float] = {}
    start = time.perf_counter()
    while True:
        response = cached_response(half_width, layers, base_thickness, base_modulus,
                                    base_poisson, gap, breakpoints, modes, keys, built,
                                    tol=tol, room=room)
        fine = response.complete(given)
        errors = truncation_errors(response, given, fine, floor)
        estimate = max(errors.values())
        if estimate <= 0.5 * tol or 2 * modes > max_modes:
            break
        modes *= 2
    # the galerkin stage's time includes the operator it built: report each once
    built_galerkin = built.get("galerkin", 0.0) - built.get("operator", 0.0)
    stages = {"operator": {"seconds": built.get("operator", 0.0),
                           "cached": "operator" not in built},
              "galerkin": {"seconds": max(built_galerkin, 0.0),
                           "cached": "galerkin" not in built},
              "solve": {"seconds": max(time.perf_counter() - start
                                       - built.get("galerkin", 0.0), 0.0), "cached": False}}
    return LayeredAnswer(fine["settlement"], fine["tilt"], fine["force"], fine["moment"],
                         response, float(estimate), errors, modes, stages)
