"""Preset scenes: the scene files shipped in the package (:mod:`core.presets`), the same
files the command line reads as ``preset:NAME``."""

from __future__ import annotations

import json
import logging
from functools import lru_cache
from typing import Any

from core.presets import preset_names, read_preset

LOG = logging.getLogger(__name__)

#: The preset a new session starts with, when it exists.
DEFAULT_PRESET = "uniform_flat"

#: Order in which presets are offered (others follow alphabetically).
ORDER = ("uniform_flat", "worn_coating", "patched_insert", "rounded_graded",
         "eccentric_creep", "eccentric_footing_liftoff", "stepped_punch", "bare_layer",
         "new_footing_beside_old")


@lru_cache(maxsize=1)
def _load_all() -> dict[str, dict[str, Any]]:
    found: dict[str, dict[str, Any]] = {}
    for name in preset_names():
        try:
            found[name] = read_preset(name)
        except (OSError, ValueError) as error:
            # One broken file must not take the explorer down; the tests read every preset.
            LOG.error("preset %s not offered: %s", name, error)
    ordered = {key: found[key] for key in ORDER if key in found}
    ordered.update({key: value for key, value in found.items() if key not in ordered})
    return ordered


def presets() -> dict[str, dict[str, Any]]:
    """Preset key (file stem) -> scene dict, in display order. Returns copies."""
    return {key: json.loads(json.dumps(scene)) for key, scene in _load_all().items()}


def preset_label(key: str, scene: dict[str, Any]) -> str:
    """What the preset selector shows for a preset."""
    return str(scene.get("name") or key.replace("_", " "))
