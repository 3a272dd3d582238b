"""Studies of several punches (core/study with a base scene of ``punches``): the spacing
swept gives at each point what ``core.solve`` gives, the coupling fades with the gap,
the outputs are named per punch, and what a study of them cannot mean is refused."""

from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import core
from core.scene import SceneSolution, punches_from_dict
from core.study import study_from_dict, sweep
from core.study.definition import apply_point
from tests.cli_runs import run_cli
from tests.conftest import scene_file
from tests.support.punch_pairs import ELASTIC, wide_and_narrow

#: Centres of the narrow punch: gaps of 0.9, 3.9, 15.9 and 39.9 m to the wide one, about
#: 0.2, 1, 4 and 10 base thicknesses (H = 4 m).
CENTRES = [1.0, 4.0, 16.0, 40.0]


def _pair() -> dict[str, Any]:
    """A wide punch under a force and a moment at -1.5 m, a narrow one held level under a
    force to its right, on an elastic base."""
    return wide_and_narrow(ELASTIC, {"end": 10.0, "count": 2})


def _spacing_study(**extra: Any) -> dict[str, Any]:
    return {"study_version": 1, "name": "spacing", "scene": _pair(),
            "vary": [{"field": "punches[1].center", "values": CENTRES}]} | extra


@pytest.fixture(scope="module")
def spacing() -> Any:
    return sweep(_spacing_study(), client="serial")


def test_outputs_are_named_per_punch() -> None:
    study = study_from_dict(_spacing_study(outputs=["settlement", "punches[1].tilt"]))
    assert study.outputs == ("punches[0].settlement", "punches[1].settlement",
                             "punches[1].tilt")
    # the study file it writes reads back as the same study
    assert study_from_dict(study.to_dict()).key == study.key
    every = study_from_dict(_spacing_study()).outputs
    assert len(every) == 2 * 7 and every[:2] == ("punches[0].settlement", "punches[0].tilt")


def test_each_point_is_the_scene_solved_on_its_own(spacing: Any) -> None:
    base = study_from_dict(_spacing_study()).base
    for i, centre in enumerate(CENTRES):
        direct = core.solve(apply_point(base, {"punches[1].center": centre}))
        for k, punch in enumerate(direct.punches):
            for name in ("settlement", "tilt", "force", "moment", "contact_width"):
                np.testing.assert_array_equal(
                    spacing[f"punches_{k}_{name}"].values[i], getattr(punch, name))
            for name, pick in (("q_max", np.max), ("q_min", np.min)):
                np.testing.assert_array_equal(spacing[f"punches_{k}_{name}"].values[i],
                                              pick(punch.pressure_on_grid, axis=0))
        assert spacing.error_estimate.values[i] == direct.info["error_estimate"]
    assert spacing.punches_1_center.attrs == {"field": "punches[1].center", "kind": "values",
                                              "units": "m"}
    assert spacing.punches_1_tilt.attrs == {"units": "rad", "output": "punches[1].tilt",
                                            "long_name": "punches[1]: tilt of the punch"}
    assert not spacing.failed.values.any()


def test_the_coupling_fades_with_the_gap(spacing: Any) -> None:
    """The wide punch's settlement and tilt less its own alone (the same thin-layer model),
    at growing gaps. Through the layer on its frictionless base the coupling changes sign
    as it decays, so the gaps are chosen where its size falls at each step: measured
    8.7e-2, 5.8e-4, 1.1e-5, 9.1e-11 of the settlement alone, and 1.75e-6, 1.43e-7,
    1.3e-10, 5e-16 rad of tilt."""
    scene = punches_from_dict(_pair()).scenes[0]
    alone = SceneSolution(scene, scene.dimensionless, scene.dimensionless.solve())
    settlement = np.abs(spacing.punches_0_settlement.values[:, 0] - alone.settlement[0])
    settlement /= abs(alone.settlement[0])
    tilt = np.abs(spacing.punches_0_tilt.values[:, 0] - alone.tilt[0])
    assert np.all(np.diff(settlement) < 0) and np.all(np.diff(tilt) < 0)
    assert settlement[0] > 0.05  # 0.2 H apart: the neighbour adds 8.7 % to it
    # 10 H apart the punches no longer feel each other (exp(-2.1 * 10) ~ 8e-10 the decay
    # of the layer's kernel; 9.1e-11 and 5e-16 rad measured)
    assert settlement[-1] < 1e-9 and tilt[-1] < 1e-12


def test_a_punch_flag_is_the_study_flag() -> None:
    d = _pair()
    d["solver"] = {"contact": "full"}
    # e = 0.6 m on a punch of a = 1 m: its heel pulls (contact_lost on punches[0] only)
    d["punches"][0]["loading"]["moment"] = 3e5
    study = {"study_version": 1, "name": "flags", "scene": d, "outputs": ["q_min"],
             "vary": [{"field": "punches[1].half_width", "values": [0.5, 0.6]}]}
    ds = sweep(study, client="serial")
    assert list(ds.flags.values) == ["punches[0].contact_lost"] * 2
    assert ds.flag_contact_lost.values.all() and not ds.failed.values.any()
    assert np.all(ds.punches_0_q_min.values < 0) and np.all(ds.punches_1_q_min.values > 0)


@pytest.mark.parametrize(("change", "message"), [
    ({"outputs": ["punches[2].tilt"]},
     "outputs[0]: 'punches[2].tilt': the base scene has 2 punches (punches[0] to punches[1])"),
    ({"outputs": ["punches[0].tilted"]}, "outputs[0]: unknown output 'punches[0].tilted'"),
    ({"vary": [{"field": "punches[1].center", "values": [1.5, 0.0]}]},
     "vary[0].values: the scene is invalid at punches[1].center = 0 (punches: punches[0] "
     "and punches[1] overlap or touch"),
    ({"vary": [{"field": "punches[2].center", "values": [1.5]}]},
     "vary[0].field: punches[2].center: no such field in the scene (no item [2])"),
])
def test_what_a_study_of_punches_cannot_mean_is_refused(change: dict, message: str) -> None:
    with pytest.raises(ValueError) as info:
        study_from_dict(_spacing_study() | change)
    assert str(info.value).startswith(message)


def test_an_output_of_one_punch_of_several_needs_several() -> None:
    study = {"study_version": 1, "name": "one", "scene": scene_file("uniform_flat"),
             "outputs": ["punches[0].settlement"],
             "vary": [{"field": "loading.force", "values": [1e5, 2e5]}]}
    with pytest.raises(ValueError, match=r"^outputs\[0\]: 'punches\[0\].settlement' is an "
                                         "output of one punch of several"):
        study_from_dict(study)


def test_the_study_file_validates_against_its_schema(tmp_path: Path) -> None:
    path = tmp_path / "spacing.json"
    path.write_text(json.dumps(_spacing_study(outputs=["settlement", "punches[1].tilt"])))
    proc = run_cli("validate", path)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith("ok: study 'spacing': 4 points, 1 varied field")


@pytest.mark.slow
def test_the_command_line_sweeps_the_spacing(tmp_path: Path) -> None:
    import pandas as pd

    study = _spacing_study(outputs=["settlement", "tilt"])
    (tmp_path / "study.json").write_text(json.dumps(study))
    proc = run_cli("sweep", "study.json", "--output", "r.csv", "--quiet", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    rows = pd.read_csv(tmp_path / "r.csv", comment="#").sort_values(["point", "time_day"])
    assert [c for c in rows.columns if c.startswith("punches_")] == [
        "punches_1_center_m", "punches_0_settlement_m", "punches_0_tilt_rad",
        "punches_1_settlement_m", "punches_1_tilt_rad"]
    direct = core.solve(apply_point(copy.deepcopy(study_from_dict(study).base),
                                    {"punches[1].center": CENTRES[1]}))
    np.testing.assert_array_equal(rows[rows.point == 1]["punches_1_settlement_m"].to_numpy(),
                                  direct.punches[1].settlement)
