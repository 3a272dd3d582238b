"""The engines that answer the dimensionless contact problem, and their registry.

An engine answers the full-contact problem of :func:`core.solver.solve_dimensionless` in two
steps: ``prepare`` a validated geometry (:class:`core.problem.Geometry`), ``solve`` a
validated time side (:class:`core.problem.TimeInputs`). It returns a
:class:`core.problem.ContactSolution` whose ``info`` carries :data:`core.problem.INFO_KEYS`,
its ``success`` judged by :func:`core.problem.accepts` with the engine's margin. The
protocol :class:`Engine`, the registry :data:`ENGINES` (:func:`get_engine`,
:func:`register_engine`) and the order a defaulted method tries them in,
:data:`DEFAULT_ORDER`, are in :mod:`core.engines.registry`.

- :mod:`core.engines.nystrom` (``"nystrom"``, the default): direct Nystrom discretization on
  graded panels, prepared once per geometry. Its error estimate is made in
  :mod:`core.engines.nystrom.adapt` (the two-grid difference of q between gradings one
  level apart, ``AdaptiveGrid.spatial_error``), plus the time stepper's estimate under
  creep; :mod:`core.engines.nystrom.result` adds them and judges the sum.
- :mod:`core.engines.projection` (``"projection"``): the seed's Galerkin series; error from
  consecutive mode levels (:mod:`core.engines.projection.levels`), judged with margin 3
  in :mod:`core.engines.projection.solve`.
- :mod:`core.engines.collocation` (``"collocation"``): an independent cross-check on fixed
  panels; it estimates its time error (:mod:`core.engines.collocation.steps`) and its
  spatial error against the rule one level coarser (marched on the same time grids).
- :mod:`core.engines.layered` (not registered): the exact kernel of uniform coating layers
  on an elastic base. It needs each layer's thickness, modulus, Poisson ratio and
  interface and the base's thickness and Poisson ratio, which the dimensionless inputs
  have collapsed into the compliance ``m(x)``, so :func:`core.scene.solve` calls it with
  the scene; it answers with the same result type, ``info`` keys and acceptance rule.

The engines are independent of each other (an import-linter contract): only the registry
knows them all.
"""

from __future__ import annotations

from core.engines.registry import (
    DEFAULT_METHOD,
    DEFAULT_ORDER,
    ENGINES,
    Engine,
    engine_options,
    get_engine,
    register_engine,
)

__all__ = [
    "DEFAULT_METHOD",
    "DEFAULT_ORDER",
    "Engine",
    "engine_options",
    "ENGINES",
    "get_engine",
    "register_engine",
]
