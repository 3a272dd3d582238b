"""Odd input to the newer scene fields, study files and code creep: a ValueError naming
the field, never another exception, and no work before the check.

Covers ``solver.contact``, ``solver.model_tol``, ``coating[k].interface``, the code creep
models (``base.creep`` with ``fib_mc2010``/``eurocode2`` and
:func:`core.creep_coefficient_curve`) and study files (:func:`core.study.study_from_dict`).
"""

from __future__ import annotations

import copy
import math
import re
from typing import Any

import pytest

from core import limits
from core.creep import creep_coefficient_curve
from core.scene import scene_from_dict
from core.study import study_from_dict
from core.study.definition import MAX_STUDY_POINTS
from tests.conftest import small_preset_scene

#: Values no number, string or choice field should take without a clear refusal.
ODD = [math.nan, math.inf, -math.inf, "x", None, True, [[1]], {"a": 1}, 10**400,
       "__import__('os').system('true')", 1e308]
EUROCODE = {"model": "eurocode2", "fcm": 38, "cement": "N", "relative_humidity": 60,
            "notional_size": 300}
FIB = {"model": "fib_mc2010", "strength_class": "C30/37", "cement": "N",
       "relative_humidity": 60, "notional_size": 300, "temperature": 20}


def _with(scene: dict[str, Any], path: tuple[Any, ...], value: Any) -> dict[str, Any]:
    changed = copy.deepcopy(scene)
    holder = changed
    for key in path[:-1]:
        holder = holder.setdefault(key, {}) if isinstance(key, str) else holder[key]
    holder[path[-1]] = value
    return changed


def _code_scene(creep: dict[str, Any]) -> dict[str, Any]:
    scene = small_preset_scene()
    scene["base"] = {k: v for k, v in scene["base"].items() if k not in ("modulus", "creep")}
    scene["base"].update(creep=dict(creep), age_at_loading=28.0)
    return scene


@pytest.mark.parametrize("value", ODD, ids=repr)
@pytest.mark.parametrize("path, field", [
    (("solver", "contact"), "solver.contact"),
    (("solver", "model_tol"), "solver.model_tol"),
    (("coating", 0, "interface"), "coating[0].interface"),
])
def test_new_scene_fields_refuse_odd_values(path, field, value) -> None:
    with pytest.raises(ValueError) as info:
        scene_from_dict(_with(small_preset_scene(), path, value))
    assert str(info.value).startswith(field + ":"), str(info.value)


@pytest.mark.parametrize("path, field", [
    (("solver", "contcat"), "solver"), (("coating", 0, "interfase"), "coating[0]")])
def test_misspelt_new_fields_are_named(path, field) -> None:
    with pytest.raises(ValueError, match=r"^" + re.escape(field) + r": unknown field"):
        scene_from_dict(_with(small_preset_scene(), path, "full"))


@pytest.mark.parametrize("value", ODD, ids=repr)
@pytest.mark.parametrize("creep, name", [
    (FIB, "relative_humidity"), (FIB, "notional_size"), (FIB, "temperature"),
    (FIB, "strength_class"), (FIB, "cement"), (EUROCODE, "fcm"), (EUROCODE, "model")])
def test_code_creep_fields_refuse_odd_values(creep, name, value) -> None:
    with pytest.raises(ValueError) as info:
        scene_from_dict(_code_scene({**creep, name: value}))
    # null counts as "not given": the strength is then missing, which base.creep names
    missing = value is None and name in ("fcm", "strength_class")
    field = "base.creep: give exactly one of" if missing else f"base.creep.{name}:"
    assert str(info.value).startswith(field), str(info.value)


@pytest.mark.parametrize("durations", ["abc", [1, "x"], {"a": 1}, [[1, 2], [3]], object(),
                                       [math.nan], [-1.0]], ids=repr)
def test_creep_curve_durations_refused_by_name(durations) -> None:
    # before the fix a dict or object gave a TypeError, a string numpy's own message
    with pytest.raises(ValueError, match=r"^durations: "):
        creep_coefficient_curve(EUROCODE, 28.0, durations)


def test_creep_curve_has_a_bounded_number_of_points() -> None:
    too_many = [1.0] * (limits.MAX_CURVE_POINTS + 1)
    with pytest.raises(ValueError, match=r"^durations: at most 100,000 values"):
        creep_coefficient_curve(EUROCODE, 28.0, too_many)


@pytest.mark.parametrize("model", [["eurocode2"], {"a": 1}, None, 3], ids=repr)
def test_creep_curve_model_name_refused_by_name(model) -> None:
    # a list as the model name made an unhashable-type TypeError before the fix
    with pytest.raises(ValueError, match=r"^creep\.model: must be one of"):
        creep_coefficient_curve({**EUROCODE, "model": model}, 28.0, [1.0])


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
