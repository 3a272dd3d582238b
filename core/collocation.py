"""An independent second method: Nystrom collocation on panels, trapezoid stepping in time.

The dimensionless problem (see ``core/README.md``)

    c(t) m(x) q(x,t) + (I - V) F q = delta(t) + alpha(t) x - g(x),   x in [-1, 1], t >= 1,
    int q dx = P(t),   int x q dx = M(t),

is discretized *directly*, with nothing in common with the Galerkin/modal solver but the
panel quadrature of :mod:`core.quadrature`:

* space: the unknowns are the values of ``q`` at the nodes of a composite Gauss-Legendre
  panel rule; ``F`` is the Nystrom matrix with product integration for the log
  singularity, and the equilibrium integrals use the same rule;
* time: ``V`` is the trapezoid rule on a grid that contains every requested time, so
  each step is one dense linear system for the nodal ``q`` and the two unknowns among
  ``delta, alpha`` (or none, in statement 1, where ``P, M`` follow by quadrature);
* the trapezoid rule has an error expansion in even powers of the step for a smooth
  kernel, so one Richardson step ``(4 x_{h/2} - x_h) / 3`` lifts the order from 2 to 4.

The pressure between nodes comes from the Nystrom formula
``q(x) = [delta + alpha x - g(x) - (I - V) F q (x)] / (c m(x))``, which inherits the
accuracy of the nodal solution. It divides by ``c m``, so for a very thin coating the
absolute error of ``(I - V) F q (x)`` is magnified by ``1 / (c m)``; the nodal values
themselves (``nodal_pressure``) carry no such factor.

Cost: one LU factorization per distinct step matrix while there are few (elastic base,
non-aging kernel), else one Schur form and O(N^2) per step; plus O(N * steps) per step for
the memory term, so O(N * steps^2) in total. Meant for cross-checks, not for speed.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.linalg import lu_factor, lu_solve, rsf2csf, schur, solve_triangular

from core.inputs import validate_times
from core.quadrature import Panels, base_panels, kernel_operator, operator_rows
from core.statements import QUANTITIES as _QUANTITIES
from core.statements import STATEMENTS as _STATEMENTS
from core.validation import PYTHON_STYLE, finite_number, positive_number

TimeInput = float | Callable[[np.ndarray], np.ndarray]

#: Default relative accuracy aimed at in time when ``time_points`` is not given.
DEFAULT_TIME_TOL = 1e-6
#: Coarsest nominal grid of the automatic time refinement, and the finest allowed.
_FIRST_STEPS = 16
_MAX_STEPS = 8192
#: LU factorizations of distinct step matrices before switching to the Schur form, which
#: costs about 30 LU factorizations once and then O(N^2) per step (measured, N = 560).
_LU_LIMIT = 16


@dataclass(frozen=True)
class CollocationSolution:
    """Result of :func:`solve_collocation`, all quantities dimensionless.

    ``times`` (T,); ``settlement`` (delta), ``tilt`` (alpha), ``force`` (P) and ``moment``
    (M) are arrays over ``times``. ``pressure(x)`` gives ``q`` of shape (len(x), T).
    ``info`` holds ``n_nodes``, ``n_steps`` (steps of the finest time grid, or the number
    of times for an elastic base), ``seconds`` (wall clock), ``statement`` (1-4),
    ``richardson``, ``error_estimate`` (estimated relative error of the time
    discretization: 0 for an elastic base, NaN for one fixed grid without Richardson)
    and ``message``. ``nodes`` and ``nodal_pressure`` expose the collocation solution.
    """

    times: np.ndarray
    settlement: np.ndarray
    tilt: np.ndarray
    force: np.ndarray
    moment: np.ndarray
    info: dict
    panels: Panels = field(repr=False)
    # Pieces of the Nystrom formula at the output times: c(t), and the density whose F
    # gives (I - V) F q, i.e. q(t) - V q(t), at the nodes (N, T).
    _lam: float = field(repr=False)
    _m: Callable[[np.ndarray], np.ndarray] = field(repr=False)
    _g: Callable[[np.ndarray], np.ndarray] = field(repr=False)
    _c: np.ndarray = field(repr=False)
    _effective: np.ndarray = field(repr=False)
    _nodal: np.ndarray = field(repr=False)

    @property
    def nodes(self) -> np.ndarray:
        """Collocation nodes in [-1, 1] (dimensionless x), shape (N,)."""
        return self.panels.nodes

    @property
    def nodal_pressure(self) -> np.ndarray:
        """Dimensionless pressure at the collocation nodes, shape (N, len(times))."""
        return self._nodal

    def pressure(self, x: Sequence[float] | np.ndarray) -> np.ndarray:
        """Dimensionless pressure ``q(x, t)`` at points ``x`` in [-1, 1], shape (len(x), T).

        Nystrom interpolation: exact at the nodes, and between them as accurate as the
        nodal solution (divided by ``c m(x)``, so relative accuracy degrades as m -> 0).
        """
        x = np.atleast_1d(np.asarray(x, dtype=float))
        if x.ndim != 1:
            raise ValueError("x: must be a scalar or a 1-D array of points")
        if not np.all(np.isfinite(x)) or np.any(np.abs(x) > 1.0):
            raise ValueError("x: points must be finite and lie in [-1, 1]")
        m = _eval_space(self._m, x, "m")
        g = _eval_space(self._g, x, "g")
        fq = operator_rows(self._lam, self.panels, x) @ self._effective
        rhs = self.settlement[None, :] + self.tilt[None, :] * x[:, None] - g[:, None] - fq
        return rhs / (m[:, None] * self._c[None, :])


def collocation_panels(lam: float, breakpoints: Sequence[float] = (), *,
                       panels_per_unit: float = 8, edge_width: float = 1e-4) -> Panels:
    """The panel rule :func:`solve_collocation` uses (x dimensionless, on [-1, 1]).

    Panels at most ``min(1 / panels_per_unit, 3 / lam)`` wide, broken at ``breakpoints``
    and graded geometrically to width ``edge_width`` at each breakpoint and at +-1.
    """
    return base_panels(lam, breakpoints, edge_width=edge_width,
                       max_width=1.0 / panels_per_unit)


def solve_collocation(
    lam: float,
    m: float | Callable[[np.ndarray], np.ndarray],
    g: float | Callable[[np.ndarray], np.ndarray],
    times: Sequence[float] | np.ndarray,
    *,
    c: TimeInput = 1.0,
    kernel: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None,
    settlement: TimeInput | None = None,
    tilt: TimeInput | None = None,
    force: TimeInput | None = None,
    moment: TimeInput | None = None,
    breakpoints: Sequence[float] = (),
    panels_per_unit: float = 8,
    edge_width: float = 1e-4,
    time_points: int | None = None,
    richardson: bool | None = None,
    time_tol: float = DEFAULT_TIME_TOL,
) -> CollocationSolution:
    """Solve the dimensionless contact problem by Nystrom collocation and trapezoid stepping.

    Arguments (all dimensionless, as in ``core/README.md``):

    * ``lam`` = a/H > 0; ``m(x)`` > 0 the coating compliance and ``g(x)`` the gap, each a
      number or a vectorized callable on [-1, 1]; ``breakpoints`` in (-1, 1) where ``m``
      or ``g`` may jump.
    * ``times``: increasing output times, the first >= 1 (time unit: age at loading).
    * ``c(t)`` > 0 the relative modulus; ``kernel(t, tau)`` the Volterra kernel of
      ``V`` (1 / unit of t, vectorized, broadcasting) or None for an elastic base.
    * exactly two of ``settlement`` (delta), ``tilt`` (alpha), ``force`` (P), ``moment``
      (M), each a number or a callable of t: one of the seed's four statements.

    Resolution: panels at most ``1 / panels_per_unit`` (and ``3 / lam``) wide, graded to
    ``edge_width`` at +-1 and at breakpoints. In time, ``time_points`` nominal uniform
    steps over ``[1, times[-1]]`` (each interval between requested times gets a whole
    number of steps); without it the grid is doubled from 16 steps until the estimated
    relative error is below ``time_tol`` (at most 8192 steps; ``info["message"]`` says
    when that limit stops it). Both are ignored for an elastic base (``kernel=None``),
    where every requested time is solved on its own. ``richardson`` (default: on when a kernel is
    given) combines the grids h and h/2 as ``(4 x_{h/2} - x_h) / 3``.

    Raises ValueError, naming the argument, for invalid input.
    """
    started = time.perf_counter()
    lam = _positive_number(lam, "lam")
    ppu = _positive_number(panels_per_unit, "panels_per_unit")
    edge = _positive_number(edge_width, "edge_width")
    if edge > 1.0:
        raise ValueError(f"edge_width: must be at most 1, got {edge!r}")
    tol = _positive_number(time_tol, "time_tol")
    times_arr = validate_times(times)  # the checks and limits of solve_dimensionless
    cuts = _check_breakpoints(breakpoints)
    m_fn = _space_function(m, "m")
    g_fn = _space_function(g, "g")
    c_fn = _time_function(c, "c")
    given = {name: value for name, value in zip(
        _QUANTITIES, (settlement, tilt, force, moment), strict=True) if value is not None}
    key = frozenset(given)
    if len(key) != 2:
        raise ValueError("settlement, tilt, force, moment: exactly two must be given, got "
                         + (", ".join(sorted(key)) or "none"))
    if key not in _STATEMENTS:
        raise ValueError("settlement, tilt, force, moment: " + " and ".join(sorted(key))
                         + " is not one of the four statements (settlement+tilt, "
                         "settlement+moment, tilt+force, force+moment)")
    loads = {name: _time_function(value, name) for name, value in given.items()}
    if kernel is not None and not callable(kernel):
        raise ValueError("kernel: must be None or a callable K(t, tau)")
    if time_points is not None:
        if isinstance(time_points, bool) or not isinstance(time_points, (int, np.integer)) \
                or time_points < 1:
            raise ValueError(f"time_points: must be a positive integer, got {time_points!r}")
    if richardson is None:
        richardson = kernel is not None

    panels = collocation_panels(lam, cuts, panels_per_unit=ppu, edge_width=edge)
    x = panels.nodes
    m_nodes = _eval_space(m_fn, x, "m")
    if np.any(m_nodes <= 0.0):
        raise ValueError("m: the coating compliance must be > 0 on [-1, 1]")
    g_nodes = _eval_space(g_fn, x, "g")
    op = kernel_operator(lam, panels).matrix
    system = _System(panels, op, m_nodes, g_nodes, key, loads, c_fn, kernel)

    span = times_arr[-1] - 1.0
    message = "ok"
    if kernel is None or span <= 0.0:
        # No memory: every requested time is an independent elastic problem.
        result = system.march(times_arr, np.diff(times_arr), np.arange(len(times_arr)))
        n_steps = len(times_arr)
        error = 0.0
        richardson = False
    elif time_points is not None:
        result, error, n_steps = _fixed_grids(system, times_arr, int(time_points), richardson)
    else:
        result, error, n_steps, met = _adaptive_grids(system, times_arr, richardson, tol)
        if not met:
            message = (f"time grid limit of {_MAX_STEPS} steps reached; estimated relative "
                       f"error {error:.1e} is above time_tol = {tol:.1e}")

    info = {
        "n_nodes": panels.size,
        "n_steps": n_steps,
        "seconds": time.perf_counter() - started,
        "statement": _STATEMENTS[key],
        "richardson": bool(richardson),
        "error_estimate": float(error),
        "message": message,
    }
    return CollocationSolution(
        times=times_arr, settlement=result.delta, tilt=result.alpha, force=result.force,
        moment=result.moment, info=info, panels=panels, _lam=lam, _m=m_fn, _g=g_fn,
        _c=result.c, _effective=result.effective, _nodal=result.nodal)


# ---------------------------------------------------------------------------------------
# Time stepping


@dataclass(frozen=True)
class _Result:
    """Outputs at the requested times; linear in the solution, so grids can be combined."""

    delta: np.ndarray
    alpha: np.ndarray
    force: np.ndarray
    moment: np.ndarray
    c: np.ndarray
    effective: np.ndarray  # (N, T): q - V q at the nodes
    nodal: np.ndarray  # (N, T): q at the nodes

    def combine(self, coarse: _Result) -> _Result:
        """Richardson extrapolation ``(4 self - coarse) / 3`` (self on the halved grid)."""
        def mix(a: np.ndarray, b: np.ndarray) -> np.ndarray:
            return (4.0 * a - b) / 3.0
        return _Result(mix(self.delta, coarse.delta), mix(self.alpha, coarse.alpha),
                       mix(self.force, coarse.force), mix(self.moment, coarse.moment),
                       self.c, mix(self.effective, coarse.effective),
                       mix(self.nodal, coarse.nodal))

    def distance(self, other: _Result) -> float:
        """Largest relative difference over all outputs (each group on its own scale)."""
        def rel(pairs: list[tuple[np.ndarray, np.ndarray]]) -> float:
            scale = max(float(np.max(np.abs(a))) for a, _ in pairs) or 1.0
            return max(float(np.max(np.abs(a - b))) for a, b in pairs) / scale
        return max(rel([(self.delta, other.delta), (self.alpha, other.alpha)]),
                   rel([(self.force, other.force), (self.moment, other.moment)]),
                   rel([(self.nodal, other.nodal)]))


class _System:
    """One scene on one panel rule; :meth:`march` solves it on a given time grid."""

    def __init__(self, panels: Panels, op: np.ndarray, m: np.ndarray, g: np.ndarray,
                 given: frozenset[str], loads: dict, c_fn: Callable, kernel: Callable | None):
        self.panels = panels
        self.op = op
        self.m = m
        self.g = g
        self.given = given
        self.loads = loads
        self.c_fn = c_fn
        self.kernel = kernel
        n = panels.size
        x = panels.nodes
        self.unknown_delta = "settlement" not in given
        self.unknown_alpha = "tilt" not in given
        # Border of the augmented system: columns of the unknown ones of delta, alpha, and
        # the equilibrium rows of the given ones of P, M.
        cols = []
        if self.unknown_delta:
            cols.append(-np.ones(n))
        if self.unknown_alpha:
            cols.append(-x)
        rows = []
        if "force" in given:
            rows.append(panels.weights)
        if "moment" in given:
            rows.append(panels.weights * x)
        self.k = len(cols)
        self.border_cols = np.array(cols).T.reshape(n, self.k)
        self.border_rows = np.array(rows).reshape(self.k, n)
        self._lu: dict[tuple[float, float], tuple] = {}
        self._n_factorized = 0
        self._schur: tuple | None = None

    def _matrix(self, c_n: float, scale: float) -> np.ndarray:
        n = self.panels.size
        big = np.zeros((n + self.k, n + self.k))
        big[:n, :n] = scale * self.op
        big[np.arange(n), np.arange(n)] += c_n * self.m
        big[:n, n:] = self.border_cols
        big[n:, :n] = self.border_rows
        return big

    def solve(self, c_n: float, scale: float, rhs: np.ndarray) -> np.ndarray:
        """Solve the bordered step system with block ``c_n diag(m) + scale F``.

        A few distinct matrices (an elastic base, a non-aging kernel on a uniform grid) are
        LU-factorized and kept. Once more than ``_LU_LIMIT`` have been needed (aging: the
        diagonal trapezoid weight or ``c`` changes every step) a real Schur form of
        ``E = D^-1/2 F D^-1/2`` (D = diag(m)) is computed once, and every later step costs
        O(N^2): ``c D + s F = s D^1/2 U (T + (c/s) I) U^T D^1/2`` with T triangular. E is
        similar to the positive operator F/m, so ``T + (c/s) I`` is well conditioned for
        ``c/s > 0``; the border (k <= 2 unknowns) is eliminated with its k x k complement.
        """
        key = (c_n, scale)
        lu = self._lu.get(key)
        if lu is None and (self._n_factorized < _LU_LIMIT or scale <= 0.0):
            lu = lu_factor(self._matrix(c_n, scale), check_finite=False)
            self._n_factorized += 1
            if len(self._lu) >= 4:
                self._lu.pop(next(iter(self._lu)))
            self._lu[key] = lu
        if lu is not None:
            return lu_solve(lu, rhs, check_finite=False)
        if self._schur is None:
            root = np.sqrt(self.m)
            tri, vecs = schur(self.op / root[:, None] / root[None, :], output="real")
            if np.any(np.diag(tri, -1) != 0.0):
                # Complex eigenvalue pairs leave 2 x 2 blocks: go to the complex form.
                tri, vecs = rsf2csf(tri, vecs)
            self._schur = (tri.copy(), np.diag(tri).copy(), vecs,
                           np.ascontiguousarray(vecs.conj().T), root)
        shifted, diagonal, vecs, vecs_h, root = self._schur
        # Only the diagonal of the triangular factor depends on the step.
        np.fill_diagonal(shifted, diagonal + c_n / scale)

        def inverse(v: np.ndarray) -> np.ndarray:
            y = solve_triangular(shifted, vecs_h @ (v / root[:, None]), check_finite=False)
            return np.real(vecs @ y) / root[:, None] / scale

        if self.k == 0:
            return inverse(rhs[:, None])[:, 0]
        n = self.panels.size
        y = inverse(np.column_stack([rhs[:n], self.border_cols]))
        complement = self.border_rows @ y[:, 1:]
        u = np.linalg.solve(complement, self.border_rows @ y[:, 0] - rhs[n:])
        return np.concatenate([y[:, 0] - y[:, 1:] @ u, u])

    def march(self, grid: np.ndarray, widths: np.ndarray, out_index: np.ndarray) -> _Result:
        """Step through ``grid`` (step lengths ``widths``); record outputs at ``out_index``."""
        panels = self.panels
        n_nodes = panels.size
        x = panels.nodes
        steps = len(grid)
        c_vals = _eval_time(self.c_fn, grid, "c")
        if np.any(c_vals <= 0.0):
            raise ValueError("c: the relative modulus must be > 0 at every time")
        load = {name: _eval_time(fn, grid, name) for name, fn in self.loads.items()}
        zero = np.zeros(steps)
        delta_given = load.get("settlement", zero)
        alpha_given = load.get("tilt", zero)

        memory = self.kernel is not None
        if memory:
            # Trapezoid weight of node j in int_{t_0}^{t_n} for every j < n.
            inner = np.zeros(steps)
            inner[:-1] += 0.5 * widths
            inner[1:] += 0.5 * widths
            history = np.zeros((n_nodes, steps))

        wanted = {int(i): k for k, i in enumerate(out_index)}
        n_out = len(out_index)
        out = {name: np.zeros(n_out) for name in ("delta", "alpha", "force", "moment", "c")}
        effective = np.zeros((n_nodes, n_out))
        nodal = np.zeros((n_nodes, n_out))

        for n in range(steps):
            vq_past = np.zeros(n_nodes)
            diag_weight = 0.0
            if memory and n > 0:
                kvals = _eval_kernel(self.kernel, grid[n], grid[: n + 1])
                vq_past = history[:, :n] @ (inner[:n] * kvals[:n])
                diag_weight = 0.5 * widths[n - 1] * kvals[n]
            rhs = np.empty(n_nodes + self.k)
            rhs[:n_nodes] = delta_given[n] + alpha_given[n] * x - self.g + self.op @ vq_past
            extra = [load[name][n] for name in ("force", "moment") if name in self.given]
            rhs[n_nodes:] = extra
            sol = self.solve(c_vals[n], 1.0 - diag_weight, rhs)
            q = sol[:n_nodes]
            if memory:
                history[:, n] = q
            if n in wanted:
                k = wanted[n]
                tail = list(sol[n_nodes:])
                d = tail.pop(0) if self.unknown_delta else delta_given[n]
                a = tail.pop(0) if self.unknown_alpha else alpha_given[n]
                out["delta"][k] = d
                out["alpha"][k] = a
                out["force"][k] = load["force"][n] if "force" in load else panels.weights @ q
                out["moment"][k] = (load["moment"][n] if "moment" in load
                                    else (panels.weights * x) @ q)
                out["c"][k] = c_vals[n]
                effective[:, k] = q * (1.0 - diag_weight) - vq_past
                nodal[:, k] = q
        return _Result(out["delta"], out["alpha"], out["force"], out["moment"], out["c"],
                       effective, nodal)


def time_grid(times: np.ndarray, steps: int,
              refine: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A grid on ``[1, times[-1]]`` containing every requested time (dimensionless t).

    The nominal step is ``(times[-1] - 1) / steps``; each interval between consecutive
    requested times (and from 1 to the first) is split into equal steps no longer than
    that, and then every step is halved ``refine`` times. Halving the steps of a fixed
    grid (rather than recounting for ``2 steps``, which need not halve every interval's
    step) keeps the trapezoid error expansion in even powers of one step, which is what
    Richardson extrapolation needs. Returns the grid (G,), the step lengths (G-1,),
    exactly equal within an interval, and the grid index of each requested time.
    """
    times = np.asarray(times, dtype=float)
    h = (times[-1] - 1.0) / steps
    points = [1.0]
    widths: list[float] = []
    index = []
    start = 1.0
    for t in times:
        length = float(t) - start
        if length > 0.0:
            count = max(1, math.ceil(length / h - 1e-9)) * 2**refine
            points.extend(start + length * np.arange(1, count + 1) / count)
            points[-1] = float(t)
            # One width per interval, not np.diff of the points: equal widths keep the
            # step matrix bit-identical, so its factorization is reused.
            widths.extend([length / count] * count)
        index.append(len(points) - 1)
        start = float(t)
    return np.array(points), np.array(widths), np.array(index)


def _fixed_grids(system: _System, times: np.ndarray, steps: int,
                 richardson: bool) -> tuple[_Result, float, int]:
    grid, widths, index = time_grid(times, steps)
    coarse = system.march(grid, widths, index)
    fine_grid, fine_widths, fine_index = time_grid(times, steps, 1)
    fine = system.march(fine_grid, fine_widths, fine_index) if richardson else None
    if fine is None:
        return coarse, float("nan"), len(grid) - 1
    # |x_{h/2} - x_h| / 3 estimates the error of x_{h/2}; the extrapolated value is
    # better still, so this is a safe (pessimistic) figure.
    return fine.combine(coarse), fine.distance(coarse) / 3.0, len(fine_grid) - 1


def _adaptive_grids(system: _System, times: np.ndarray, richardson: bool,
                    tol: float) -> tuple[_Result, float, int, bool]:
    """Double the grid until the estimated relative error in time is below ``tol``."""
    level = 0
    plain: list[_Result] = []
    extrapolated: list[_Result] = []
    while True:
        grid, widths, index = time_grid(times, _FIRST_STEPS, level)
        plain.append(system.march(grid, widths, index))
        n_steps = len(grid) - 1
        error = float("inf")
        if richardson:
            if len(plain) >= 2:
                extrapolated.append(plain[-1].combine(plain[-2]))
            best = extrapolated[-1] if extrapolated else plain[-1]
            if len(extrapolated) >= 2:
                # Order 4: the newer extrapolation is ~16 times closer than the older one.
                error = extrapolated[-1].distance(extrapolated[-2]) / 15.0
        else:
            best = plain[-1]
            if len(plain) >= 2:
                error = plain[-1].distance(plain[-2]) / 3.0
        if error <= tol:
            return best, error, n_steps, True
        if 2 * n_steps > _MAX_STEPS:
            return best, error, n_steps, False
        level += 1


# ---------------------------------------------------------------------------------------
# Input checking


def _positive_number(value: object, name: str) -> float:
    return positive_number(value, name, style=PYTHON_STYLE)


def _check_breakpoints(breakpoints: Sequence[float]) -> list[float]:
    try:
        cuts = sorted(float(b) for b in breakpoints)
    except (TypeError, ValueError):
        raise ValueError("breakpoints: must be a sequence of numbers") from None
    if any(not math.isfinite(b) or abs(b) >= 1.0 for b in cuts):
        raise ValueError("breakpoints: must lie strictly inside (-1, 1)")
    if any(b - a <= 0.0 for a, b in zip(cuts[:-1], cuts[1:], strict=True)):
        raise ValueError("breakpoints: must be distinct")
    return cuts


def _space_function(value: object, name: str) -> Callable[[np.ndarray], np.ndarray]:
    if callable(value):
        return value  # type: ignore[return-value]
    number = _finite_number(value, name)
    return lambda x: np.full(np.shape(x), number)


def _time_function(value: object, name: str) -> Callable[[np.ndarray], np.ndarray]:
    if callable(value):
        return value  # type: ignore[return-value]
    number = _finite_number(value, name)
    return lambda t: np.full(np.shape(t), number)


def _finite_number(value: object, name: str) -> float:
    # reached only for values that are not callables, so a number is what is missing
    return finite_number(value, name, style=PYTHON_STYLE)


def _eval_space(fn: Callable, x: np.ndarray, name: str) -> np.ndarray:
    values = np.broadcast_to(np.asarray(fn(x), dtype=float), x.shape)
    if not np.all(np.isfinite(values)):
        raise ValueError(f"{name}: values on [-1, 1] must be finite")
    return np.array(values)


def _eval_time(fn: Callable, t: np.ndarray, name: str) -> np.ndarray:
    values = np.broadcast_to(np.asarray(fn(t), dtype=float), t.shape)
    if not np.all(np.isfinite(values)):
        raise ValueError(f"{name}: values must be finite at every time")
    return np.array(values)


def _eval_kernel(kernel: Callable, t: float, tau: np.ndarray) -> np.ndarray:
    values = np.broadcast_to(np.asarray(kernel(np.full(tau.shape, t), tau), dtype=float),
                             tau.shape)
    if not np.all(np.isfinite(values)):
        raise ValueError(f"kernel: K(t, tau) must be finite; it is not at t = {t!r}")
    return values
