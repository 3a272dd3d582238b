"""The default engine: a direct Nystrom discretization on graded panels, prepared once.

- :mod:`~core.engines.nystrom.engine`: :data:`NYSTROM`, the engine of the registry;
- :mod:`~core.engines.nystrom.prepared`: :func:`prepare` and :class:`PreparedContact`
  (the geometry prepared once, the members its solves build and keep, ``solve``), the
  cache of prepared geometries :data:`PREPARED`, :func:`solve_with_prepared`;
- :mod:`~core.engines.nystrom.adapt`: the adaptive refinement of the grid and **the
  error estimate in space**: the two-grid difference of the nodal q when the grading
  toward +-1 and the jumps deepens by one level (times ``SAFETY / (LEVEL_RATIO - 1)``),
  plus the Legendre tails of the interior panels (``AdaptiveGrid.spatial_error``);
- :mod:`~core.engines.nystrom.bordered`: the discretization, the bordered solve of q and
  the two unknown scalars, the Nystrom formula between the nodes;
  :mod:`~core.engines.nystrom.twogrid`: a refined grid solved with the factors of the
  grid it refines;
- :mod:`~core.engines.nystrom.elastic`: the elastic answer from cached unit responses;
  :mod:`~core.engines.nystrom.modal`: the modal form for creep or a modulus varying in
  time, stepped by :mod:`core.time.integration`, whose estimate is the time part;
- :mod:`~core.engines.nystrom.multi`: several punches on one foundation, each on its own
  grid, coupled through the base (:func:`solve_punches`, :class:`PunchGeometry`);
- :mod:`~core.engines.nystrom.result`: the two parts added into
  ``info["error_estimate"]``, judged against ``tol`` (margin 1) and packed.
"""

from __future__ import annotations

from core.engines.nystrom.engine import NYSTROM, NystromEngine
from core.engines.nystrom.multi import (
    COUPLED,
    CoupledPunches,
    PunchGeometry,
    coupled_for,
    coupled_x,
    interacting,
    solve_punches,
)
from core.engines.nystrom.prepared import (
    PREPARED,
    PREPARED_BYTES,
    PreparedContact,
    creep_reference,
    prepare,
    prepared_for,
    solve_with_prepared,
)

__all__ = [
    "COUPLED",
    "coupled_for",
    "coupled_x",
    "creep_reference",
    "CoupledPunches",
    "interacting",
    "PunchGeometry",
    "solve_punches",
    "NYSTROM",
    "NystromEngine",
    "prepare",
    "PREPARED",
    "PREPARED_BYTES",
    "prepared_for",
    "PreparedContact",
    "solve_with_prepared",
]
