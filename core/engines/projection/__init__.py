"""The seed's projection method: a Galerkin series on a basis orthonormal for ``1/m``.

- :mod:`~core.engines.projection.engine`: :data:`PROJECTION`, the engine of the registry
  (options ``basis`` and ``n_modes``);
- :mod:`~core.engines.projection.solve`: :func:`solve_projection`, the adaptive mode count
  over the cached stages, and the judgement of its estimate with :data:`SUCCESS_MARGIN`
  (3: the estimate can read ~3x low);
- :mod:`~core.engines.projection.stages`: :func:`validate_inputs` and the spatial stages
  (panels, operator, basis, Galerkin rows, gap, modes);
- :mod:`~core.engines.projection.levels`: the time stage of one mode level, the
  superposition of loads, and **the error estimate**: the differences of consecutive
  mode levels extrapolated as a geometric tail (``_extrapolated_error``), and the
  residual at sample points;
- :mod:`~core.engines.projection.matrices`: the Galerkin matrices ``R_ij``, ``G_i``;
- :mod:`~core.engines.projection.caches`: the stage caches, keyed by content.
"""

from __future__ import annotations

from core.engines.projection.caches import DEFAULT_STAGE_BYTES, PROJECTION_CACHES
from core.engines.projection.engine import PROJECTION, ProjectionEngine, ProjectionSetup
from core.engines.projection.solve import SUCCESS_MARGIN, solve_projection
from core.engines.projection.stages import validate_inputs

__all__ = [
    "DEFAULT_STAGE_BYTES",
    "PROJECTION",
    "PROJECTION_CACHES",
    "ProjectionEngine",
    "ProjectionSetup",
    "solve_projection",
    "SUCCESS_MARGIN",
    "validate_inputs",
]
