"""A scene with a design code's creep law meets its tolerance by default, and a tighter
tolerance says which one the law's fit allows."""

from __future__ import annotations

import copy

import pytest

from core.creep import DEFAULT_TOL_LADDER, FIT_ERROR_SHARE, creep_model_from_spec
from core.scene import default_tol, scene_from_dict, solve
from tests.conftest import scene_file


def _code_scene(age: float, humidity: float = 40.0, model: str = "fib_mc2010") -> dict:
    d = copy.deepcopy(scene_file("young_concrete_50_years"))
    d["base"]["age_at_loading"] = age
    d["base"]["creep"]["model"] = model
    d["base"]["creep"]["relative_humidity"] = humidity
    d["times"] = {"end": 18262.5, "count": 12, "spacing": "log"}
    del d["solver"]["tol"]
    return d


# fib MC2010 at RH 40 %, 50 years: fit errors 2.2e-4 (1 day), 2.3e-5 (7), 4.2e-6 (28),
# 4.4e-7 (365 days), hence the ladder's 1e-3, 1e-4, 1e-5 and 1e-6
@pytest.mark.parametrize(("age", "tol"), [(1.0, 1e-3), (7.0, 1e-4), (28.0, 1e-5),
                                          (365.0, 1e-6)])
def test_a_code_creep_scene_without_a_tolerance_meets_its_default(age, tol):
    d = _code_scene(age)
    result = solve(d)
    assert result.scene.tol == tol
    assert result.scene.to_dict()["solver"]["tol"] == tol  # a saved scene keeps it
    assert "tol_not_met" not in result.flags, result.info["message"]
    fit = result.info["kernel_fit_error"]
    # the smallest of the ladder at least twice the fit's error
    assert tol >= FIT_ERROR_SHARE * fit
    finer = [t for t in DEFAULT_TOL_LADDER if t < tol]
    assert not finer or finer[-1] < FIT_ERROR_SHARE * fit
    assert default_tol(d["base"]["creep"], age) == tol
    assert default_tol(creep_model_from_spec(d["base"]["creep"]), age) == tol


def test_other_creep_laws_keep_the_default_of_one_in_a_million():
    d = copy.deepcopy(scene_file("uniform_flat"))
    d.get("solver", {}).pop("tol", None)
    assert scene_from_dict(d).tol == 1e-6
    assert default_tol(d["base"]["creep"], d["base"]["age_at_loading"]) == 1e-6


def test_a_tolerance_below_the_fit_is_flagged_with_the_one_it_allows():
    d = _code_scene(7.0)
    d["solver"]["tol"] = 1e-6
    result = solve(d)
    assert "tol_not_met" in result.flags
    message = result.info["message"]
    assert "fitted by exponentials no closer than" in message
    assert "ask for solver.tol >=" in message
