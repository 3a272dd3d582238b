"""The collocation method as an engine of :func:`core.solver.solve_dimensionless`.

Meant for cross-checks, not for speed (O(N steps^2) in time): it shares nothing with the
other engines but the panel quadrature. Its panels are fixed by ``panels_per_unit`` and
``edge_width``; ``tol`` sets the time grid (Richardson over halved grids,
:mod:`core.engines.collocation.steps`), and the rule one level coarser (under creep
marched on the same time grids) estimates the spatial error.
"""

from __future__ import annotations

from collections.abc import Sequence

from core.engines.collocation.solve import (
    SUCCESS_MARGIN,
    CollocationGeometry,
    CollocationSolution,
    check_resolution,
    check_time_points,
    prepare_collocation,
    solve_prepared,
)
from core.problem import Geometry, TimeInputs


class CollocationEngine:
    """Nystrom collocation on fixed panels graded toward +-1 and the jumps, trapezoid
    product integration in time with Richardson extrapolation."""

    name = "collocation"
    prepare_options = ("panels_per_unit", "edge_width")
    solve_options = ("time_points", "richardson", "time_breaks")
    success_margin = SUCCESS_MARGIN

    def prepare(self, geometry: Geometry, *, panels_per_unit: float = 8,
                edge_width: float = 1e-4) -> CollocationGeometry:
        """Panels at most ``min(1 / panels_per_unit, 3 / lam)`` wide, graded to
        ``edge_width`` at +-1 and the breakpoints, and the operator on them."""
        ppu, edge = check_resolution(panels_per_unit, edge_width)
        return prepare_collocation(geometry.lam, geometry.m, geometry.g, geometry.breakpoints,
                                   ppu, edge, geometry.tol)

    def solve(self, prepared: CollocationGeometry, inputs: TimeInputs, *,
              time_points: int | None = None,
              richardson: bool | None = None,
              time_breaks: Sequence[float] = ()) -> CollocationSolution:
        """The full-contact answer for ``inputs``: ``time_points`` nominal steps over
        ``[1, times[-1]]`` (default: grids doubled until the estimate in time meets
        ``tol``); ``richardson`` (default: on under creep) extrapolates grids h and h/2;
        ``time_breaks``: times where a given history jumps (both sides are grid points)."""
        check_time_points(time_points)
        return solve_prepared(prepared, inputs.times, inputs.c, inputs.kernel, inputs.loads,
                              time_points, richardson, time_breaks=time_breaks)


#: The engine registered as ``"collocation"`` in :data:`core.engines.ENGINES`.
COLLOCATION = CollocationEngine()
