"""What the time stepping of a creeping full contact aims at: what the panel rule and the
kernel's fit leave of tol (``core/engines/nystrom/prepared.py``, ``time_tolerance``).

A loose tol buys fewer steps; the answer stays within its estimate against a tight
reference; where the responses' errors add up past tol on a load (parts that cancel in
the answer), the stepping is done again at the floor of its aim, ``tol / 30``.
"""

from __future__ import annotations

import numpy as np
import pytest

import core.engines.nystrom.prepared as prepared_module
from core.cache import clear_caches
from core.engines.nystrom.prepared import (
    TIME_LEFT_SHARE,
    TIME_SHARE,
    step_again_at_floor,
    time_tolerance,
)
from core.scene import solve
from tests.conftest import scene_file


def test_the_time_steps_aim_at_half_of_what_space_and_the_fit_leave():
    assert time_tolerance(1e-4, 4e-6, 1e-6) == pytest.approx(
        TIME_LEFT_SHARE * (1e-4 - 5e-6), rel=1e-15)
    assert time_tolerance(1e-4, 4e-6, 1e-6, 5e-6) == pytest.approx(
        TIME_LEFT_SHARE * (1e-4 - 1e-5), rel=1e-15)
    # little left (or nothing known of it): the floor, as the steps aimed before
    assert time_tolerance(1e-4, 9.9e-5, 0.0) == pytest.approx(1e-4 / TIME_SHARE)
    assert time_tolerance(1e-4, 2e-4, 0.0) == pytest.approx(1e-4 / TIME_SHARE)
    assert time_tolerance(1e-4, float("nan"), 0.0) == pytest.approx(1e-4 / TIME_SHARE)
    assert time_tolerance(1e-4, float("inf"), 0.0) == pytest.approx(1e-4 / TIME_SHARE)


def test_the_floor_is_taken_again_when_any_one_part_misses():
    """Several punches: each punch's estimate is a part with its own tol; one part that
    misses (the other within) is enough to step again, unless the aim was the floor
    already or the stepping stopped at its step limit (it would stop there again)."""
    tol = 1e-6
    within, missing = (0.5 * tol, tol), (2.0 * tol, tol)
    aim = 0.5 * tol
    assert step_again_at_floor(aim, tol, True, [within, missing])
    assert step_again_at_floor(aim, tol, True, [missing, within])
    assert not step_again_at_floor(aim, tol, True, [within, within])
    assert not step_again_at_floor(tol / TIME_SHARE, tol, True, [within, missing])
    assert not step_again_at_floor(aim, tol, False, [within, missing])


def _ten_years(tol: float) -> dict:
    data = scene_file("young_concrete_50_years")
    # ten years and 40 outputs keep the test short; the path is the one of 50 years
    data["times"] = {"end": 3652.5, "count": 40, "spacing": "log"}
    data["solver"] = {**data.get("solver", {}), "tol": tol}
    return data


def _at_floor(monkeypatch: pytest.MonkeyPatch, scene: dict):
    """The answer with the steps aimed at ``tol / TIME_SHARE`` alone (as before)."""
    with monkeypatch.context() as patch:
        patch.setattr(prepared_module, "TIME_LEFT_SHARE", 0.0)
        clear_caches()
        return solve(scene)


def _aimed_far_above_tol(monkeypatch: pytest.MonkeyPatch, scene: dict):
    """The answer with ``TIME_LEFT_SHARE`` 50 (the first stepping stops at its coarsest
    grids, its estimate over tol), which succeeds, and the floor's answer."""
    floor = _at_floor(monkeypatch, scene)
    monkeypatch.setattr(prepared_module, "TIME_LEFT_SHARE", 50.0)
    clear_caches()
    answer = solve(scene)
    assert answer.info["success"]
    return answer, floor


def test_a_loose_tol_buys_fewer_steps_and_stays_within_its_estimate(monkeypatch):
    scene = _ten_years(1e-4)
    floor = _at_floor(monkeypatch, scene)
    clear_caches()
    answer = solve(scene)
    clear_caches()
    reference = solve(_ten_years(1e-7))
    assert answer.info["success"] and floor.info["success"] and reference.info["success"]
    # measured: 63 steps instead of 125 (time estimate 1.4e-5 instead of 2.1e-6)
    assert answer.info["n_steps"] < floor.info["n_steps"]
    assert answer.info["time_error_estimate"] > floor.info["time_error_estimate"]
    error = max(np.max(np.abs(answer.settlement - reference.settlement))
                / np.max(np.abs(reference.settlement)),
                np.max(np.abs(answer.pressure_on_grid - reference.pressure_on_grid))
                / np.max(np.abs(reference.pressure_on_grid)))
    assert error <= answer.info["error_estimate"] <= 1e-4


def test_an_answer_whose_time_part_misses_tol_is_stepped_again_at_the_floor(monkeypatch):
    """With the aim put far above tol (``TIME_LEFT_SHARE`` 50), the first stepping stops
    at its coarsest grids, its estimate over tol: the answer is stepped again at
    ``tol / TIME_SHARE`` and is the floor's answer, to the digit."""
    answer, floor = _aimed_far_above_tol(monkeypatch, _ten_years(1e-6))
    assert answer.info["n_steps"] == floor.info["n_steps"]
    np.testing.assert_array_equal(answer.settlement, floor.settlement)


def _two_footings(tol: float) -> dict:
    data = scene_file("new_footing_beside_old")
    # ten years and 30 outputs keep the test short; the path is the one of 50 years
    data["times"] = {"end": 3652.5, "count": 30, "spacing": "log"}
    data["solver"] = {**data.get("solver", {}), "tol": tol}
    return data


def test_several_punches_whose_time_part_misses_tol_are_stepped_again_at_the_floor(
        monkeypatch):
    """As for one punch: each punch's estimate is its own, and the stepping is done again
    at ``tol / TIME_SHARE`` when one of them misses tol."""
    answer, floor = _aimed_far_above_tol(monkeypatch, _two_footings(1e-5))
    for punch, alone in zip(answer.punches, floor.punches, strict=True):
        assert punch.info["n_steps"] == alone.info["n_steps"]
        np.testing.assert_array_equal(punch.settlement, alone.settlement)
