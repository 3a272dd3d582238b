"""Creep solves that reuse work: a load change of an aging scene, batched output times.

Times are never asserted; what is shown is that a load change does not step in time
again (the prepared object's build counts) and that the answers agree.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from core.cache import clear_caches
from core.scene import scene_from_dict

ROOT = Path(__file__).resolve().parents[1]


def _young_concrete(force: float) -> dict:
    data = json.loads((ROOT / "assets/scenes/young_concrete_50_years.json").read_text())
    # one year and 24 outputs keep the test short; the path is the one of 50 years
    data["times"] = {"end": 365.25, "count": 24, "spacing": "log"}
    data["loading"] = {"force": force, "moment": 0.0}
    return data


def test_a_load_change_of_an_aging_scene_does_not_step_in_time_again():
    clear_caches()
    first = scene_from_dict(_young_concrete(6.0e5)).dimensionless.solve()
    steps_built = first.info["builds"]["time_response"]
    # a force in N turned dimensionless: its shape differs from the first one's by
    # rounding only, so the cached response to that shape is scaled
    second = scene_from_dict(_young_concrete(6.0e5 * 1.37)).dimensionless.solve()
    assert second.info["builds"]["time_response"] == steps_built
    assert second.info["success"]
    # linear in the loads: measured ratio 1.37 to 2e-16 relative
    np.testing.assert_allclose(second.settlement, 1.37 * first.settlement, rtol=1e-12)
