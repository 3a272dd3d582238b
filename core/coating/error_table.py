"""Measured error of the thin-coating model against the resolved FE model.

The map lives in ``error_table.json`` beside this module, written by ``python -m
benchmarks.coating_validity --table`` (do not edit it by hand): signed relative errors
(fast - FE) / FE of the force per settlement and the moment per tilt, flat punch,
uniform coating, base Poisson ratio 0.2, FE level 0 (its own error ~2e-4). Axes: sum h /
2a, E_c / E, nu_c, H / a; ``ERRORS[interface][part]`` is indexed in that order (nested
lists, 5 x 6 x 4 x 3).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

__all__ = ["BASE_RATIOS", "COATING_POISSON", "ERRORS", "MODULUS_RATIOS", "THICKNESS_RATIOS"]

_DATA: dict[str, Any] = json.loads(
    (Path(__file__).with_name("error_table.json")).read_text(encoding="utf-8"))

#: sum h / 2a [-] of the map's grid.
THICKNESS_RATIOS: tuple[float, ...] = tuple(_DATA["thickness_ratios"])
#: E_c / E [-].
MODULUS_RATIOS: tuple[float, ...] = tuple(_DATA["modulus_ratios"])
#: nu_c [-].
COATING_POISSON: tuple[float, ...] = tuple(_DATA["coating_poisson"])
#: H / a [-].
BASE_RATIOS: tuple[float, ...] = tuple(_DATA["base_ratios"])
#: ERRORS[interface]["force" | "moment"][thickness][modulus][poisson][base] [-].
ERRORS: dict[str, dict[str, list]] = _DATA["errors"]
