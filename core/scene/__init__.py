"""core.scene.pipeline."""

from __future__ import annotations

from core.scene.coating_check import check_scene
from core.scene.files import load_scene, read_scene_json, save_scene
from core.scene.model import Scene, profile_values
from core.scene.pipeline import solve
from core.scene.results import (
    FLAG_MESSAGES,
    LARGE_TILT,
    SceneSolution,
    plotting_grid,
    scene_model_error,
)
from core.scene.schema import MAX_SCENE_BYTES, check_fields, integer_in_range
from core.scene.validate import replace_loads, scene_from_dict

__all__ = [
    "check_fields",
    "check_scene",
    "FLAG_MESSAGES",
    "integer_in_range",
    "LARGE_TILT",
    "load_scene",
    "MAX_SCENE_BYTES",
    "plotting_grid",
    "profile_values",
    "read_scene_json",
    "replace_loads",
    "save_scene",
    "Scene",
    "scene_from_dict",
    "scene_model_error",
    "SceneSolution",
    "solve",
]
