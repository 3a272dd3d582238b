"""The Study tab on a scene of several punches: the spacing (a punch's centre) and each
punch's half-width and loads are offered, every output is one punch's, the points equal
``core.solve`` of their scenes, and the chart, CSV and link name the punch."""

from __future__ import annotations

import copy

import numpy as np
import pytest

import core
from core.study.definition import apply_point
from explorer.files import study_csv
from explorer.model import (
    ExplorerState,
    default_range,
    plan_study,
    presets,
    study_choices,
    study_outputs,
)
from explorer.model.study import Axis
from explorer.model.view_link import study_settings
from explorer.plots.study import chart_title
from explorer.solving import StudyRun

KEY = "new_footing_beside_old"


def screen_scene() -> dict:
    """The preset of a new footing beside an old one, with three output times (before
    and after the new footing's load steps up at one year), as the page holds it."""
    scene = copy.deepcopy(presets()[KEY])
    scene["times"] = [30.0, 400.0, 3650.0]
    state = ExplorerState()
    state.load_scene(scene)
    return state.to_scene()


def test_the_fields_of_each_punch_and_its_outputs_are_offered() -> None:
    scene = screen_scene()
    choices = {c.key: c for c in study_choices(scene)}
    for k in (0, 1):
        assert choices[f"punches[{k}].center"].title == f"punch {k + 1}: centre x [m]"
        assert choices[f"punches[{k}].half_width"].unit == "m"
    # a constant load is a field; the new footing's force is a history (not offered)
    assert choices["punches[0].loading.force"].unit == "kN/m"
    assert "punches[1].loading.force" not in choices
    outputs = study_outputs(scene)
    assert list(outputs)[:2] == ["punches[0].settlement", "punches[0].tilt"]
    assert outputs["punches[1].tilt"] == ("punch 2: tilt", "mrad", 1e3)
    assert len(outputs) == 2 * 5
    # a scene of one punch keeps its outputs
    assert list(study_outputs(presets()["uniform_flat"]))[0] == "settlement"


@pytest.mark.parametrize("key", ["punches[0].center", "punches[1].center",
                                 "punches[0].half_width", "punches[1].half_width"])
def test_a_punchs_first_range_keeps_the_punches_apart(key: str) -> None:
    scene = screen_scene()
    choice = {c.key: c for c in study_choices(scene)}[key]
    axis = default_range(choice, scene)
    # the old footing (x = 0) and the new (x = 3), 1 m apart: a centre moves away from
    # the other punch, from half the gap to four times it
    if key == "punches[1].center":
        assert (axis.start, axis.stop) == (2.5, 6.0)
    if key == "punches[0].center":
        assert (axis.start, axis.stop) == (-3.0, 0.5)
    plan_study(scene, [axis])  # valid at both ends: plan_study checks them


def test_a_spacing_study_equals_the_solves_of_its_scenes() -> None:
    scene = screen_scene()
    planned = plan_study(scene, [Axis("punches[1].center", 2.5, 5.0, 3)])
    runner = StudyRun()
    runner.start(planned)
    assert runner.wait(300), "the study did not end"
    assert runner.status == "done", runner.message
    result = runner.result
    assert not result.failed.any()
    for i, center in enumerate((2.5, 3.75, 5.0)):
        want = core.solve(apply_point(scene, {"punches[1].center": center}))
        for k, punch in enumerate(want.punches):
            for name in ("settlement", "tilt"):
                got = result.outputs[f"punches[{k}].{name}"][i]
                expected = np.asarray(getattr(punch, name))
                # the same solver on the same scene (bitwise in practice); 1e-12 of the
                # scale leaves room for caches prepared in another order
                # (the tilt's scale is the settlement over the half-width, 1 m)
                scale = float(np.max(np.abs(want.punches[k].settlement)))
                np.testing.assert_allclose(got / scale, expected / scale, rtol=0,
                                           atol=1e-12, err_msg=f"punch {k} {name}")
            # both in full contact: each punch's contact width is its own width
            np.testing.assert_allclose(result.outputs[f"punches[{k}].contact_width"][i],
                                       2.0, rtol=1e-12)
    # the old footing settles less, and tilts less toward the new one, the further it is
    old_tilt = result.outputs["punches[0].tilt"][:, -1]
    assert old_tilt[0] > old_tilt[1] > old_tilt[2] > 0
    # what the page shows and hands out names the punch
    assert chart_title(result, "punches[0].tilt", 2).startswith("punch 1: tilt [mrad] at t")
    header = [line for line in study_csv(result).splitlines()
              if not line.startswith("#")][0].split(",")
    assert header[:2] == ["punch_2_centre_x_m", "time_day"]
    assert "punch_1_settlement_mm" in header and "punch_2_contact_width_m" in header
    assert len(header) == 2 + 10 + 3
    assert header[-3:] == ["error_estimate", "flags", "error"]


def test_a_link_keeps_a_punchs_output_and_refuses_others() -> None:
    settings = {"axes": [["punches[1].center", 2.5, 5.0, 9, "linear"]],
                "output": "punches[1].tilt"}
    assert study_settings(settings)["output"] == "punches[1].tilt"
    for bad in ("punches[9].tilt", "punches[0].bogus", "punch.tilt"):
        with pytest.raises(ValueError, match="study output"):
            study_settings(settings | {"output": bad})
