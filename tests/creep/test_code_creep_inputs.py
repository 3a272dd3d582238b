"""Odd input to the design-code creep models (``base.creep`` with ``fib_mc2010`` or
``eurocode2``, and :func:`core.creep.creep_coefficient_curve`): a ValueError naming the
field, never another exception, and no work before the check."""

from __future__ import annotations

import math
from typing import Any

import pytest

from core import limits
from core.creep import creep_coefficient_curve
from core.scene import scene_from_dict
from tests.conftest import ODD, small_preset_scene

EUROCODE = {"model": "eurocode2", "fcm": 38, "cement": "N", "relative_humidity": 60,
            "notional_size": 300}


FIB = {"model": "fib_mc2010", "strength_class": "C30/37", "cement": "N",
       "relative_humidity": 60, "notional_size": 300, "temperature": 20}


def _code_scene(creep: dict[str, Any]) -> dict[str, Any]:
    scene = small_preset_scene()
    scene["base"] = {k: v for k, v in scene["base"].items() if k not in ("modulus", "creep")}
    scene["base"].update(creep=dict(creep), age_at_loading=28.0)
    return scene


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
                                       [math.nan], [-1.0]],
                         # (an object's repr holds its address: another in each process)
                         ids=lambda v: "object()" if type(v) is object else repr(v))
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
