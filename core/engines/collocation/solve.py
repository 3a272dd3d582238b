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

This module holds the solution type, the input checks and :func:`solve_collocation`, made
of the two steps the registered engine (:mod:`core.engines.collocation.engine`) takes too:
:func:`prepare_collocation` (panels and operator) and :func:`solve_prepared` (the time
stepping, the judgement of its estimate, the answer); the time stepping itself is
:mod:`core.engines.collocation.steps`.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from core.discretize import Panels, base_panels, kernel_operator, operator_rows
from core.engines.collocation.steps import (
    FIRST_STEPS,
    MAX_STEPS,
    CollocationSystem,
    adaptive_grids,
    finite_values,
    fixed_grids,
    grids_at,
)
from core.limits import MAX_RUN_MEMORY_BYTES
from core.problem import QUANTITIES as _QUANTITIES
from core.problem import STATEMENTS as _STATEMENTS
from core.problem import ContactSolution, accepts, validate_times
from core.validation import PYTHON_STYLE, finite_number, positive_number

TimeInput = float | Callable[[np.ndarray], np.ndarray]

#: Default relative accuracy aimed at in time when ``time_points`` is not given.
DEFAULT_TIME_TOL = 1e-6
#: The spatial estimate of an elastic answer is this many times its distance from the
#: rule of merged panels: the edge panels double too, where q converges slowly, so the
#: distance is about the error itself (measured error / distance 0.98 to 1.1 for m from
#: 1e-6 to 0.05, lam 1 and 50).
COARSER_FACTOR = 2.0
#: Margin of :func:`core.problem.accepts`: the estimate in time (the distance of two
#: Richardson levels over 15, or of two grids over 3) is taken as it stands.
SUCCESS_MARGIN = 1.0

__all__ = ["DEFAULT_TIME_TOL", "CollocationGeometry", "CollocationSolution", "TimeInput",
           "collocation_panels", "prepare_collocation", "solve_collocation", "solve_prepared"]


class CollocationSolution(ContactSolution):
    """The :class:`core.problem.ContactSolution` of the collocation engine.

    Its ``info`` holds the keys every engine sets (:data:`core.problem.INFO_KEYS`) and
    ``richardson``, ``nodes`` and ``nodal_pressure`` (the collocation solution itself,
    arrays); this class only reads the last two as attributes. ``error_estimate`` is the
    estimated relative error of the time discretization (NaN for one fixed grid without
    Richardson) plus the spatial one (``spatial_error_estimate``: twice the distance from
    the rule one level coarser, marched on the same time grids), the panels being fixed by
    ``panels_per_unit`` and ``edge_width`` (refine them where the estimate says so).
    """

    @property
    def nodes(self) -> np.ndarray:
        """Collocation nodes in [-1, 1] (dimensionless x), shape (N,)."""
        return self.info["nodes"]

    @property
    def nodal_pressure(self) -> np.ndarray:
        """Dimensionless pressure at the collocation nodes, shape (N, len(times))."""
        return self.info["nodal_pressure"]


@dataclass(frozen=True)
class CollocationGeometry:
    """The spatial side of a collocation solve (dimensionless): the panel rule, the
    discrete operator ``F`` on it (N x N), ``m`` and ``g`` at its nodes, and ``tol``, the
    relative accuracy the time grid aims at (the panels are fixed)."""

    lam: float
    m: Callable[[np.ndarray], np.ndarray]
    g: Callable[[np.ndarray], np.ndarray]
    panels: Panels
    operator: np.ndarray = field(repr=False)
    m_nodes: np.ndarray = field(repr=False)
    g_nodes: np.ndarray = field(repr=False)
    breakpoints: tuple[float, ...]
    tol: float
    seconds: float  # time of the preparation [s]
    #: Whether an answer is compared with the rule one level coarser (:attr:`coarse`)
    coarser: bool = True

    @cached_property
    def coarse(self) -> CollocationGeometry | None:
        """The rule one level coarser, pairs of this one's panels merged (each breakpoint
        kept an edge), and the operator on it: its distance is the spatial estimate (None
        when there is no coarser rule, or for the coarse rule itself).
        Merged panels, not half the panels per unit and a coarser edge: those caps (panels
        at most 3 / lam wide, edge panels at most an eighth of their interval) could make
        the same rule again, whose distance, 0, let a wrong answer pass."""
        edges = self.panels.edges
        if not self.coarser or edges.size < 3:
            return None
        merged = np.union1d(edges[::2], np.concatenate([[edges[0], edges[-1]],
                                                        np.asarray(self.breakpoints)]))
        if merged.size == edges.size:
            return None
        return _geometry(self.lam, self.m, self.g, Panels.from_edges(merged),
                         self.breakpoints, self.tol, time.perf_counter(), coarser=False)


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
    time_breaks: Sequence[float] = (),
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
    given) combines the grids h and h/2 as ``(4 x_{h/2} - x_h) / 3``. Success asks the
    estimate in time plus the spatial one (twice the distance from the rule one level
    coarser, marched on the same time grids) to be below ``time_tol``. ``time_breaks``:
    times where a given history jumps; every time grid holds both sides of each.

    Raises ValueError, naming the argument, for invalid input.
    """
    started = time.perf_counter()
    lam = _positive_number(lam, "lam")
    ppu, edge = check_resolution(panels_per_unit, edge_width)
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
    check_time_points(time_points)

    prepared = prepare_collocation(lam, m_fn, g_fn, cuts, ppu, edge, tol, started=started)
    return solve_prepared(prepared, times_arr, c_fn, kernel, loads, time_points, richardson,
                          tol_name="time_tol", time_breaks=time_breaks)


#: Dense N x N matrices a collocation geometry holds at once (the operator, its
#: factors, the coarser rule's): what its memory check counts.
DENSE_COPIES = 3


def prepare_collocation(lam: float, m: Callable[[np.ndarray], np.ndarray],
                        g: Callable[[np.ndarray], np.ndarray], breakpoints: Sequence[float],
                        panels_per_unit: float, edge_width: float, tol: float, *,
                        started: float | None = None, coarser: bool = True
                        ) -> CollocationGeometry:
    """The panel rule of :func:`collocation_panels` and the operator on it, for checked
    arguments (``started``: the clock [s] the preparation counts from, default now), and
    with ``coarser`` an answer compared with the rule one level coarser
    (:attr:`CollocationGeometry.coarse`, made when first asked)."""
    started = time.perf_counter() if started is None else started
    panels = collocation_panels(lam, breakpoints, panels_per_unit=panels_per_unit,
                                edge_width=edge_width)
    dense = DENSE_COPIES * 8.0 * float(panels.size) ** 2
    if dense > MAX_RUN_MEMORY_BYTES:
        # (panels_per_unit 2000 asked numpy for 30.6 GiB and raised its MemoryError)
        raise ValueError(f"panels_per_unit: {panels_per_unit:g} makes {panels.size} nodes, "
                         f"whose dense operators would take {dense / 2**30:.3g} GiB, over "
                         f"the {MAX_RUN_MEMORY_BYTES / 2**30:g} GiB a run may take: ask "
                         "fewer panels a unit (or a larger edge_width)")
    return _geometry(lam, m, g, panels, breakpoints, tol, started, coarser)


def _geometry(lam: float, m: Callable[[np.ndarray], np.ndarray],
              g: Callable[[np.ndarray], np.ndarray], panels: Panels,
              breakpoints: Sequence[float], tol: float, started: float, coarser: bool
              ) -> CollocationGeometry:
    """The :class:`CollocationGeometry` on ``panels``."""
    x = panels.nodes
    m_nodes = _eval_space(m, x, "m")
    if np.any(m_nodes <= 0.0):
        raise ValueError("m: the coating compliance must be > 0 on [-1, 1]")
    g_nodes = _eval_space(g, x, "g")
    op = kernel_operator(lam, panels).matrix
    return CollocationGeometry(lam, m, g, panels, op, m_nodes, g_nodes, tuple(breakpoints),
                               tol, time.perf_counter() - started, coarser)


def solve_prepared(prepared: CollocationGeometry, times: np.ndarray,
                   c: Callable[[np.ndarray], np.ndarray], kernel: Callable | None,
                   loads: dict[str, Callable[[np.ndarray], np.ndarray]],
                   time_points: int | None, richardson: bool | None, *,
                   tol_name: str = "tol", time_breaks: Sequence[float] = ()
                   ) -> CollocationSolution:
    """March the prepared rule through ``times`` for checked arguments: ``loads`` the two
    given histories by name, ``time_points`` a fixed grid (None: grids doubled until the
    estimate meets ``prepared.tol``, named ``tol_name`` in the message), every grid
    holding both sides of each of ``time_breaks`` (times where a history jumps).

    The spatial estimate is :data:`COARSER_FACTOR` times this answer's distance from the
    one on the rule one level coarser (``prepared.coarse``: the histories, and q at this
    rule's nodes by the coarser answer's formula); under creep the coarser rule is marched
    on this answer's time grids (``info["time_grid"]``), so the two err alike in time and
    differ by space. Without it a fixed rule claimed success with an estimate of 0: q off
    by 2.4e-2 at the edges of a stiff coating (m = 1e-6), whose layer the default edge
    grading (1e-4) does not resolve; under creep the estimate was NaN."""
    jumps = tuple(sorted({float(b) for b in np.asarray(time_breaks, dtype=float).ravel()
                          if np.isfinite(b) and 1.0 < b < float(times[-1])}))
    answer = _march_prepared(prepared, times, c, kernel, loads, time_points, richardson,
                             tol_name, jumps=jumps)
    if not prepared.coarser:
        return answer
    info = answer.info
    if prepared.coarse is None:  # one panel: nothing coarser to compare with
        spatial = math.nan
    else:
        coarse = _march_prepared(prepared.coarse, times, c, kernel, loads, time_points,
                                 richardson, tol_name, on_grid=info["time_grid"],
                                 jumps=jumps)
        spatial = COARSER_FACTOR * _distance(answer, coarse)
        info["seconds"] += prepared.coarse.seconds + coarse.info["seconds"]
    time_error = float(info["time_error_estimate"])
    error = time_error + spatial
    success = accepts(error, prepared.tol, SUCCESS_MARGIN)
    info.update(spatial_error_estimate=spatial, error_estimate=error, success=success)
    # lift-off is judged against the whole estimate, as the other engines judge it
    flags = [f for f in info["flags"] if f not in ("tol_not_met", "contact_lost")]
    if info["min_pressure"] < -max(error if math.isfinite(error) else 0.0,
                                   1e-12) * info["max_pressure"]:
        flags.append("contact_lost")
    if not success:
        flags.insert(0, "tol_not_met")
        reasons = []
        if info["message"] != "ok":  # the time part's own reason (a limit, no estimate)
            reasons.append(f"time: {info['message']}")
        if not spatial * SUCCESS_MARGIN <= prepared.tol:
            reasons.append(f"space: the distance from the rule one level coarser gives "
                           f"{spatial:.1e}; refine panels_per_unit or edge_width")
        if not reasons:
            reasons.append(f"space {spatial:.1e} and time {time_error:.1e} together")
        info["message"] = (f"estimated relative error {error:.1e} is above {tol_name} = "
                           f"{prepared.tol:.1e}: " + "; ".join(reasons))
    info["flags"] = flags
    return answer


def _distance(answer: CollocationSolution, coarse: CollocationSolution) -> float:
    """The relative distance of two answers: settlement and tilt relative to the larger of
    their largest values, force and moment too, q at ``answer``'s nodes (``coarse`` by its
    formula) relative to the largest q."""
    kin = max(float(np.max(np.abs(answer.settlement))), float(np.max(np.abs(answer.tilt))),
              1e-300)
    dyn = max(float(np.max(np.abs(answer.force))), float(np.max(np.abs(answer.moment))),
              1e-300)
    out = max(float(np.max(np.abs(answer.settlement - coarse.settlement))) / kin,
              float(np.max(np.abs(answer.tilt - coarse.tilt))) / kin,
              float(np.max(np.abs(answer.force - coarse.force))) / dyn,
              float(np.max(np.abs(answer.moment - coarse.moment))) / dyn)
    q = answer.nodal_pressure
    scale = max(float(np.max(np.abs(q))), 1e-300)
    return max(out, float(np.max(np.abs(coarse.pressure(answer.nodes) - q))) / scale)


def _march_prepared(prepared: CollocationGeometry, times: np.ndarray,
                    c: Callable[[np.ndarray], np.ndarray], kernel: Callable | None,
                    loads: dict[str, Callable[[np.ndarray], np.ndarray]],
                    time_points: int | None, richardson: bool | None,
                    tol_name: str, on_grid: tuple[int, int] | None = None,
                    jumps: Sequence[float] = ()) -> CollocationSolution:
    """:func:`solve_prepared` on the prepared rule alone (its time estimate only).

    ``on_grid``: ``(steps, level)`` of another answer's time grid (its ``info["time_grid"]``)
    to march on, without an estimate in time (see :func:`steps.grids_at`)."""
    started = time.perf_counter()
    tol = prepared.tol
    panels = prepared.panels
    key = frozenset(loads)
    if richardson is None:
        richardson = kernel is not None
    system = CollocationSystem(panels, prepared.operator, prepared.m_nodes, prepared.g_nodes,
                               key, loads, c, kernel)

    span = times[-1] - 1.0
    limited = False
    grid_used: tuple[int, int] | None = None
    if kernel is None or span <= 0.0:
        # No memory: every requested time is an independent elastic problem.
        result = system.march(times, np.diff(times), np.arange(len(times)))
        n_steps = len(times)
        error = 0.0
        richardson = False
    elif on_grid is not None:
        result = grids_at(system, times, on_grid[0], on_grid[1], richardson, jumps)
        error, n_steps, grid_used = 0.0, 0, on_grid
    elif time_points is not None:
        result, error, n_steps = fixed_grids(system, times, int(time_points), richardson,
                                             jumps)
        grid_used = (int(time_points), 1 if richardson else 0)
    else:
        result, error, n_steps, met, level = adaptive_grids(system, times, richardson, tol,
                                                            jumps)
        limited = not met
        grid_used = (FIRST_STEPS, level)

    success = accepts(error, tol, SUCCESS_MARGIN)
    if success:
        message = "ok"
    elif limited:
        message = (f"time grid limit of {MAX_STEPS} steps reached; estimated relative "
                   f"error {error:.1e} is above {tol_name} = {tol:.1e}")
    elif math.isnan(error):
        message = ("no error estimate: one fixed time grid without Richardson "
                   "extrapolation")
    else:
        message = f"estimated relative error {error:.1e} is above {tol_name} = {tol:.1e}"
    flags = [] if success else ["tol_not_met"]
    q_scale = max(float(np.max(np.abs(result.nodal))), 1e-300)
    min_q = float(np.min(result.nodal))
    # as the other engines judge lift-off: below minus the estimate, relative to max|q|
    if min_q < -max(error if math.isfinite(error) else 0.0, 1e-12) * q_scale:
        flags.append("contact_lost")
    seconds = time.perf_counter() - started
    info = {
        "method": "collocation",
        "error_estimate": float(error),
        "spatial_error_estimate": math.nan,
        "time_error_estimate": float(error),
        "kernel_fit_error": 0.0,  # the kernel is used as it is, not fitted
        "seconds": prepared.seconds + seconds,
        "flags": flags,
        "success": success,
        "message": message,
        "n_modes": panels.size,
        "n_nodes": panels.size,
        "n_steps": n_steps,
        "statement": _STATEMENTS[key],
        "given": sorted(key),
        # over the nodes and the output times
        "min_pressure": min_q,
        "max_pressure": q_scale,
        "basis": "collocation",
        "element_ends": sorted(set(panels.edges[1:-1].tolist()) | set(prepared.breakpoints)),
        "stages": {"panels": {"seconds": prepared.seconds, "cached": False},
                   "solve": {"seconds": seconds, "cached": False}},
        "richardson": bool(richardson),
        # (nominal steps, halvings) of the time grid marched, None without memory
        "time_grid": grid_used,
        "nodes": panels.nodes,
        "nodal_pressure": result.nodal,
    }
    lam, m, g = prepared.lam, prepared.m, prepared.g
    c_out, effective = result.c, result.effective
    settlement, tilt = result.delta, result.alpha

    def pressure(x: np.ndarray) -> np.ndarray:
        # the Nystrom formula: exact at the nodes, and between them as accurate as the
        # nodal solution (divided by c m(x), so relative accuracy degrades as m -> 0)
        if x.ndim != 1:
            raise ValueError("x: must be a scalar or a 1-D array of points")
        m_x = _eval_space(m, x, "m")
        g_x = _eval_space(g, x, "g")
        fq = operator_rows(lam, panels, x) @ effective
        rhs = settlement[None, :] + tilt[None, :] * x[:, None] - g_x[:, None] - fq
        return rhs / (m_x[:, None] * c_out[None, :])

    return CollocationSolution(times, settlement, tilt, result.force, result.moment, info,
                               None, np.zeros((0, times.size)), c_out, m, g, pressure)



# ---------------------------------------------------------------------------------------
# Input checking


def check_resolution(panels_per_unit: object, edge_width: object) -> tuple[float, float]:
    """``panels_per_unit`` and ``edge_width`` checked (``ValueError`` naming a bad one)."""
    ppu = _positive_number(panels_per_unit, "panels_per_unit")
    edge = _positive_number(edge_width, "edge_width")
    if edge > 1.0:
        raise ValueError(f"edge_width: must be at most 1, got {edge!r}")
    return ppu, edge


def check_time_points(time_points: object) -> None:
    """Refuse a ``time_points`` that is not None or a positive integer, naming it."""
    if time_points is not None:
        if isinstance(time_points, bool) or not isinstance(time_points, (int, np.integer)) \
                or time_points < 1:
            raise ValueError(f"time_points: must be a positive integer, got {time_points!r}")


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

