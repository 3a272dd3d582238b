"""Preset scenes: the JSON files in ``assets/scenes`` (the same files the CLI reads)."""

from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path
from typing import Any

#: The project's ``assets/scenes`` (this file is the project's ``explorer/model/presets.py``).
SCENES_DIR = Path(__file__).resolve().parents[2] / "assets" / "scenes"

#: The preset a new session starts with, when it exists.
DEFAULT_PRESET = "uniform_flat"

#: Order in which presets are offered (others follow alphabetically).
ORDER = ("uniform_flat", "worn_coating", "patched_insert", "rounded_graded",
         "eccentric_creep", "eccentric_footing_liftoff", "stepped_punch")


@lru_cache(maxsize=1)
def _load_all(directory: str) -> dict[str, dict[str, Any]]:
    found: dict[str, dict[str, Any]] = {}
    root = Path(directory)
    if not root.is_dir():
        return found
    for path in sorted(root.glob("*.json")):
        try:
            scene = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, json.JSONDecodeError):
            continue  # a broken file must not take the explorer down; the CLI reports it
        if isinstance(scene, dict):
            found[path.stem] = scene
    ordered = {key: found[key] for key in ORDER if key in found}
    ordered.update({key: value for key, value in found.items() if key not in ordered})
    return ordered


def presets(directory: Path | None = None) -> dict[str, dict[str, Any]]:
    """Preset key (file stem) -> scene dict, in display order. Returns copies."""
    scenes = _load_all(str(directory or SCENES_DIR))
    return {key: json.loads(json.dumps(scene)) for key, scene in scenes.items()}


def preset_label(key: str, scene: dict[str, Any]) -> str:
    """What the preset selector shows for a preset."""
    return str(scene.get("name") or key.replace("_", " "))
