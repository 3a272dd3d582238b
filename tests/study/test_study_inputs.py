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
