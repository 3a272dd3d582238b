"""A rigid punch on uniform coating layers, solved with the exact layered kernel.

A rigid punch of half-width ``a`` and base shape ``f`` in full contact, settled by
``delta`` and tilted by ``alpha``, on the stack of :mod:`core.layered_kernel` (elastic
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

:func:`flat_punch_stiffness` is the flat-punch special case in SI units (force per unit
settlement, moment per unit tilt), which the FE comparison (``benchmarks/layered_kernel.py``)
uses.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.fft import dct, next_fast_len

from core.layered_cache import LAYERED_OPERATOR, LAYERED_RESPONSE, LAYERED_TABLE, gap_key, stack_key
from core.layered_kernel import (
    _PANEL_DEGREE,
    COARSE_PANEL_DEGREE,
    RegularPartTable,
    UniformLayer,
    symbol_at_infinity,
)

__all__ = ["FlatPunchStiffness", "LayeredAnswer", "LayeredResponse", "MAX_MODES",
           "MAX_NODES", "default_modes", "flat_punch_stiffness", "layered_response",
           "node_count", "solve_layered", "table_degree"]

#: Chebyshev modes of the pressure per ``sqrt(a / h_min)``: the edge boundary layer of
#: width ``h`` is ``sqrt(h / a)`` wide in the angle of ``t = cos(theta)``. Measured (smooth,
#: E_c = 0.3 E, H = a): h = 0.04 a, 64 modes: force and moment settled to 1e-10; h = 0.002 a:
#: 128 modes 6e-5, 256 modes 1e-7 (relative change to the next doubling).
MODES_PER_ROOT = 12
#: Fewest modes.
MIN_MODES = 32
#: Most modes (2048 nodes: a 2048^2 table lookup, ~1 s); a thinner coating than
#: ``(MODES_PER_ROOT / MAX_MODES)^2 a`` (5.5e-4 a) would need more from the start.
MAX_MODES = 512
#: Gauss-Chebyshev nodes of the smooth part per mode.
NODES_PER_MODE = 4
#: The same for ``tol >= COARSE_TOL``. Measured at tol 1e-6 against tol 1e-11 with 4 per
#: mode (force and moment; 135-270 modes): 2 per mode leaves 1.1e-13 (uniform_flat),
#: 1.4e-11 (rounded_graded: its nodes are set by the thickness), 2.3e-10 (soft bonded,
#: h = 0.008 a: the coarser table's floor), 2.1e-12 (stiff smooth, H = a / 2).
COARSE_NODES_PER_MODE = 2
#: Nodes per ``a / h_min``: the smooth part ``K`` turns from the top coating's logarithm
#: to the base's over distances ~ h, so the node spacing at the centre (``pi / nodes``)
#: must resolve h. Measured (bonded, h = 0.008 a, E_c = 0.01 E, crowned punch with a
#: kink): spacing 0.73 h errs by 3e-7 in the settlement, 0.36 h by 1e-13.
NODES_PER_THICKNESS = 3 * np.pi
#: Tolerances at or above this take the coarser quadrature and table below: their error
#: (<= 2.3e-10 measured) stays 200x below the ``tol / 2`` a solve aims at.
COARSE_TOL = 1e-7
#: Nodes per ``a / h_min`` for ``tol >= COARSE_TOL`` (spacing 0.5 h). Measured against
#: 6 pi on rounded_graded at tol 1e-6 (135 modes): 3 pi 1.6e-14, 2.4 pi 1.5e-13, 2 pi
#: 2.1e-11, 1.6 pi 2.7e-9, 1.4 pi 3.0e-8 in force and moment; a soft bonded and a stiff
#: smooth coating (240-270 modes) are set by the modes there, 3.5e-14 and 1e-16.
COARSE_NODES_PER_THICKNESS = 2 * np.pi
#: Most nodes (a 4096^2 table lookup and product, a few seconds): coatings thinner than
#: ``NODES_PER_THICKNESS a / MAX_NODES`` (2.3e-3 a) are left to the thin-layer model.
MAX_NODES = 4096
#: Gauss-Legendre points per panel of the gap's moments (panels of ~ pi / modes in angle).
GAP_POINTS = 12
_GAP_RULE = np.polynomial.legendre.leggauss(GAP_POINTS)
#: Gap moments kept per (gap, modes): a new coating under the same punch reuses them
#: (they were a fifth of a new rounded_graded coating's solve).
_GAP_MOMENTS_KEPT = 32
_gap_moments_kept: dict[tuple[str, int], np.ndarray] = {}
#: Geometric extrapolation of the last two differences uses at most this ratio (a slower
#: decrease is not trusted: the estimate is then 9x the last difference).
MAX_RATIO = 0.9
#: Floor of the error estimate [-]: the symbol's conditioning at small u (~1e-16 / u^2
#: relative, tests/test_layered_kernel.py) and the kernel's ~1e-14; settled answers change
#: by ~1e-12 between mode counts (a flat punch, h = 0.02 a, H = 4 a: 1.5e-12 in q).
ERROR_FLOOR = 1e-12
#: The floor for ``tol >= COARSE_TOL``: the coarser table and quadrature, measured to
#: leave up to 2.3e-10 (:data:`COARSE_NODES_PER_MODE`).
COARSE_ERROR_FLOOR = 5e-10
#: A gap: ``g*(t)`` [-] as a vectorized callable of ``t`` in [-1, 1], a number, or None.
Gap = Callable[[np.ndarray], np.ndarray] | float | None
#: Pressure errors are measured on ``|t| <= PRESSURE_REACH`` (the corner singularities).
PRESSURE_REACH = 0.9
_NAMES = ("settlement", "tilt", "force", "moment")


def node_count(half_width: float, layers: Sequence[UniformLayer], modes: int, *,
               tol: float = 0.0) -> int:
    """Gauss-Chebyshev nodes [-]: ``max(NODES_PER_MODE modes, NODES_PER_THICKNESS a /
    h_min)`` (:data:`COARSE_NODES_PER_MODE`, :data:`COARSE_NODES_PER_THICKNESS` for ``tol
    >= COARSE_TOL``), rounded up to a product of 2, 3 and 5: the Galerkin matrix's DCTs
    then take half the time (1179 nodes 28 ms, 1200 nodes 13 ms)."""
    thinnest = min([lay.thickness for lay in layers] + [half_width])
    coarse = tol >= COARSE_TOL
    per_thickness = COARSE_NODES_PER_THICKNESS if coarse else NODES_PER_THICKNESS
    per_mode = COARSE_NODES_PER_MODE if coarse else NODES_PER_MODE
    return next_fast_len(max(per_mode * modes,
                             int(np.ceil(per_thickness * half_width / thinnest))), real=True)


def table_degree(tol: float) -> int:
    """The Chebyshev degree [-] of the stack's table for a solve to ``tol`` [-]."""
    return COARSE_PANEL_DEGREE if tol >= COARSE_TOL else _PANEL_DEGREE


def default_modes(half_width: float, layers: Sequence[UniformLayer]) -> int:
    """``max(MIN_MODES, MODES_PER_ROOT sqrt(a / h_min))`` [-] for half-width a [m]."""
    thinnest = min([lay.thickness for lay in layers] + [half_width])
    return max(MIN_MODES, int(np.ceil(MODES_PER_ROOT * np.sqrt(half_width / thinnest))))


def _galerkin_matrix(lam: float, l_inf: float, table: RegularPartTable, modes: int,
                     n_nodes: int) -> np.ndarray:
    """``pi`` times the Galerkin matrix of ``(1/pi) int k_stack(lam (t - s)) . ds`` on
    ``T_n / sqrt(1 - t^2)``, n < modes."""
    theta = np.pi * (np.arange(n_nodes) + 0.5) / n_nodes
    t = np.cos(theta)
    smooth = np.empty((n_nodes, n_nodes))
    # K(t_i - t_j) is symmetric: the table is read for j >= i only, in blocks of rows that
    # keep its temporaries small
    for start in range(0, n_nodes, 64):
        rows = slice(start, min(start + 64, n_nodes))
        block = table(lam * np.abs(t[rows, None] - t[None, start:]))
        smooth[rows, start:] = block
        smooth[start:, rows] = block.T
    smooth -= l_inf * np.log(lam)
    # sum_i T_m(t_i) X_i = sum_i cos(m pi (i + 1/2) / n) X_i: a DCT-II (scipy's is twice it)
    weight = np.pi / n_nodes
    half = dct(smooth, type=2, axis=0)[:modes]
    matrix = 0.25 * weight * weight * dct(half, type=2, axis=1)[:, :modes]
    diagonal = np.empty(modes)
    diagonal[0] = np.pi**2 * np.log(2.0)
    diagonal[1:] = np.pi**2 / (2 * np.arange(1, modes))
    matrix[np.diag_indices(modes)] += l_inf * diagonal
    return matrix


def _gap_moments(gap: Callable[[np.ndarray], np.ndarray], breakpoints: Sequence[float],
                 modes: int) -> np.ndarray:
    """``G_m = int_0^pi g*(cos th) cos(m th) dth`` [-], m < modes, for a callable ``gap``
    of ``t`` in [-1, 1] (Gauss-Legendre panels in ``th`` broken at the breakpoints)."""
    cuts = sorted({0.0, np.pi} | {float(np.arccos(b)) for b in breakpoints if -1 < b < 1})
    count = max(4, modes // 2)
    edges = np.unique(np.concatenate([np.linspace(lo, hi, max(2, int(np.ceil(
        count * (hi - lo) / np.pi)) + 1)) for lo, hi in zip(cuts[:-1], cuts[1:], strict=True)]))
    x, w = _GAP_RULE
    half = 0.5 * np.diff(edges)
    theta = (0.5 * (edges[1:] + edges[:-1])[:, None] + half[:, None] * x).ravel()
    weights = (half[:, None] * w).ravel()
    values = np.broadcast_to(np.asarray(gap(np.cos(theta)), dtype=float), theta.shape)
    return np.cos(np.outer(np.arange(modes), theta)) @ (weights * values)


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


#: Point sets whose Chebyshev rows are kept (:func:`_chebyshev_rows`), and the most
#: values (points x modes) in a kept set (2 MiB; 32 MiB in all): the error estimate and
#: the pressure ask the same few sets at every load, and their cosines were half of a
#: load change's CPU time (measured on a 10,000-point load study: 4.3 of 9 ms a point).
_CHEBYSHEV_SETS = 16
_CHEBYSHEV_MOST_VALUES = 2**18
_chebyshev_kept: dict[tuple[bytes, int], np.ndarray] = {}
_chebyshev_lock = threading.Lock()


def _chebyshev_rows(t: np.ndarray, modes: int) -> np.ndarray:
    """``cos(k arccos t)`` for k < ``modes`` at the points ``t`` of [-1, 1] (clipped),
    shape (len(t), modes); the same values every time, kept for small point sets."""
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size * modes > _CHEBYSHEV_MOST_VALUES:
        return np.cos(np.outer(np.arccos(np.clip(t, -1, 1)), np.arange(modes)))
    key = (t.tobytes(), modes)
    with _chebyshev_lock:  # solves may run in threads (a served explorer, Dask threads)
        rows = _chebyshev_kept.pop(key, None)
        if rows is not None:
            _chebyshev_kept[key] = rows  # now the most recently used
            return rows
    rows = np.cos(np.outer(np.arccos(np.clip(t, -1, 1)), np.arange(modes)))
    rows.setflags(write=False)
    with _chebyshev_lock:
        while len(_chebyshev_kept) >= _CHEBYSHEV_SETS:
            del _chebyshev_kept[next(iter(_chebyshev_kept))]  # the least recently used
        _chebyshev_kept[key] = rows
    return rows


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
    n_nodes = node_count(half_width, layers, modes, tol=tol)
    matrix = _operator(half_width, layers, base_thickness, base_modulus, base_poisson,
                       modes, table, n_nodes)
    return _unit_responses(lam, matrix, gap, breakpoints, n_nodes)


def _operator(half_width: float, layers: Sequence[UniformLayer], base_thickness: float,
              base_modulus: float, base_poisson: float, modes: int,
              table: RegularPartTable, n_nodes: int) -> np.ndarray:
    """The Galerkin matrix of the stack on ``modes`` modes and ``n_nodes`` nodes
    (:func:`_galerkin_matrix`)."""
    lam = half_width / base_thickness
    l_inf = symbol_at_infinity(layers, base_modulus, base_poisson)
    return _galerkin_matrix(lam, l_inf, table, modes, n_nodes)


def _kept_gap_moments(gap: Callable[[np.ndarray], np.ndarray], breakpoints: Sequence[float],
                      modes: int, gap_id: str | None) -> np.ndarray:
    """:func:`_gap_moments`, kept per ``(gap_id, modes)`` when ``gap_id`` is given."""
    if gap_id is None:
        return _gap_moments(gap, breakpoints, modes)
    key = (gap_id, modes)
    with _chebyshev_lock:
        kept = _gap_moments_kept.get(key)
    if kept is not None:
        return kept
    moments = _gap_moments(gap, breakpoints, modes)
    moments.setflags(write=False)
    with _chebyshev_lock:
        while len(_gap_moments_kept) >= _GAP_MOMENTS_KEPT:
            del _gap_moments_kept[next(iter(_gap_moments_kept))]  # the oldest
        _gap_moments_kept[key] = moments
    return moments


def _unit_responses(lam: float, matrix: np.ndarray, gap: Gap, breakpoints: Sequence[float],
                    n_nodes: int, gap_id: str | None = None) -> LayeredResponse:
    """The responses to the gap, a unit settlement and a unit tilt on ``matrix``
    (``gap_id``: the gap's key, to reuse its moments)."""
    modes = matrix.shape[0]
    rhs = np.zeros((modes, 3))
    if callable(gap):
        rhs[:, 0] = -np.pi * _kept_gap_moments(gap, breakpoints, modes, gap_id)
    elif gap:
        rhs[0, 0] = -np.pi * np.pi * float(gap)
    rhs[0, 1] = np.pi * np.pi
    rhs[1, 2] = 0.5 * np.pi * np.pi
    blocks = (modes // 2, modes // 4)
    return LayeredResponse(lam, np.linalg.solve(matrix, rhs), tuple(
        np.linalg.solve(matrix[:n, :n], rhs[:n]) for n in blocks), n_nodes)


def _cached_response(half_width: float, layers: Sequence[UniformLayer],
                     base_thickness: float, base_modulus: float, base_poisson: float,
                     gap: Gap, breakpoints: Sequence[float], modes: int,
                     keys: tuple[str, str], built: dict[str, float],
                     tol: float = 0.0, room: int = 0) -> LayeredResponse:
    """:func:`layered_response` through the caches of :mod:`core.layered_cache` (``keys``:
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
    n_nodes = node_count(half_width, layers, room, tol=tol)

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
    unknowns = [n for n in _NAMES if n not in given]
    while True:
        response = _cached_response(half_width, layers, base_thickness, base_modulus,
                                    base_poisson, gap, breakpoints, modes, keys, built,
                                    tol=tol, room=room)
        fine = response.complete(given)
        d1 = _differences(response, given, fine, level=1)
        d0 = _differences(response, given, fine, level=2)
        errors = {}
        for name in unknowns + ["pressure"]:
            ratio = min(d1[name] / d0[name], MAX_RATIO) if d0[name] > 0 else MAX_RATIO
            errors[name] = max(d1[name] * ratio / (1 - ratio), floor)
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


@dataclass(frozen=True)
class FlatPunchStiffness:
    """``force_per_settlement`` [N/m per m], ``moment_per_tilt`` [N per rad] (per unit
    length out of plane), the pressure's Chebyshev coefficients [Pa] for a unit settlement
    (``settlement_modes``) and a unit tilt (``tilt_modes``), and ``modes``, ``nodes``."""

    force_per_settlement: float
    moment_per_tilt: float
    settlement_modes: np.ndarray
    tilt_modes: np.ndarray
    modes: int
    nodes: int


def flat_punch_stiffness(half_width: float, layers: Sequence[UniformLayer],
                         base_thickness: float, base_modulus: float, base_poisson: float,
                         *, modes: int | None = None) -> FlatPunchStiffness:
    """Force per unit settlement and moment per unit tilt of a flat punch of half-width a
    [m] on ``layers`` (top first) over the base (H [m], E [Pa], nu), all SI units.

    ``modes`` defaults to :func:`default_modes` (nodes: :func:`node_count`).
    """
    if half_width <= 0 or not np.isfinite(half_width):
        raise ValueError(f"half_width: must be a finite positive number, got {half_width!r}")
    modes = modes or default_modes(half_width, layers)
    response = layered_response(half_width, layers, base_thickness, base_modulus,
                                base_poisson, modes=modes)
    # q = E / (2 (1 - nu^2)) q*, delta* = delta / a: per metre of settlement, q* / a
    scale = base_modulus / (2 * (1 - base_poisson**2))
    settlement_modes = scale * response.coefficients[:, 1] / half_width
    tilt_modes = scale * response.coefficients[:, 2]
    force = np.pi * half_width * settlement_modes[0]
    moment = 0.5 * np.pi * half_width**2 * tilt_modes[1]
    return FlatPunchStiffness(float(force), float(moment), settlement_modes, tilt_modes,
                              modes, response.nodes)
