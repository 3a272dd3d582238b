"""coated-punch: contact of a rigid punch on a coated, aging viscoelastic layer.

The public entry points are loaded on first use, so that importing one submodule (say
:mod:`core.kernel`) does not load the whole pipeline:

- :func:`solve_dimensionless`, :class:`ContactSolution` (:mod:`core.solver`): the
  dimensionless problem;
- :func:`prepare` (:mod:`core.prepared`): prepare a geometry once, ``.solve(...)`` the
  loads many times;
- :func:`solve`, :class:`Scene`, :class:`SceneSolution`, :func:`scene_from_dict`,
  :func:`load_scene`, :func:`save_scene` (:mod:`core.scene`): dimensional scenes in SI
  units with time in days;
- :func:`sweep` (:mod:`core.sweeps`), :func:`load_study`, :func:`study_from_dict`
  (:mod:`core.study`): design studies (parameter sweeps, Monte Carlo) run on Dask.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from core.code_creep import creep_coefficient_curve
    from core.prepared import prepare
    from core.scene import (
        Scene,
        SceneSolution,
        load_scene,
        save_scene,
        scene_from_dict,
        solve,
    )
    from core.solver import ContactSolution, solve_dimensionless
    from core.study import load_study, study_from_dict
    from core.sweeps import sweep

_EXPORTS: dict[str, str] = {
    "solve_dimensionless": "core.solver",
    "prepare": "core.prepared",
    "ContactSolution": "core.solver",
    "solve": "core.scene",
    "Scene": "core.scene",
    "SceneSolution": "core.scene",
    "scene_from_dict": "core.scene",
    "load_scene": "core.scene",
    "save_scene": "core.scene",
    "creep_coefficient_curve": "core.code_creep",
    "sweep": "core.sweeps",
    "load_study": "core.study",
    "study_from_dict": "core.study",
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
