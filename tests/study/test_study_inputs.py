"""Odd input to study files (:func:`core.study.study_from_dict`): a ValueError naming the
field, never another exception, no field path evaluated, and no work before the check."""

from __future__ import annotations

from typing import Any

import pytest

from core.study import study_from_dict
from core.study.definition import MAX_STUDY_POINTS
from tests.conftest import ODD, small_preset_scene


def _study(**change: Any) -> dict[str, Any]:
    study = {"study_version": 1, "name": "odd", "scene": small_preset_scene(),
             "vary": [{"field": "coating[0].modulus",
                       "linspace": {"start": 5e7, "stop": 5e9, "count": 3}}]}
    study.update(change)
    return study


def test_a_stray_study_field_is_not_blamed_on_the_scene() -> None:
    # "scene" is itself a study field (the base scene): the message said "scene:" before
    with pytest.raises(ValueError, match=r"^study: unknown field 'bogus'"):
        study_from_dict(_study(bogus=1))
    with pytest.raises(ValueError, match=r"^study: must be an object"):
        study_from_dict([1, 2])  # type: ignore[arg-type]


@pytest.mark.parametrize("value", ODD, ids=repr)
@pytest.mark.parametrize("field", ["samples", "seed", "outputs", "times", "vary",
                                   "study_version"])
def test_study_fields_refuse_odd_values(field, value) -> None:
    with pytest.raises(ValueError) as info:
        study_from_dict(_study(**{field: value}))
    assert str(info.value).startswith(field), str(info.value)


@pytest.mark.parametrize("count", [10**9, 10**400, MAX_STUDY_POINTS + 1])
def test_huge_study_counts_are_refused_before_any_work(count) -> None:
    vary = [{"field": "coating[0].modulus", "linspace": {"start": 5e7, "stop": 5e9,
                                                         "count": count}}]
    with pytest.raises(ValueError, match=r"^vary"):
        study_from_dict(_study(vary=vary))


@pytest.mark.parametrize("expr", ["__import__('os')", "().__class__", "x" * 10_000])
def test_study_field_paths_are_not_evaluated(expr) -> None:
    vary = [{"field": expr, "values": [1.0]}]
    with pytest.raises(ValueError, match=r"^vary\[0\]\.field: "):
        study_from_dict(_study(vary=vary))


@pytest.mark.parametrize("output", [[1], {"a": 1}, None, 3], ids=repr)
def test_study_output_names_of_any_type_are_refused_by_name(output) -> None:
    # a list inside "outputs" made an unhashable-type TypeError before the fix
    with pytest.raises(ValueError, match=r"^outputs\[1\]: unknown output"):
        study_from_dict(_study(outputs=["settlement", output]))


def _liftoff_study(vary: list) -> dict[str, Any]:
    return {"study_version": 1, "name": "audit", "scene": "preset:eccentric_footing_liftoff",
            "vary": vary}


@pytest.mark.parametrize(("vary", "message"), [
    # two spellings of one field: the second overwrote the first, whose column then named
    # values never solved (a 2e8 Pa modulus shown with the settlement of 4e8)
    ([{"field": "coating[0].modulus", "values": [2e8, 8e8]},
      {"field": "coating[00].modulus", "values": [4e8, 3.2e9]}],
     "vary[1].field: 'coating[00].modulus' is already varied by vary[0] (as "
     "'coating[0].modulus')"),
    # loads every solve refuses passed validation ("ok: 2 points"), failing only when run
    ([{"field": "loading.force", "values": [-1e5, 8e5]}],
     "vary[0].values: the scene is invalid at loading.force = -100000 (loading.force: the punch is "
     "pulled away"),
    ([{"field": "loading.moment", "values": [0.0, 9e5]}],
     "vary[0].values: the scene is invalid at loading.moment = 900000 (loading.moment: the "
     "eccentricity"),
    ([{"field": "punch.half_width", "values": [0.5, 1.0]}],
     "vary[0].values: the scene is invalid at punch.half_width = 0.5 (loading.moment: the "
     "eccentricity"),
    # a grid that says less than it reads
    ([{"field": "loading.force", "linspace": {"start": 1e5, "stop": 5e5, "count": 1}}],
     "vary[0].linspace.count: 1 point is start alone, and stop (500000) would be ignored"),
    ([{"field": "loading.force", "values": [1e5, 1e5, 2e5]}],
     "vary[0].values[1]: repeats vary[0].values[0] (100000): equal points would repeat"),
])
def test_a_study_that_would_solve_other_points_than_it_names_is_refused(vary, message) -> None:
    with pytest.raises(ValueError) as info:
        study_from_dict(_liftoff_study(vary))
    assert str(info.value).startswith(message), str(info.value)


def test_a_study_takes_its_scene_as_a_preset_or_an_absolute_path(tmp_path) -> None:
    """``"scene": "preset:NAME"`` read as a file name ("No such file or directory"),
    although the commands and core.solve take it; an absolute path needed a directory."""
    import json

    import core

    vary = [{"field": "loading.force", "values": [6e5, 8e5]}]
    by_name = study_from_dict(_liftoff_study(vary))
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(core.load_scene("preset:eccentric_footing_liftoff").to_dict()))
    by_path = study_from_dict({**_liftoff_study(vary), "scene": str(path)})
    assert by_name.key == by_path.key and by_name.n_points == 2
    with pytest.raises(ValueError, match=r"^scene: preset:nope: no shipped scene"):
        study_from_dict({**_liftoff_study(vary), "scene": "preset:nope"})
    with pytest.raises(ValueError, match=r"^scene: a relative scene file path needs"):
        study_from_dict({**_liftoff_study(vary), "scene": "scene.json"})


def test_an_output_in_a_directory_that_does_not_exist_is_refused(tmp_path) -> None:
    """A mistyped directory was created (``-o /nonexist/x.csv`` made /nonexist)."""
    from pathlib import Path

    from core.study import check_output

    with pytest.raises(ValueError, match=r"^output: the directory '.*missing' does not "):
        check_output(tmp_path / "missing" / "x.csv")
    assert not (tmp_path / "missing").exists()
    check_output(tmp_path / "x.csv")
    check_output(Path("x.csv"))  # the working directory


@pytest.mark.parametrize(("path", "unit"), [
    ("coating[0].modulus", "Pa"), ("punch.shape", "m"), ("base.creep.alpha", "1/day"),
    ("base.creep.fcm", "MPa"), ("base.creep.beta", "1"), ("solver.model_tol", "1"),
    ("coating[0].modulus.start", "Pa"), ("loading.force.values[1]", "N/m"),
    ("loading.moment.amplitude", "N"), ("loading.force.breaks[0]", "day"),
    ("coating[0].thickness.breaks[0]", "m"), ("punches[1].center", "m"),
    ("loading.force.center", "day"), ("punch.shape.coefficients[2]", "1/m"),
    ("coating[0].thickness.points[3][0]", "m"), ("coating[0].modulus.points[3][1]", "Pa"),
])
def test_every_varied_number_has_its_unit(path, unit) -> None:
    """The unit of a study's or a fit's field: a number inside a profile object, the
    punch's shape and three creep coefficients had none ('')."""
    from core.study import field_unit

    assert field_unit(path) == unit


def test_the_long_form_names_each_varied_field_with_its_unit(tmp_path) -> None:
    """The outputs' columns carried their units (settlement_m), the fields' did not."""
    import csv

    from core.study import sweep

    study = study_from_dict(_liftoff_study([
        {"field": "loading.force", "values": [7e5, 8e5]},
        {"field": "coating[0].poisson",
         "values": [0.3, 0.35]}]))
    out = tmp_path / "s.csv"
    sweep(study, output=out, progress=False, return_dataset=False)
    with out.open() as f:
        header = next(csv.reader(line for line in f if not line.startswith("#")))
    assert header[:4] == ["point", "loading_force_N_per_m", "coating_0_poisson", "sample"]
    assert "settlement_m" in header and "q_max_Pa" in header


def test_a_parquet_output_without_pyarrow_is_refused_before_the_study(monkeypatch,
                                                                     tmp_path) -> None:
    """Every point was solved, then the table refused (pyarrow missing), its parts left."""
    import sys

    from core.optional import MissingDependency
    from core.study import check_output

    for name in ("pyarrow", "pyarrow.parquet"):  # not installed, as the import sees it
        monkeypatch.setitem(sys.modules, name, None)
    with pytest.raises(MissingDependency, match="pyarrow is needed for a study's Parquet"):
        check_output(tmp_path / "r.parquet")
    check_output(tmp_path / "r.csv")
