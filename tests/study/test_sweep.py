"""Design studies: validation names the field, a real Dask cluster on loopback gives what a
serial loop gives, failed points are recorded, an interrupted study resumes."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import core
from core.contact import ZONE_END_TOL
from core.scene import solve
from core.study import load_study, numeric_fields, study_from_dict
from core.study.definition import MAX_STUDY_POINTS, apply_point, parse_path
from core.study.points import point_table
from tests.cli_runs import run_cli
from tests.conftest import scene_file

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "core" / "presets" / "scenes"
OUTPUTS = ("settlement", "tilt", "force", "moment", "q_max", "q_min", "contact_width")


def elastic_scene() -> dict:
    scene = scene_file("uniform_flat")
    scene["base"]["creep"] = {"model": "elastic", "modulus": 3.0e10}
    return scene


def small_study(**extra) -> dict:
    """Loads on a 3 x 2 grid and two coating moduli: 12 points, 2 geometries."""
    study = {"study_version": 1, "name": "small", "scene": elastic_scene(),
             "vary": [{"field": "coating[0].modulus", "values": [8e8, 4e8]},
                      {"field": "loading.force", "linspace": {"start": 2e5, "stop": 6e5,
                                                              "count": 3}},
                      {"field": "loading.moment", "values": [0.0, 1e5]}],
             "times": [1.0, 365.0]}
    study.update(extra)
    return study


def serial_loop(study) -> dict[str, np.ndarray]:
    """The reference: every point solved with core.solve, one after another."""
    table = point_table(study)
    paths = [p.path for p in study.parameters]
    out = {name: np.full((study.n_points, len(study.times)), np.nan) for name in OUTPUTS}
    for i in range(study.n_points):
        result = solve(apply_point(study.base, {p: table[p][i] for p in paths}))
        q = result.pressure_on_grid
        out["settlement"][i] = result.settlement
        out["tilt"][i] = result.tilt
        out["force"][i] = result.force
        out["moment"][i] = result.moment
        out["q_max"][i] = q.max(axis=0)
        out["q_min"][i] = q.min(axis=0)
        out["contact_width"][i] = result.contact_width
    return out


def assert_equal_to_serial(ds, study) -> None:
    reference = serial_loop(study)
    assert not ds.failed.any()
    for name in OUTPUTS:
        got = ds[name].values
        want = reference[name]
        # the same solver with the same inputs: measured bitwise equal (difference 0.0);
        # 1e-12 leaves room for a cache prepared by another point on another worker
        scale = np.max(np.abs(want), axis=0, keepdims=True)
        np.testing.assert_allclose(got / np.where(scale > 0, scale, 1.0),
                                   want / np.where(scale > 0, scale, 1.0), rtol=0, atol=1e-12)


def each_load_point_against_solve(study, grid, got, same_as_the_point) -> dict[str, int]:
    """Check a batch's answers ``got`` over the (force, moment) ``grid`` point by point
    against ``core.solve``: a refused point recorded with its message and no values, a
    solved one by ``same_as_the_point(i, result)`` and its flags. Returns the count of
    each kind (failed, unilateral, full)."""
    kinds = {"failed": 0, "unilateral": 0, "full": 0}
    for i, (force, moment) in enumerate(grid):
        try:
            result = solve(apply_point(study.base, {"loading.force": force,
                                                    "loading.moment": moment}))
        except ValueError as exc:
            kinds["failed"] += 1
            assert got["flags"][i] == "failed"
            assert got["error"][i] == " ".join(str(exc).split())[:500]
            assert np.all(np.isnan(got["values"][i]))
            continue
        kinds[result.info["contact"]] += 1
        same_as_the_point(i, result)
        assert got["flags"][i] == ",".join(result.flags) and got["error"][i] == ""
    return kinds


# ------------------------------------------------------------------------- validation


@pytest.mark.parametrize(("change", "starts"), [
    ({"vary": [{"field": "coating[2].modulus", "values": [1e8]}]}, "vary[0].field: coating[2]"),
    ({"vary": [{"field": "loading.forse", "values": [1e5]}]}, "vary[0].field: loading.forse"),
    ({"vary": [{"field": "coating[0]modulus", "values": [1e8]}]}, "vary[0].field:"),
    ({"vary": [{"field": "base.creep", "values": [1]}]}, "vary[0].field: 'base.creep' holds"),
    ({"vary": [{"field": "times.end", "values": [1]}]}, "vary[0].field: 'times.end' cannot"),
    ({"vary": [{"field": "coating[0].modulus", "values": [1e8, -1e8]}]},
     "vary[0].values: the scene is invalid at coating[0].modulus = -1e+08 "
     "(coating[0].modulus: must be >= 10000"),
    ({"vary": [{"field": "base.poisson", "uniform": {"low": 0.1, "high": 0.5}}],
      "samples": 4}, "vary[0].uniform.high: the scene is invalid"),
    ({"vary": [{"field": "base.poisson", "uniform": {"low": 0.3, "high": 0.1}}],
      "samples": 4}, "vary[0].uniform.high: must be greater than low"),
    ({"vary": [{"field": "loading.force", "logspace": {"start": 0, "stop": 1e5,
                                                       "count": 3}}]},
     "vary[0].logspace.start: must be > 0"),
    ({"vary": [{"field": "loading.force", "linspace": {"start": 1, "stop": 2,
                                                       "count": 2.5}}]},
     "vary[0].linspace.count: must be an integer"),
    ({"vary": [{"field": "loading.force", "linspace": {"start": 1, "stop": 1,
                                                       "count": 3}}]},
     "vary[0].linspace.stop: equals start"),
    ({"vary": [{"field": "loading.force", "normal": {"mean": 1e5, "std": -1}}],
      "samples": 3}, "vary[0].normal.std: must be > 0"),
    ({"vary": [{"field": "loading.force", "normal": {"mean": 1e5, "std": 1e4}}]},
     "samples: required"),
    ({"vary": [{"field": "loading.force", "values": [1e5, 2e5],
                "linspace": {"start": 1, "stop": 2, "count": 2}}]},
     "vary[0]: give exactly one"),
    ({"vary": [{"field": "loading.force", "values": [1e5]},
               {"field": "loading.force", "values": [2e5]}]},
     "vary[1].field: 'loading.force' is already varied by vary[0]"),
    ({"vary": [{"field": "loading.force", "linspace": {"start": 1, "stop": 2, "count": 1001}},
               {"field": "loading.moment", "linspace": {"start": 0, "stop": 1,
                                                        "count": 1000}}]},
     f"vary: the study has 1,001,000 points (grid sizes times samples), more than the "
     f"limit of {MAX_STUDY_POINTS:,}"),
    ({"outputs": ["settlement", "qmax"]}, "outputs[1]: unknown output"),
    ({"times": [5.0, 1.0]}, "times[1]"),
    ({"study_version": 2}, "study_version: must be an integer from 1 to 1"),
    ({"vary": []}, "vary: must be a list of 1 to"),
    ({"extra": 1}, "study: unknown field 'extra'"),
])
def test_bad_study_names_the_field(change, starts):
    with pytest.raises(ValueError) as info:
        study_from_dict(small_study(**change))
    assert str(info.value).startswith(starts), str(info.value)


def test_bad_base_scene_and_paths(tmp_path: Path):
    bad = elastic_scene()
    bad["base"]["poisson"] = 0.7
    with pytest.raises(ValueError, match=r"^scene: base\.poisson: must be in"):
        study_from_dict(small_study(scene=bad))
    with pytest.raises(ValueError, match=r"^scene: cannot read 'missing\.json'"):
        study_from_dict(small_study(scene="missing.json"), base_dir=tmp_path)
    assert parse_path("coating[0].modulus") == ("coating", 0, "modulus")
    with pytest.raises(ValueError, match=r"^field: "):
        parse_path("coating[-1].modulus")


def test_points_are_a_pure_function_of_the_study(tmp_path: Path):
    (tmp_path / "scene.json").write_text(json.dumps(elastic_scene()))
    spec = small_study(scene="scene.json")
    spec["vary"].append({"field": "base.thickness", "lognormal": {"median": 4.0,
                                                                  "sigma": 0.1}})
    spec["samples"] = 5
    (tmp_path / "study.json").write_text(json.dumps(spec))
    study = load_study(tmp_path / "study.json")
    assert study.n_points == 2 * 3 * 2 * 5
    table, again = point_table(study), point_table(load_study(tmp_path / "study.json"))
    for path in table:
        np.testing.assert_array_equal(table[path], again[path])
    # the grid in study order (the last axis fastest), the samples innermost and shared
    assert list(table["coating[0].modulus"][:60:30]) == [8e8, 4e8]
    assert list(table["loading.moment"][:10:5]) == [0.0, 1e5]
    draws = table["base.thickness"].reshape(12, 5)
    assert np.all(draws == draws[0]) and np.all(draws > 0)
    base = study.base
    before = json.dumps(base)
    point = apply_point(base, {"coating[0].modulus": 1.0, "loading.force": 2.0})
    assert point["coating"][0]["modulus"] == 1.0 and point["loading"]["force"] == 2.0
    assert json.dumps(base) == before


def test_fields_a_study_can_vary_and_a_smaller_limit():
    fields = dict(numeric_fields(study_from_dict(small_study()).base))
    assert fields["coating[0].modulus"] == 8e8 and fields["loading.moment"] == 0.0
    assert fields["base.creep.modulus"] == 3e10
    assert not any(path.startswith(("times", "schema_version")) for path in fields)
    for path in fields:  # each one is accepted by a study
        study_from_dict(small_study(vary=[{"field": path, "values": [fields[path]]}]))
    with pytest.raises(ValueError, match=r"^vary: the study has 12 points .* limit of 10$"):
        study_from_dict(small_study(), max_points=10)


# ------------------------------------------------------------------------- execution


def test_serial_run_equals_the_loop_and_batches_follow_geometry():
    from core.study import sweep
    from core.study.plan import BatchPlan

    study = study_from_dict(small_study())
    ds = sweep(study, client="serial", batch_points=4)
    assert_equal_to_serial(ds, study)
    assert ds.settlement.attrs["units"] == "m" and ds.q_max.attrs["units"] == "Pa"
    assert ds.coating_0_modulus.attrs["field"] == "coating[0].modulus"
    assert ds.attrs["batches"] == 3 and ds.attrs["points_failed"] == 0
    # a geometry's points are neighbours; inside it, force and moment both varying, the
    # loads in order of eccentricity M / P, then force, then moment
    table = point_table(study)
    plan = BatchPlan(study, 4)
    order = np.concatenate([plan.batch(k) for k in range(plan.n_batches)])
    moduli = table["coating[0].modulus"][order]
    assert np.count_nonzero(np.diff(moduli)) == 1
    force, moment = table["loading.force"][order][:6], table["loading.moment"][order][:6]
    keys = list(zip(moment / force, force, moment, strict=True))
    assert keys == sorted(keys)


#: Batched against one-point answers, relative to the size of each kind of output
#: (kinematics max(|delta|, a |alpha|), statics max(|P|, |M| / a), pressures max |q|,
#: widths a): the batch's matrix products round differently. Measured at most 2.0e-15
#: (q_min) over the 8,224 full-contact points of benchmarks.sweep.loads_study(100).
BATCH_ROUNDING = 1e-13
#: The error estimate extrapolates differences of answers near round-off (~1e-13), whose
#: rounding differs the same way: measured at most 4.7e-7 relative on those points.
BATCH_ESTIMATE_ROUNDING = 1e-5


def assert_batched_equal(values, estimate, result, outputs):
    """A batched point's outputs and estimate equal one point's solve to rounding."""
    want = sweeps_point_outputs(result, outputs)
    a = result.scene.half_width
    rows = dict(zip(outputs, want, strict=True))
    kin = max(np.max(np.abs(rows["settlement"])), a * np.max(np.abs(rows["tilt"])))
    stat = max(np.max(np.abs(rows["force"])), np.max(np.abs(rows["moment"])) / a)
    q = max(np.max(np.abs(rows["q_max"])), np.max(np.abs(rows["q_min"])))
    scale = {"settlement": kin, "tilt": kin / a, "force": stat, "moment": stat * a,
             "q_max": q, "q_min": q, "contact_width": a}
    for j, name in enumerate(outputs):
        np.testing.assert_allclose(values[j], want[j], rtol=0,
                                   atol=BATCH_ROUNDING * scale[name], err_msg=name)
    np.testing.assert_allclose(estimate, result.info["error_estimate"],
                               rtol=BATCH_ESTIMATE_ROUNDING)


def sweeps_point_outputs(result, outputs):
    from core.study.outputs import point_outputs

    return point_outputs(result, outputs)


@pytest.mark.parametrize("contact", ["auto", "full"])
def test_load_batch_equals_core_solve_on_a_loads_grid(contact):
    """core.study.loads answers the full-contact points of a force x moment grid at once,
    equal to core.solve point by point; it leaves lift-off (``auto``) and refused points
    alone; with ``full`` contact it answers the points that lose contact, flagged."""
    from core.scene import scene_from_dict
    from core.study.loads import load_batch_applies, solve_load_batch

    base = elastic_scene() | {"times": [1.0, 365.0]}
    base["solver"] = dict(base.get("solver", {}), contact=contact)
    scene = scene_from_dict(base)
    assert load_batch_applies(scene)
    force, moment = (v.ravel() for v in np.meshgrid(np.linspace(1e5, 1e6, 7),
                                                     np.linspace(0.0, 3e5, 6)))
    outputs = list(OUTPUTS)
    got = solve_load_batch(scene, {"force": force, "moment": moment}, outputs)
    kinds = {"failed": 0, "unilateral": 0, "full": 0}
    lost = 0
    for i in range(force.size):
        try:
            result = solve(apply_point(base, {"loading.force": force[i],
                                              "loading.moment": moment[i]}))
        except ValueError:
            kinds["failed"] += 1
            assert not got.answered[i]
            continue
        kinds[result.info["contact"]] += 1
        if result.info["contact"] == "unilateral":
            assert not got.answered[i]
            continue
        assert got.answered[i]
        assert_batched_equal(got.values[i], got.error_estimate[i], result, outputs)
        assert got.flags[i] == ",".join(result.flags)
        lost += "contact_lost" in result.flags
    assert kinds["failed"] >= 1 and kinds["full"] >= 20
    assert kinds["unilateral"] >= 1 if contact == "auto" else lost >= 1


def test_load_batch_flags_large_settlements_as_core_solve():
    from core.scene import scene_from_dict
    from core.study.loads import solve_load_batch

    base = elastic_scene() | {"times": [1.0]}
    scene = scene_from_dict(base)
    force = np.array([1e6, 1e8, 3e8, 1e9])
    got = solve_load_batch(scene, {"force": force, "moment": 0.1 * force}, list(OUTPUTS))
    flags = [",".join(solve(apply_point(base, {"loading.force": f, "loading.moment": 0.1 * f}))
                      .flags) for f in force]
    assert got.answered.all() and list(got.flags) == flags
    assert flags[0] == "" and flags[-1] == "large_settlement"


def test_load_only_batch_equals_core_solve_point_for_point(monkeypatch):
    """A batch varying only loads validates the base scene once and replaces the loads of
    each point: every output, estimate, flag and message equals core.solve's on the
    point's whole scene dict, lift-off and refused points included."""
    import core.study.batch as batch
    import core.study.batch as sweeps

    # (the study gives the base scene and the times; the batch's points, a pulled punch
    # among them, which a study's grid ends may not hold, are given to run_batch)
    study = study_from_dict(small_study(vary=[
        {"field": "loading.force", "values": [1e5, 5e5]},
        {"field": "loading.moment", "values": [0.0, 4e4, 8e4, 2e5]}]))
    paths = ["loading.force", "loading.moment"]
    grid = np.array([(f, m) for f in (-1e5, 1e5, 5e5) for m in (0.0, 4e4, 8e4, 2e5)])
    outputs = list(OUTPUTS)

    def whole_scene(*args):
        raise AssertionError("a load-only batch must not rebuild each point's scene dict")

    monkeypatch.setattr(batch, "apply_point", whole_scene)
    got = sweeps.run_batch(study.base, paths, grid, outputs, len(study.times))
    monkeypatch.undo()
    def same_as_the_point(i, result):
        if result.info["contact"] == "unilateral":
            # the same solver on equal scenes: measured bitwise equal
            np.testing.assert_array_equal(got["values"][i],
                                          sweeps_point_outputs(result, outputs))
            assert got["error_estimate"][i] == result.info["error_estimate"]
        else:  # full contact: the whole batch at once (core.study.loads)
            assert_batched_equal(got["values"][i], got["error_estimate"][i], result,
                                 outputs)

    kinds = each_load_point_against_solve(study, grid, got, same_as_the_point)
    # pulled (P < 0) and beyond the edge (e = 2 m > a) refused; lift-off at e = 0.8 m
    assert kinds["failed"] == 5 and kinds["unilateral"] >= 1 and kinds["full"] >= 4


def test_replace_loads_equals_the_validated_dict():
    from core.scene import replace_loads, scene_from_dict

    study = study_from_dict(small_study())
    base = scene_from_dict(study.base)
    new = replace_loads(base, {"moment": 3e4})
    assert new.key == scene_from_dict(apply_point(study.base, {"loading.moment": 3e4})).key
    assert base.loading["moment"](0.0) != new.loading["moment"](0.0)  # base unchanged
    # the geometric figures it keeps from the base scene are those of a fresh solve
    whole = solve(apply_point(study.base, {"loading.moment": 3e4}))
    base.sample_extremes  # noqa: B018 - computed on the base, then kept by the copy
    assert solve(replace_loads(base, {"moment": 3e4})).info["dimensional"] \
        == whole.info["dimensional"]
    with pytest.raises(ValueError, match=r"^loading\.tilt: not one of the scene's given"):
        replace_loads(base, {"tilt": 1e-3})
    with pytest.raises(ValueError, match=r"^loading\.force: must be a finite number"):
        replace_loads(base, {"force": float("nan")})


def test_failed_point_is_recorded_and_the_study_goes_on():
    from core.study import sweep

    spec = small_study(vary=[{"field": "base.poisson", "normal": {"mean": 0.3, "std": 0.15}}],
                       samples=12, seed=3)
    study = study_from_dict(spec)
    draws = point_table(study)["base.poisson"]
    bad = draws >= 0.5
    assert 0 < bad.sum() < len(draws)  # seed 3 draws both kinds
    ds = sweep(study, client="serial")
    np.testing.assert_array_equal(ds.failed.values, bad)
    for message in ds.error.values[bad]:
        assert message.startswith("base.poisson: must be in (-1, 0.5)")
    assert np.all(np.isnan(ds.settlement.values[bad]))
    assert np.all(np.isfinite(ds.settlement.values[~bad]))
    assert ds.attrs["points_failed"] == bad.sum()


def test_interrupted_study_resumes_without_recomputing(tmp_path: Path):
    from core.study import sweep
    from core.study.run import StudyInterrupted

    study = study_from_dict(small_study())
    work = tmp_path / "parts"
    calls = []

    def stop_after_two_batches(done: int, total: int) -> bool:
        calls.append(done)
        return len(calls) < 2

    with pytest.raises(StudyInterrupted):
        sweep(study, client="serial", work_dir=work, batch_points=4,
              progress=stop_after_two_batches)
    written = {p.name: p.stat().st_mtime_ns for p in (work / "parts").glob("*.npz")}
    assert len(written) == 2
    ds = sweep(study, client="serial", work_dir=work, batch_points=4)
    assert ds.attrs["batches_reused"] == 2 and ds.attrs["batches_computed"] == 1
    for name, mtime in written.items():
        assert (work / "parts" / name).stat().st_mtime_ns == mtime
    assert not list((work / "parts").glob(".*"))  # no temporary file left behind
    assert_equal_to_serial(ds, study)
    other = study_from_dict(small_study(times=[365.0]))
    with pytest.raises(ValueError, match=r"^work_dir: .* holds the parts of another study"):
        sweep(other, client="serial", work_dir=work)
    # parts cut in another order (lexicographic loads, before the eccentricity plan)
    manifest = work / "manifest.json"
    manifest.write_text(json.dumps({**json.loads(manifest.read_text()), "plan":
                                    "lexicographic"}))
    with pytest.raises(ValueError, match=r"^work_dir: .* planned in another order"):
        sweep(study, client="serial", work_dir=work)


@pytest.fixture(scope="module")
def loopback_cluster(tmp_path_factory):
    """A ``dask scheduler`` and two single-threaded ``dask worker`` processes on 127.0.0.1,
    started as separate programs, as a user would start a cluster (without nannies: they
    only slow the shutdown here)."""
    import distributed  # noqa: F401  (installed by the test set-up)
    where = tmp_path_factory.mktemp("cluster")
    scheduler_file = where / "scheduler.json"
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1",
               PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    common = ["--scheduler-file", str(scheduler_file)]
    procs = [subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler",
                               "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                               *common], cwd=where, env=env, stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL)]
    address = None
    try:
        deadline = time.monotonic() + 60
        while not scheduler_file.exists() and time.monotonic() < deadline:
            time.sleep(0.1)
        assert scheduler_file.exists(), "the scheduler did not start in 60 s"
        address = json.loads(scheduler_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        procs.extend(subprocess.Popen(
            [sys.executable, "-m", "distributed.cli.dask_worker", "--no-nanny",
             "--nthreads", "1", "--host", "127.0.0.1", "--no-dashboard", *common],
            cwd=where, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            for _ in range(2))
        from distributed import Client

        with Client(address, timeout=60) as client:
            client.wait_for_workers(2, timeout=60)
        yield address
    finally:
        # the workers hold nothing worth an orderly exit (a graceful one waited up to 20 s
        # here for a scheduler going down at the same time)
        for proc in procs[1:]:
            proc.kill()
        procs[0].terminate()
        for proc in procs:
            try:
                proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait(timeout=20)


@pytest.mark.slow
def test_study_on_a_separately_started_cluster_equals_a_serial_loop(loopback_cluster):
    from distributed import Client

    from core.study import sweep

    study = study_from_dict(small_study())
    with Client(loopback_cluster, timeout=60) as client:
        ds = sweep(study, client=client, batch_points=3)
        assert len({w for w in client.scheduler_info()["workers"]}) == 2
    assert ds.attrs["batches"] == 4 and ds.attrs["batches_lost"] == 0
    assert_equal_to_serial(ds, study)


@pytest.mark.slow
def test_cli_sweep_on_the_cluster_writes_each_format(loopback_cluster, tmp_path: Path):
    import pandas as pd
    import xarray as xr

    from core.study import sweep

    (tmp_path / "study.json").write_text(json.dumps(small_study()))
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    proc = subprocess.run([sys.executable, "-m", "core", "sweep", "study.json", "--output",
                           "r.csv", "--scheduler", loopback_cluster], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith("12 points in "), proc.stdout
    assert not (tmp_path / "r.csv.parts").exists()  # its own work directory, removed
    for name in ("r.nc", "r.parquet"):
        sweep(tmp_path / "study.json", scheduler=loopback_cluster, output=tmp_path / name,
              return_dataset=False)
    ds = xr.open_dataset(tmp_path / "r.nc", engine="scipy")
    assert ds.settlement.attrs["units"] == "m"
    head = [line for line in (tmp_path / "r.csv").read_text().splitlines()
            if line.startswith("# ")]
    assert f"# version: {core.__version__}" in head
    assert any(line.startswith("# base_scene: {") for line in head)
    assert any(line.startswith("# study_definition: {") for line in head)
    rows = pd.read_csv(tmp_path / "r.csv", comment="#").sort_values(["point", "time_day"])
    assert len(rows) == 12 * 2
    np.testing.assert_array_equal(rows["settlement_m"].to_numpy(),
                                  ds.settlement.values.reshape(-1))
    table = pd.read_parquet(tmp_path / "r.parquet").sort_values(["point", "time_day"])
    np.testing.assert_array_equal(table["q_max_Pa"].to_numpy(), ds.q_max.values.reshape(-1))
    ds.close()
    bad = run_cli("sweep", "study.json", "--output", "r.txt", cwd=tmp_path)
    assert bad.returncode == 2
    assert bad.stderr.strip() == ("error: output: unsupported extension '.txt' (use .nc, "
                                  ".csv or .parquet)")


def test_workers_are_warmed_by_a_plugin_and_the_warming_batches_solve(loopback_cluster):
    from distributed import Client

    from core.study.batch import run_batch
    from core.study.warm import WARM_LOADS, WARM_SCENE, warm_worker, warm_workers

    # the warming batch goes through the load paths: full contact, lift-off and scaled
    got = run_batch(WARM_SCENE, ["loading.force", "loading.moment"], WARM_LOADS,
                    ("settlement", "q_min"), 1)
    assert not np.any(got["flags"] == "failed")
    q_min = got["values"][:, 1, 0]
    assert np.all(q_min[:3] > 0) and np.all(q_min[3:] == 0)  # full contact, then lift-off
    np.testing.assert_allclose(got["values"][4], 2 * got["values"][3], rtol=1e-12)
    assert warm_worker() > 0
    with Client(loopback_cluster, timeout=60) as client:
        warm_workers(client)
        cpu = client.run(lambda dask_worker: dask_worker.coated_punch_warm_cpu)
    assert len(cpu) == 2 and all(t > 0 for t in cpu.values())


def test_a_failed_warming_leaves_the_worker_running(monkeypatch):
    import distributed  # noqa: F401  (installed by the test set-up)

    import core.study.warm as warm

    def broken() -> float:
        raise RuntimeError("no tables today")

    monkeypatch.setattr(warm, "warm_worker", broken)
    worker = type("Worker", (), {})()
    warm.WarmStudyWorker().setup(worker)
    assert worker.coated_punch_warm_error == "RuntimeError: no tables today"


def test_solving_does_not_import_dask():
    code = ("import sys, core, core.cli; core.cli.main(['solve', "
            f"{str(SCENES / 'uniform_flat.json')!r}]); core.solve; core.load_study; "
            "print(sorted(m for m in sys.modules if m.split('.')[0] in "
            "('dask', 'distributed', 'xarray')))")
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True,
                         text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().splitlines()[-1] == "[]"


def test_batch_groups_points_sharing_a_geometry(monkeypatch):
    """Points that differ only in their loads share one validated scene and one load batch
    per geometry; every answer equals core.solve on the point's whole scene dict, and a
    geometry that does not validate leaves its points to report their own messages."""
    import core.study.batch as sweeps
    import core.study.loads as sweep_loads

    study = study_from_dict(small_study())
    paths = ["coating[0].modulus", "loading.force", "loading.moment"]
    grid = np.array([(e, f, m) for e in (8e8, -1.0, 4e8) for f in (2e5, 6e5)
                     for m in (0.0, 1e5, 1.9e5)])
    calls = []
    original = sweep_loads.solve_load_batch

    def counted(scene, loads, outputs):
        calls.append(len(next(iter(loads.values()))))
        return original(scene, loads, outputs)

    monkeypatch.setattr(sweeps, "solve_load_batch", counted)
    outputs = list(OUTPUTS)
    got = sweeps.run_batch(study.base, paths, grid, outputs, len(study.times))
    assert calls == [6, 6]  # the two valid moduli; the negative one is not batched
    kinds = {"failed": 0, "unilateral": 0, "full": 0}
    for i, row in enumerate(grid):
        try:
            result = solve(apply_point(study.base, dict(zip(paths, row, strict=True))))
        except ValueError as exc:
            kinds["failed"] += 1
            assert got["flags"][i] == "failed"
            assert got["error"][i] == " ".join(str(exc).split())[:500]
            continue
        kinds[result.info["contact"]] += 1
        if result.info["contact"] == "unilateral":
            np.testing.assert_array_equal(got["values"][i],
                                          sweeps_point_outputs(result, outputs))
        else:
            assert_batched_equal(got["values"][i], got["error_estimate"][i], result,
                                 outputs)
        assert got["flags"][i] == ",".join(result.flags) and got["error"][i] == ""
    assert kinds["failed"] == 6 and kinds["unilateral"] >= 1 and kinds["full"] >= 6


#: A point answered by scaling another point of its eccentricity against core.solve on its
#: own scene, relative to each output's size: measured at most 5.6e-15 on this test's
#: grid (the unilateral solver rounds differently at another load size; 6.7e-13 at most
#: over the 10,000 points of benchmarks.sweep.loads_study(100)); the error estimate,
#: which extrapolates differences near round-off, 5.3e-8 relative here.
SCALED_ROUNDING = 1e-13
SCALED_ESTIMATE_ROUNDING = 1e-6


def test_points_of_one_eccentricity_are_one_answer_scaled(monkeypatch):
    """On a flat punch over an elastic base the answer is proportional to the loads at a
    fixed eccentricity: a batch solves one point per eccentricity that the load batch
    leaves (lift-off here) and scales it for the others; outputs, estimates and flags
    equal core.solve's on each point's scene."""
    import core.study.batch as batch

    study = study_from_dict(small_study(vary=[
        {"field": "loading.force", "values": [1e5]},
        {"field": "loading.moment", "values": [0.0]}]))
    # e = 0.8 m (lift-off) three times, at force ratios 1.7 and 3 (not powers of two,
    # whose scaling is exact); 0.47 m and 0.45 m once; 1.36, 1.41 and 2.4 m refused
    grid = np.array([(f, m) for f in (1e5, 1.7e5, 3e5) for m in (8e4, 1.36e5, 2.4e5)])
    assert batch.answers_scale_with_loads(batch.scene_from_dict(study.base))
    solved = []
    one_point = batch.solve
    monkeypatch.setattr(batch, "solve", lambda scene: solved.append(1) or one_point(scene))
    got = batch.run_batch(study.base, ["loading.force", "loading.moment"], grid,
                          list(OUTPUTS), len(study.times))
    monkeypatch.undo()
    # three refused, one per eccentricity 0.8, 0.47 and 0.45 m; 300 kN/m at 0.267 m is
    # answered with the load batch
    assert len(solved) == 6
    def same_as_the_point(i, result):
        want = sweeps_point_outputs(result, list(OUTPUTS))
        scale = np.max(np.abs(want), axis=1, keepdims=True)
        scale = np.where(scale > 0, scale, 1.0)
        np.testing.assert_allclose(got["values"][i] / scale, want / scale, rtol=0,
                                   atol=SCALED_ROUNDING)
        np.testing.assert_allclose(got["error_estimate"][i], result.info["error_estimate"],
                                   rtol=SCALED_ESTIMATE_ROUNDING)

    kinds = each_load_point_against_solve(study, grid, got, same_as_the_point)
    assert kinds == {"failed": 3, "unilateral": 5, "full": 1}


def test_scaled_answer_flags_a_large_tilt_by_its_own_size():
    from core.scene import LARGE_TILT
    from core.study.batch import _scaled

    answer = (1e5, np.array([[1.0], [2.0]]), 1e-9, ["contact_lost", "large_tilt"],
              0.8 * LARGE_TILT, 0.6)
    values, estimate, flags = _scaled(answer, 2e5, ["tilt", "contact_width"])
    np.testing.assert_array_equal(values, [[2.0], [2.0]])
    assert estimate == 1e-9 and flags == "contact_lost,large_settlement,large_tilt"
    assert _scaled(answer, 1e5, ["tilt"])[2] == "contact_lost"
    # a creeping base (the preset as shipped) is not taken as one that scales here
    from core.scene import scene_from_dict
    from core.study.batch import answers_scale_with_loads

    scene = scene_file("uniform_flat")
    assert not answers_scale_with_loads(scene_from_dict(scene))


#: The lift-off answers of one geometry's batch located along the zone end
#: (core.study.liftoff) against core.solve on each point's scene, relative to each
#: output's size: measured at most 2.3e-9 over the 1,470 lift-off points of
#: benchmarks.sweep.loads_study(100) and 4.7e-11 on this test's grid; both
#: solve the same zone to its solver's tolerance (estimates ~1e-8 to 6e-8), so they differ
#: by their discretizations at zone ends ~1e-10 apart, well below tol = 1e-6.
#: The contact width is the zone's length: the family's zone end and core.solve's are each
#: located to core.contact.ZONE_END_TOL (1e-6 a), which bounds their difference (measured
#: at most 9.9e-8 a on this test's grid).
LIFTOFF_FAMILY_DIFFERENCE = 1e-8


@pytest.mark.slow
def test_liftoff_eccentricities_of_a_batch_are_one_family(monkeypatch):
    """Many lift-off eccentricities of a flat punch in one batch: the smallest and the
    largest are solved by core.solve, the others located along the zone end and solved on
    their zones (core.study.liftoff); every point's outputs, flags and messages match
    core.solve's, and its error estimate stays within a third of tol."""
    import core.study.batch as batch

    study = study_from_dict(small_study(vary=[
        {"field": "loading.force", "values": [1e5]},
        {"field": "loading.moment", "values": [0.0]}], times=[365.0]))
    # 14 lift-off eccentricities 0.46-0.95 m at two forces (not in a ratio of powers of
    # two), one that keeps full contact (0.2 m) and one refused (1.2 m); then 10 negative
    # ones -0.5 to -0.9 m (the zone [-a, c], a family of its own)
    eccentricities = list(np.linspace(0.46, 0.95, 14)) + [0.2, 1.2] + list(
        np.linspace(-0.9, -0.5, 10))
    grid = np.array([(f, f * e) for e in eccentricities for f in (1e5, 2.3e5)])
    solved = []
    one_point = batch.solve
    monkeypatch.setattr(batch, "solve", lambda scene: solved.append(1) or one_point(scene))
    got = batch.run_batch(study.base, ["loading.force", "loading.moment"], grid,
                          list(OUTPUTS), len(study.times))
    monkeypatch.undo()
    # the two ends of each family and the refused point (twice): 6 one-point solves
    # where one per eccentricity would be 26
    assert len(solved) == 6
    # the batch's own points decide its answers: the same again after another batch has
    # warmed this process's caches (as on a worker that ran other batches before)
    batch.run_batch(study.base, ["loading.force", "loading.moment"], grid[::3],
                    list(OUTPUTS), len(study.times))
    again = batch.run_batch(study.base, ["loading.force", "loading.moment"], grid,
                            list(OUTPUTS), len(study.times))
    for name in ("values", "error_estimate", "flags", "error"):
        np.testing.assert_array_equal(again[name], got[name])
    worst, widths = [], []
    j_width = OUTPUTS.index("contact_width")

    def same_as_the_point(i, result):
        want = sweeps_point_outputs(result, list(OUTPUTS))
        scale = np.max(np.abs(want), axis=1, keepdims=True)
        scale = np.where(scale > 0, scale, 1.0)
        others = np.arange(len(OUTPUTS)) != j_width
        worst.append(float(np.max(np.abs(got["values"][i] - want)[others] / scale[others])))
        assert worst[-1] <= LIFTOFF_FAMILY_DIFFERENCE
        # the width is the zone's length: the family's zone end against core.solve's
        a = result.scene.half_width
        widths.append(float(np.max(np.abs(got["values"][i][j_width] - want[j_width]))) / a)
        assert widths[-1] <= ZONE_END_TOL
        assert got["error_estimate"][i] <= study.base["solver"]["tol"] / 3

    kinds = each_load_point_against_solve(study, grid, got, same_as_the_point)
    assert kinds == {"failed": 2, "unilateral": 48, "full": 2}
    print(f"largest difference to core.solve: {max(worst):.2e}; "
          f"of the contact width: {max(widths):.2e} a")


def test_a_scheduler_that_does_not_answer_is_named_and_leaves_nothing(tmp_path: Path):
    """``--scheduler`` at an address where nothing listens, or that is no address: exit 2
    naming the option (it read "internal error (OSError: Timed out ...); please report it"
    after 30 s), and no ``.parts`` folder left, since nothing was computed."""
    import dask

    study = tmp_path / "study.json"
    study.write_text(json.dumps(small_study()))
    output = tmp_path / "d.csv"
    with dask.config.set({"distributed.comm.timeouts.connect": "1s"}):
        for address, says in (("tcp://127.0.0.1:1", "Timed out trying to connect"),
                              ("foo", "missing port number")):
            done = run_cli("sweep", study, "--output", output, "--scheduler", address)
            assert done.returncode == 2, done.stderr
            assert done.stderr.startswith(f"error: --scheduler: cannot connect to "
                                          f"'{address}' ("), done.stderr
            assert says in done.stderr and "internal error" not in done.stderr
            assert not output.exists()
            assert list(tmp_path.iterdir()) == [study]
