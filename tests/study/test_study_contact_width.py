"""A study's ``contact_width`` is the length of each point's contact set, as
``SceneSolution.contact_width`` gives it (:func:`core.scene.contact_width`), through the
Python API and the command line: the lift-off preset at M = 480 kN m/m touches on
[-0.3486, 1] m at 1000 days, 1.3486 m of its 2 m, not the 2 m where q >= 0 (q = 0 on the
lifted heel). A full-contact answer keeps the whole width, flagged or not."""

from __future__ import annotations

import json
from pathlib import Path
from subprocess import CompletedProcess

import numpy as np
import pytest

from core.scene import solve
from core.study import study_from_dict
from core.study.definition import apply_point
from tests.cli_runs import run_cli
from tests.conftest import scene_file

#: The preset's moment, and none (full contact) [N m/m].
MOMENTS = [4.8e5, 0.0]
#: The lift-off preset's contact width at 1000 days [m], to the 5e-5 m of its digits.
LAST_WIDTH = 1.3486


def liftoff_study(contact: str | None = None) -> dict:
    scene = scene_file("eccentric_footing_liftoff")
    if contact is not None:
        scene["solver"]["contact"] = contact
    return {"study_version": 1, "name": "contact width", "scene": scene,
            "vary": [{"field": "loading.moment", "values": MOMENTS}],
            "outputs": ["q_min", "contact_width"]}


def solved(study: dict) -> list:
    return [solve(apply_point(study["scene"], {"loading.moment": m})) for m in MOMENTS]


def test_a_study_records_the_width_of_the_contact_set() -> None:
    import xarray  # noqa: F401  (installed by the test set-up)

    from core.study import sweep

    study = liftoff_study()
    ds = sweep(study_from_dict(study), client="serial")
    for i, result in enumerate(solved(study)):
        # the same solver on the same scene: measured bitwise equal
        np.testing.assert_array_equal(ds.contact_width.values[i], result.contact_width)
    lifted, full = ds.contact_width.values
    assert lifted[-1] == pytest.approx(LAST_WIDTH, abs=5e-5)
    assert ds.q_min.values[0, -1] == 0.0  # the lifted heel carries q = 0 ...
    assert np.all(lifted < 2.0)            # ... and is not in contact
    np.testing.assert_array_equal(full, 2.0)


def test_a_full_contact_study_keeps_the_whole_width_where_it_pulls() -> None:
    import xarray  # noqa: F401  (installed by the test set-up)

    from core.study import sweep

    ds = sweep(study_from_dict(liftoff_study("full")), client="serial")
    assert ds.flag_contact_lost.values.tolist() == [True, False]
    assert np.all(ds.q_min.values[0] < 0)
    np.testing.assert_array_equal(ds.contact_width.values, 2.0)


def test_the_command_line_sweep_writes_the_width_of_the_contact_set(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """``python -m core sweep`` in this process, its Dask cluster replaced by the serial
    runner (the cluster itself: tests/study/test_sweep.py)."""
    import pandas as pd


    study = liftoff_study()
    _serial_cli_sweep(study, tmp_path, monkeypatch)
    rows = pd.read_csv(tmp_path / "r.csv", comment="#").sort_values(["point", "time_day"])
    widths = rows["contact_width_m"].to_numpy().reshape(len(MOMENTS), -1)
    for i, result in enumerate(solved(study)):
        np.testing.assert_array_equal(widths[i], result.contact_width)
    assert widths[0, -1] == pytest.approx(LAST_WIDTH, abs=5e-5)


def test_a_study_of_a_scene_with_limits_says_they_are_not_checked(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A study whose base scene has design limits wrote no verdict and said nothing of
    them (exit code 0), where ``solve --strict`` of its worst point fails: the dataset
    and the command line now say the limits are not checked point by point. Its outputs
    have a ``long_name`` too (only time, flags and the estimate had one)."""
    from core.study import LIMITS_NOT_CHECKED, study_from_dict, sweep

    study = liftoff_study()
    study["scene"]["limits"] = {"allowable_pressure": 1.5e6, "settlement_limit": 1.2e-4}
    ds = sweep(study_from_dict(study), client="serial")
    assert ds.attrs["design_limits"] == LIMITS_NOT_CHECKED
    assert ds.q_min.attrs["long_name"].startswith("smallest contact pressure")
    assert ds.contact_width.attrs["long_name"] == "length of the contact set"
    plain = sweep(study_from_dict(liftoff_study()), client="serial")
    assert "design_limits" not in plain.attrs
    done = _serial_cli_sweep(study, tmp_path, monkeypatch)
    assert f"warning: sweep: {LIMITS_NOT_CHECKED}" in done.stderr


def _serial_cli_sweep(study: dict, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
                      ) -> CompletedProcess:
    """``sweep study.json --output r.csv`` in ``tmp_path``, in this process, its Dask
    cluster replaced by the serial runner; returns the finished run (exit code 0)."""
    import core.study

    (tmp_path / "study.json").write_text(json.dumps(study))
    run_sweep = core.study.sweep
    monkeypatch.setattr(core.study, "sweep",
                        lambda *args, **kwargs: run_sweep(*args, client="serial", **kwargs))
    done = run_cli("sweep", "study.json", "--output", "r.csv", "--quiet", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    return done
