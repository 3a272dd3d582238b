"""An independent second method for cross-checks: Nystrom collocation on fixed panels.

- :mod:`~core.engines.collocation.engine`: :data:`COLLOCATION`, the engine of the registry
  (options ``panels_per_unit``, ``edge_width``, ``time_points``, ``richardson``);
- :mod:`~core.engines.collocation.solve`: :func:`solve_collocation` (the method with its
  own checks and ``time_tol``), the preparation of the panels and the packing of the
  answer as a :class:`CollocationSolution` (a ``ContactSolution`` that also reads its
  nodal solution from ``info``);
- :mod:`~core.engines.collocation.steps`: the trapezoid-product time stepping, and **the
  error estimate in time**: Richardson over halved grids (``fixed_grids``,
  ``adaptive_grids``). The panels are fixed; the rule one level coarser, marched on the
  same grids (``grids_at``), estimates the spatial error.
"""

from __future__ import annotations

from core.engines.collocation.engine import COLLOCATION, CollocationEngine
from core.engines.collocation.solve import CollocationSolution, solve_collocation

__all__ = [
    "COLLOCATION",
    "CollocationEngine",
    "CollocationSolution",
    "solve_collocation",
]
