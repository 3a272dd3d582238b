"""The exact layered kernel: uniform coating layers on an elastic base (a scene-level engine).

It needs the stack itself (each layer's thickness, modulus, Poisson ratio and interface,
the base's thickness and Poisson ratio), which the dimensionless problem has collapsed into
the thin-layer compliance ``m(x)``: so it is not in :data:`core.engines.ENGINES`, and
:func:`core.scene.solve` asks it first with the scene (:func:`solve_scene_layered`, None
where :func:`layered_declines`). Its answer is a :class:`core.problem.ContactSolution`
with the common ``info`` keys and :func:`core.problem.accepts` (margin 1).

- :mod:`~core.engines.layered.answer`: :func:`solve_scene_layered`, when it applies, the
  answer packed;
- :mod:`~core.engines.layered.solve`: :func:`solve_layered` (Chebyshev-Galerkin on the
  stack's kernel) and **the error estimate**: the answers with half and a quarter of the
  modes, their differences extrapolated geometrically;
- :mod:`~core.engines.layered.bare_creep`: the bare base that creeps or ages (scalar
  Volterra equations over the elastic unit responses);
  :mod:`~core.engines.layered.bare_lift_off`: a punch lifting off the bare elastic base
  (the zone a narrower punch's, its free end where the pressure's singular coefficient
  vanishes); :mod:`~core.engines.layered.bare_growing_zone`: lifting off the bare base
  that creeps or ages while the zone grows (the elastic zones of the crept loads, the
  pressure their hereditary transform);
- :mod:`~core.engines.layered.galerkin`: modes, nodes and the Galerkin matrix;
- :mod:`~core.engines.layered.cache`: the bounded caches of tables, operators and
  responses; :mod:`~core.engines.layered.stiffness`: flat-punch stiffnesses in SI units.
"""

from __future__ import annotations

from core.engines.layered.answer import (
    EXACT_LAYERED,
    LIFT_OFF_SHARE,
    NO_COATING,
    LiftOffNotAnswered,
    bare_creep_declines,
    corner_reach,
    layered_declines,
    solve_scene_layered,
    thinnest_bare_base,
    uniform_layers,
)
from core.engines.layered.cache import gap_key, share_budget, stack_key
from core.engines.layered.galerkin import COARSE_TOL, MAX_MODES, default_modes
from core.engines.layered.solve import (
    COARSE_ERROR_FLOOR,
    ERROR_FLOOR,
    MAX_RATIO,
    PRESSURE_REACH,
    LayeredResponse,
    cached_response,
    geometric_tail,
)

__all__ = [
    "bare_creep_declines",
    "cached_response",
    "corner_reach",
    "COARSE_ERROR_FLOOR",
    "COARSE_TOL",
    "default_modes",
    "ERROR_FLOOR",
    "EXACT_LAYERED",
    "gap_key",
    "geometric_tail",
    "layered_declines",
    "LayeredResponse",
    "LIFT_OFF_SHARE",
    "LiftOffNotAnswered",
    "MAX_MODES",
    "MAX_RATIO",
    "NO_COATING",
    "PRESSURE_REACH",
    "share_budget",
    "solve_scene_layered",
    "stack_key",
    "thinnest_bare_base",
    "uniform_layers",
]
