"""What a study's result files record besides their values: the package version, the
study's definition (which rebuilds the study), the base scene and its solver settings."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import core
from core.study import study_from_dict, sweep
from tests.conftest import scene_file


def small_study() -> dict:
    """Four points on an elastic base (a solve of a few ms each), every kind of field."""
    scene = scene_file("uniform_flat")
    scene["base"]["creep"] = {"model": "elastic", "modulus": 3.0e10}
    scene["solver"] = {"tol": 1e-5, "model_tol": 0.05}
    return {"study_version": 1, "name": "metadata", "scene": scene,
            "vary": [{"field": "coating[0].modulus", "logspace": {"start": 2e8, "stop": 8e8,
                                                                  "count": 2}},
                     {"field": "loading.force", "uniform": {"low": 2e5, "high": 6e5}}],
            "samples": 2, "seed": 7, "outputs": ["settlement", "q_max"],
            "times": [1.0, 10.0]}


@pytest.mark.parametrize("vary", [
    [{"field": "loading.force", "values": [1e5, 3e5, 2e5]}],
    [{"field": "loading.force", "linspace": {"start": 1e5, "stop": 7e5, "count": 7}},
     {"field": "coating[0].thickness", "logspace": {"start": 1e-3, "stop": 3e-2,
                                                    "count": 9}}],
    [{"field": "loading.moment", "normal": {"mean": 0.0, "std": 1e4}},
     {"field": "coating[0].modulus", "lognormal": {"median": 4e8, "sigma": 0.3}}],
])
def test_a_study_dict_rebuilds_the_study(vary: list) -> None:
    d = small_study() | {"vary": vary}
    if all("values" in v or "linspace" in v or "logspace" in v for v in vary):
        del d["samples"]
    study = study_from_dict(d)
    again = study_from_dict(study.to_dict())
    assert again == study and again.key == study.key
    assert json.loads(json.dumps(study.to_dict())) == study.to_dict()


def _check(attrs: dict, study_dict: dict) -> None:
    study = study_from_dict(study_dict)
    assert attrs["version"] == core.__version__
    assert attrs["format"] == "coated-punch study" and attrs["study_key"] == study.key
    assert study_from_dict(json.loads(attrs["study_definition"])).key == study.key
    assert json.loads(attrs["base_scene"]) == study.base
    assert json.loads(attrs["solver_settings"]) == {"tol": 1e-5, "model_tol": 0.05}


def test_study_files_record_version_study_scene_and_solver(tmp_path: Path) -> None:
    xr = pytest.importorskip("xarray")
    pd = pytest.importorskip("pandas")
    pq = pytest.importorskip("pyarrow.parquet")
    d = small_study()
    ds = sweep(d, client="serial", output=tmp_path / "r.parquet")
    _check(ds.attrs, d)
    sweep(d, client="serial", output=tmp_path / "r.nc", return_dataset=False)
    with xr.open_dataset(tmp_path / "r.nc", engine="scipy") as back:
        _check(back.attrs, d)
        assert back.attrs["points_failed"] == 0
    table = pd.read_parquet(tmp_path / "r.parquet")
    _check(table.attrs, d)
    assert table.attrs["points_failed"] == 0
    metadata = pq.read_schema(tmp_path / "r.parquet").metadata
    _check(json.loads(metadata[b"coated_punch"]), d)
