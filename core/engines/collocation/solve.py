"""An independent second method: Nystrom collocation on panels, trapezoid stepping in time.

The dimensionless problem (see ``core/README.md``)

    c(t) m(x) q(x,t) + (I - V) F q = delta(t) + alpha(t) x - g(x),   x in [-1, 1], t >= 1,
    int q dx = P(t),   int x q dx = M(t),

is discretized *directly*, with nothing in common with the Galerkin/modal solver but the
panel quadrature of :mod:`core.discretize.quadrature`:

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

This module holds the solution, the input checks and :func:`solve_collocation`; the time
stepping is :mod:`core.engines.collocation.steps` (``time_grid`` is re-exported here).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from core.discretize import Panels, base_panels, kernel_operator, operator_rows
from core.engines.collocation.steps import (
    MAX_STEPS,
    CollocationSystem,
    adaptive_grids,
    finite_values,
    fixed_grids,
    time_grid,
)
from core.problem import QUANTITIES as _QUANTITIES
from core.problem import STATEMENTS as _STATEMENTS
from core.problem import validate_times
from core.validation import PYTHON_STYLE, finite_number, positive_number

TimeInput = float | Callable[[np.ndarray], np.ndarray]

#: Default relative accuracy aimed at in time when ``time_points`` is not given.
DEFAULT_TIME_TOL = 1e-6

__all__ = ["DEFAULT_TIME_TOL", "CollocationSolution", "TimeInput", "collocation_panels",
           "solve_collocation", "time_grid"]


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
    m_fn = _function(m, "m")
    g_fn = _function(g, "g")
    c_fn = _function(c, "c")
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
    loads = {name: _function(value, name) for name, value in given.items()}
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
    system = CollocationSystem(panels, op, m_nodes, g_nodes, key, loads, c_fn, kernel)

    span = times_arr[-1] - 1.0
    message = "ok"
    if kernel is None or span <= 0.0:
        # No memory: every requested time is an independent elastic problem.
        result = system.march(times_arr, np.diff(times_arr), np.arange(len(times_arr)))
        n_steps = len(times_arr)
        error = 0.0
        richardson = False
    elif time_points is not None:
        result, error, n_steps = fixed_grids(system, times_arr, int(time_points), richardson)
    else:
        result, error, n_steps, met = adaptive_grids(system, times_arr, richardson, tol)
        if not met:
            message = (f"time grid limit of {MAX_STEPS} steps reached; estimated relative "
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


def _function(value: object, name: str) -> Callable[[np.ndarray], np.ndarray]:
    # a callable of x or t as it is, a number as the constant function of that value
    if callable(value):
        return value  # type: ignore[return-value]
    number = _finite_number(value, name)
    return lambda points: np.full(np.shape(points), number)


def _finite_number(value: object, name: str) -> float:
    # reached only for values that are not callables, so a number is what is missing
    return finite_number(value, name, style=PYTHON_STYLE)


def _eval_space(fn: Callable, x: np.ndarray, name: str) -> np.ndarray:
    return finite_values(fn, x, name, "values on [-1, 1] must be finite")

