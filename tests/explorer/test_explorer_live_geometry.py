"""Geometry sliders apply every drag step while the last solve was fast in CPU time (the
wall time of a loaded machine does not decide); no browser."""

from __future__ import annotations

import json
from dataclasses import replace

import pytest

from explorer.model import presets

KEY = "rounded_graded"


def test_the_scene_solve_counts_its_validation_in_its_cpu_time() -> None:
    from core.scene import solve

    info = solve(json.loads(json.dumps(presets()[KEY]))).info
    assert isinstance(info["cpu_seconds"], float) and info["cpu_seconds"] > 0.0


@pytest.mark.parametrize(("cpu", "wall", "live"),
                         [(0.020, 0.200, True), (0.150, 0.020, False), (None, 0.020, True),
                          (None, 0.200, False)])
def test_geometry_sliders_are_live_when_the_solve_is_fast_in_cpu_time(cpu, wall, live,
                                                                       explorer_app):
    from explorer.app import LIVE_SOLVE_S

    app = explorer_app(KEY, solved=True)
    view = app.controller.view
    info = {k: v for k, v in view.info.items() if k != "cpu_seconds"}
    if cpu is not None:
        info["cpu_seconds"] = cpu
    info["seconds"] = wall
    app.controller.view = replace(view, info=info)
    assert ((cpu if cpu is not None else wall) < LIVE_SOLVE_S) == live
    assert app.fast_solves() == live
    # a drag step of the base thickness (no release): applied only when live
    before = app.state.base.thickness
    app.base_tab.base_thickness.value = 2.5
    assert app.controller.wait(120)
    assert app.state.base.thickness == pytest.approx(2.5 if live else before)
