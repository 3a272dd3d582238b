"""The points and batches of a study made batch by batch from its description
(core.study.definition.StudyPoints, core.study.BatchPlan): the same points as the whole table,
the same order as a sort of all of them where the loads fit a window, bounded memory."""

from __future__ import annotations

import json
import tracemalloc
from pathlib import Path

import numpy as np
import pytest

import core.study.plan as sweep_plan
from core.study import study_from_dict
from core.study.plan import BatchPlan
from core.study.points import DRAW_BLOCK, StudyPoints, point_table
from tests.study.test_sweep import elastic_scene, small_study


def loads_grid(n_force: int, n_moment: int, **extra) -> dict:
    """Force [N/m] and moment [N] on a grid, some of one eccentricity, some lifting off."""
    spec = {"study_version": 1, "name": "loads", "scene": elastic_scene(),
            "vary": [{"field": "loading.force", "linspace": {"start": 1e5, "stop": 1e6,
                                                             "count": n_force}},
                     {"field": "loading.moment", "linspace": {"start": 0.0, "stop": 4e5,
                                                              "count": n_moment}}]}
    spec.update(extra)
    return spec


def whole_sort(study) -> np.ndarray:
    """The former plan: all the points sorted at once by geometry, eccentricity, loads."""
    table = point_table(study)
    loads = [p.path for p in study.parameters if p.is_load]
    geometry = [p.path for p in study.parameters if not p.is_load]
    force, moment = table["loading.force"], table["loading.moment"]
    keys = [table[p] for p in reversed(loads)] + [moment / force]
    return np.lexsort(keys + [table[p] for p in reversed(geometry)])


def every_batch(plan: BatchPlan) -> np.ndarray:
    return np.concatenate([plan.batch(k) for k in range(plan.n_batches)])


def test_points_on_demand_equal_the_table_whatever_the_batching():
    spec = small_study()
    spec["vary"].append({"field": "base.thickness", "lognormal": {"median": 4.0,
                                                                  "sigma": 0.1}})
    for samples in (5, DRAW_BLOCK + 3):  # one stream, then blocks of streams
        study = study_from_dict({**spec, "samples": samples, "seed": 7}, max_points=10**6)
        table = point_table(study)
        rng = np.random.default_rng(0)
        for size in (1, 13, 4000):
            index = np.sort(rng.choice(study.n_points, min(size, study.n_points),
                                       replace=False))
            got = StudyPoints(study)(index)
            for path in table:
                np.testing.assert_array_equal(got[path], table[path][index])
    # a small study draws as before: one stream, each distribution's draws in turn
    study = study_from_dict({**spec, "samples": 5, "seed": 7})
    want = 4.0 * np.exp(np.random.default_rng(7).normal(0.0, 0.1, 5))
    np.testing.assert_array_equal(point_table(study)["base.thickness"][:5], want)


def test_plan_equals_a_sort_of_all_the_points_when_the_loads_fit_a_window():
    # a descending grid, a geometry axis between the loads, equal eccentricities
    spec = small_study(vary=[
        {"field": "loading.moment", "values": [2e4, 0.0, 1e4]},
        {"field": "coating[0].modulus", "values": [8e8, 4e8, 6e8]},
        {"field": "loading.force", "linspace": {"start": 4e5, "stop": 2e5, "count": 3}}])
    for study in (study_from_dict(spec), study_from_dict(loads_grid(30, 40))):
        plan = BatchPlan(study, 7)
        assert plan.same_as_whole_sort
        np.testing.assert_array_equal(every_batch(plan), whole_sort(study))


def test_windowed_plan_keeps_geometries_together_and_sorts_each_window(monkeypatch):
    monkeypatch.setattr(sweep_plan, "PLAN_WINDOW", 50)
    spec = loads_grid(12, 10)
    spec["vary"].insert(0, {"field": "coating[0].modulus", "values": [8e8, 4e8]})
    study = study_from_dict(spec)
    plan = BatchPlan(study, 16)
    assert not plan.same_as_whole_sort
    order = every_batch(plan)
    np.testing.assert_array_equal(np.sort(order), np.arange(study.n_points))
    table = point_table(study)
    moduli = table["coating[0].modulus"][order]
    assert np.count_nonzero(np.diff(moduli)) == 1
    eccentricity = (table["loading.moment"] / table["loading.force"])[order]
    # 120 loads per geometry: windows of 50, 50 and 20, each in eccentricity order
    for start, stop in ((0, 50), (50, 100), (100, 120), (120, 170), (220, 240)):
        assert np.all(np.diff(eccentricity[start:stop]) >= 0)
    assert eccentricity[50] < eccentricity[49]


def _planning_peak(study) -> tuple[BatchPlan, float]:
    """The plan after every batch was asked for in order, and tracemalloc's peak [B]."""
    tracemalloc.start()
    try:
        plan = BatchPlan(study, 500)
        for k in range(plan.n_batches):
            plan.batch(k)
        return plan, tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_plan_of_a_million_points_holds_no_per_point_array():
    study = study_from_dict(loads_grid(1000, 1000))
    assert study.n_points == 10**6
    plan, peak = _planning_peak(study)
    _, peak_small = _planning_peak(study_from_dict(loads_grid(200, 1000)))
    # the peak does not grow with the study (measured 6.30 and 6.31 MB at 2e5 and 1e6
    # points); a per-point index alone would be 8 MB at 1e6 points
    assert peak < 8e6 and peak < 1.05 * peak_small
    for holder in (plan, plan.points):
        for value in vars(holder).values():
            arrays = value if isinstance(value, tuple) else (value,)
            for a in arrays:
                assert not isinstance(a, np.ndarray) or a.size <= 2 * sweep_plan.PLAN_WINDOW
    # the batches run every point once
    order = np.concatenate([plan.batch(k) for k in range(300)])
    assert len(np.unique(order)) == len(order) == 150_000


def test_parts_written_before_the_order_was_named_resume_when_it_is_the_same(
        tmp_path: Path):
    from core.study import sweep

    study = study_from_dict(small_study())
    work = tmp_path / "parts"
    sweep(study, client="serial", work_dir=work, batch_points=4)
    manifest = work / "manifest.json"
    have = json.loads(manifest.read_text())
    del have["order"]
    manifest.write_text(json.dumps(have))
    ds = sweep(study, client="serial", work_dir=work, batch_points=4)
    assert ds.attrs["batches_reused"] == 3
    drawn = study_from_dict(small_study(vary=[{"field": "base.poisson", "normal":
                                               {"mean": 0.3, "std": 0.01}}], samples=4))
    other = tmp_path / "drawn"
    sweep(drawn, client="serial", work_dir=other)
    have = json.loads((other / "manifest.json").read_text())
    del have["order"]
    (other / "manifest.json").write_text(json.dumps(have))
    with pytest.raises(ValueError, match=r"^work_dir: .* planned in another order"):
        sweep(drawn, client="serial", work_dir=other)
