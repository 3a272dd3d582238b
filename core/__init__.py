"""coated-punch: contact of a rigid punch on a coated, aging viscoelastic layer.

The public entry points, loaded on first use (importing one subpackage, say
:mod:`core.kernel`, does not load the whole pipeline):

- :func:`solve_dimensionless` (:mod:`core.solver`), :class:`ContactSolution`
  (:mod:`core.problem`): the dimensionless problem, answered by one of the engines;
- :func:`prepare` (:mod:`core.engines.nystrom`): prepare a geometry once, then
  ``.solve(...)`` the loads many times;
- :func:`solve`, :class:`Scene`, :class:`SceneSolution`, :func:`scene_from_dict`,
  :func:`load_scene`, :func:`save_scene` (:mod:`core.scene`): dimensional scenes in SI
  units with time in days;
- :func:`sweep`, :func:`load_study`, :func:`study_from_dict` (:mod:`core.study`): design
  studies (parameter sweeps, Monte Carlo) run on Dask;
- :func:`calibrate` (:mod:`core.back_analysis`): back-analysis, scene fields fitted to
  measured settlements and tilts with their standard errors and a forecast band;
- :func:`creep_coefficient_curve` (:mod:`core.creep`): the design codes' creep laws;
- :data:`STAGE_CACHE_BYTES`, :func:`set_stage_cache_budget`, :func:`stage_cache_bytes`
  (:mod:`core.budget`): the memory the solver's caches may hold;
  :func:`release_freed_memory`: freed memory given back to the system.

``core/README.md`` maps the subpackages.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from core.optional import lazy_exports
from core.version import VERSION as __version__

if TYPE_CHECKING:
    from core.back_analysis import calibrate
    from core.budget import (
        STAGE_CACHE_BYTES,
        release_freed_memory,
        set_stage_cache_budget,
        stage_cache_bytes,
    )
    from core.creep import creep_coefficient_curve
    from core.engines.nystrom import prepare
    from core.problem import ContactSolution
    from core.scene import Scene, SceneSolution, load_scene, save_scene, scene_from_dict, solve
    from core.solver import solve_dimensionless
    from core.study import load_study, study_from_dict, sweep

_EXPORTS: dict[str, str] = {
    "solve_dimensionless": "core.solver",
    "ContactSolution": "core.problem",
    "prepare": "core.engines.nystrom",
    "solve": "core.scene",
    "Scene": "core.scene",
    "SceneSolution": "core.scene",
    "scene_from_dict": "core.scene",
    "load_scene": "core.scene",
    "save_scene": "core.scene",
    "creep_coefficient_curve": "core.creep",
    "sweep": "core.study",
    "load_study": "core.study",
    "study_from_dict": "core.study",
    "calibrate": "core.back_analysis",
    "STAGE_CACHE_BYTES": "core.budget",
    "set_stage_cache_budget": "core.budget",
    "stage_cache_bytes": "core.budget",
    "release_freed_memory": "core.budget",
}

__all__ = [
    "__version__",
    "solve_dimensionless",
    "ContactSolution",
    "prepare",
    "solve",
    "Scene",
    "SceneSolution",
    "scene_from_dict",
    "load_scene",
    "save_scene",
    "creep_coefficient_curve",
    "sweep",
    "load_study",
    "study_from_dict",
    "calibrate",
    "STAGE_CACHE_BYTES",
    "set_stage_cache_budget",
    "stage_cache_bytes",
    "release_freed_memory",
]


__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS, globals())
