"""coated-punch: contact of a rigid punch on a coated, aging viscoelastic layer.

The public entry points are loaded on first use, so that importing one submodule (say
:mod:`core.kernel.plane`) does not load the whole pipeline:

- :func:`solve_dimensionless`, :class:`ContactSolution` (:mod:`core.solver`): the
  dimensionless problem;
- :func:`prepare` (:mod:`core.engines.nystrom.prepared`): prepare a geometry once, ``.solve(...)`` the
  loads many times;
- :func:`solve`, :class:`Scene`, :class:`SceneSolution`, :func:`scene_from_dict`,
  :func:`load_scene`, :func:`save_scene` (:mod:`core.scene.pipeline`): dimensional scenes in SI
  units with time in days;
- :func:`sweep` (:mod:`core.study.run`), :func:`load_study`, :func:`study_from_dict`
  (:mod:`core.study.definition`): design studies (parameter sweeps, Monte Carlo) run on Dask.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from core.budget import STAGE_CACHE_BYTES, set_stage_cache_budget, stage_cache_bytes
    from core.creep.design_codes import creep_coefficient_curve
    from core.engines.nystrom.prepared import prepare
    from core.scene.pipeline import (
        Scene,
        SceneSolution,
        load_scene,
        save_scene,
        scene_from_dict,
        solve,
    )
    from core.solver import ContactSolution, solve_dimensionless
    from core.study.definition import load_study, study_from_dict
    from core.study.run import sweep

_EXPORTS: dict[str, str] = {
    "solve_dimensionless": "core.solver",
    "prepare": "core.engines.nystrom.prepared",
    "ContactSolution": "core.solver",
    "solve": "core.scene.pipeline",
    "Scene": "core.scene.pipeline",
    "SceneSolution": "core.scene.pipeline",
    "scene_from_dict": "core.scene.pipeline",
    "load_scene": "core.scene.pipeline",
    "save_scene": "core.scene.pipeline",
    "creep_coefficient_curve": "core.creep.design_codes",
    "sweep": "core.study.run",
    "STAGE_CACHE_BYTES": "core.budget",
    "set_stage_cache_budget": "core.budget",
    "stage_cache_bytes": "core.budget",
    "load_study": "core.study.definition",
    "study_from_dict": "core.study.definition",
}

__all__ = [
    "solve_dimensionless",
    "prepare",
    "ContactSolution",
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
    "STAGE_CACHE_BYTES",
    "set_stage_cache_budget",
    "stage_cache_bytes",
]


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'core' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value  # later lookups skip this function
    return value


def __dir__() -> list[str]:
    return sorted(list(globals()) + __all__)
