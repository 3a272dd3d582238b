"""Lift-off of several punches on a creeping base (core/contact/coupled_creep.py): far apart
as single punches, a mirrored pair that lifts off as it creeps, convergence of a close pair
where both lift off, and what is refused."""

from __future__ import annotations

import copy
from typing import Any

import numpy as np
import pytest

import core
from core.contact.zones import ZONE_END_TOL
from core.work import work_bound
from tests.conftest import scene_file
from tests.scene.test_punches import QUANTITIES, _base, _creeping, _pair, _single
from tests.scene.test_punches_liftoff import (
    LIFTING,
    _errors,
    assert_lift_off_in_mirror,
)

#: Punch 1 of :func:`_pair` lifts its right edge off under this load (e = -0.56 a).
LIFTING_RIGHT = {"force": 3e5, "moment": -1e5}


def _lifting_pair(gap: float, tol: float = 1e-6, count: int = 6) -> dict[str, Any]:
    """Both punches of :func:`_pair` lifting off (each its outer side) on the creeping
    base of tests/scene/test_punches.py, ``count`` output times up to a year."""
    d = _creeping(_pair(gap, tol=tol, loads=(LIFTING, LIFTING_RIGHT)))
    d["times"]["count"] = count
    d["solver"]["contact"] = "unilateral"
    return d


def test_far_apart_punches_lift_off_under_creep_as_single_punches() -> None:
    d = _lifting_pair(60.0)  # 15 base thicknesses apart
    result = core.solve(d)
    for k, punch in enumerate(result.punches):
        alone = _single(d, k)
        assert punch.info["contact"] == alone.info["contact"] == "unilateral"
        # The verdict of each alone (both succeed at tol 1e-6, measured: estimates 1.8e-7
        # and 2.3e-7 alone, 2.7e-7 paired). While q at the free ends was taken on the end
        # panels' Gauss rule, its step there (2.5e-7 / 1.7e-7 of the largest q) refused the
        # punches alone and the pair claimed success without that part of the estimate.
        assert punch.info["success"] == alone.info["success"]
        assert punch.flags == alone.flags
        shifted = copy.copy(alone)
        shifted.contact_set = [[(punch.center + lo, punch.center + hi) for lo, hi in zones]
                               for zones in alone.contact_set]
        errors = _errors(punch, shifted)
        if punch.info["n_steps"] == alone.info["n_steps"]:
            # the same rules and grids (punch 0): measured <= 1.2e-15 in the histories,
            # q 5.1e-14, zone ends 2.0e-15 half-widths; the coupling at 15 H ~exp(-2.1 *
            # 15) = 2e-14
            bounds = dict.fromkeys((*QUANTITIES, "q", "ends"), 1e-9)
        else:
            # The pair's shared time grid is the one punch 0 needs (160 steps); punch 1
            # alone meets tol on 80, so the two differ by its own time error: measured
            # 1.8e-9 / 8.4e-9 (settlement, tilt), 3.3e-8 (q), ends 2.3e-8 (its estimates
            # 2.3e-7 and 4.9e-8); bounds 3x those
            bounds = {**dict.fromkeys(QUANTITIES, 3e-8), "q": 1e-7, "ends": 7e-8}
        for q in (*QUANTITIES, "q"):
            assert errors[q] < min(bounds[q], alone.info["error_estimate"]), (k, q, errors)
        assert errors["ends"] < min(bounds["ends"], alone.info["zone_end_error"])
        # one march serves both: its estimate is the larger of the two punches'
        assert punch.info["error_estimate"] >= 0.5 * alone.info["error_estimate"]
        assert punch.settlement[-1] > 1.2 * punch.settlement[0]  # it creeps
    lifted, right = result.punches[0].contact_set, result.punches[1].contact_set
    assert all(len(z) == 1 and z[0][0] > -1.0 and z[0][1] == 1.0 for z in lifted)
    assert all(len(z) == 1 and z[0][0] == pytest.approx(61.0) and z[0][1] < 62.2
               for z in right)
    # the zone shrinks as the base creeps (measured: its end from -0.773 to -0.876 m)
    assert lifted[-1][0][0] < lifted[0][0][0] - 0.03


@pytest.mark.slow
def test_far_apart_punches_on_an_aging_base_lift_off_as_single_punches() -> None:
    young = scene_file("young_concrete_50_years")
    d = _lifting_pair(60.0, tol=1e-4)
    d["base"]["creep"] = copy.deepcopy(young["base"]["creep"])
    d["base"]["age_at_loading"] = young["base"]["age_at_loading"]
    result = core.solve(d)
    estimates = []
    for k, punch in enumerate(result.punches):
        alone = _single(d, k)
        shifted = copy.copy(alone)
        shifted.contact_set = [[(punch.center + lo, punch.center + hi) for lo, hi in zones]
                               for zones in alone.contact_set]
        errors = _errors(punch, shifted)
        # measured: outputs <= 2.3e-15, q 4.3e-14, zone ends 1.2e-14 half-widths. The
        # aging kernel is fast just after loading: the single punches and the pair stop
        # at the finest time grid with estimates of 1.2e-4 (flagged, all)
        for q in (*QUANTITIES, "q"):
            assert errors[q] < 1e-9, (k, q, errors)
        assert errors["ends"] < 1e-9
        assert punch.flags == alone.flags
        estimates.append(alone.info["time_error_estimate"])
    # one march for both: its estimate is the larger of theirs (measured 1.2457e-4 and
    # 1.2457e-4 against 1.2113e-4 and 1.2457e-4 alone)
    for punch in result.punches:
        assert punch.info["time_error_estimate"] == pytest.approx(max(estimates), rel=1e-6)


@pytest.mark.slow
def test_a_mirrored_pair_lifts_off_in_mirror_as_the_base_creeps() -> None:
    """contact "auto": full contact while it holds under both punches, then lift-off of
    their outer heels as the moment grows (the full-contact answer flags it)."""
    # tol 1e-4: what is checked is the mirror (to rounding) and the switch to lift-off,
    # the same at 1e-6 (27 s of CPU there, 16 s here)
    d = _creeping(_base(1e-4))
    d["times"]["count"] = 6  # log-spaced: the heels lift between the last two
    ramp = {"kind": "linear", "start": 0.0, "end": 3e5}
    d["punches"] = [
        {"center": -1.2, "half_width": 1.0, "loading": {"force": 5e5, "moment": ramp}},
        {"center": 1.2, "half_width": 1.0,
         "loading": {"force": 5e5, "moment": dict(ramp, end=-3e5)}}]
    result = core.solve(d)
    assert not result.flags
    left, right = result.punches
    assert left.info["contact"] == "unilateral"
    assert "contact_lost" in left.info["full_contact"]["flags"]
    # measured: settlement 5.1e-15, tilt 5.6e-15 of the largest, zone ends 2.0e-15 m,
    # q 6.4e-15 (mirrored rules, equal to rounding)
    assert_lift_off_in_mirror(left, right)
    assert np.all(left.tilt[1:] > 0) and np.all(np.diff(left.tilt) > 0)


def _largest_at_free_ends(punch: Any) -> float:
    """The largest q at the free zone ends a punch reports, of its largest q."""
    a = float(np.max(np.abs(punch.x)))
    scale = float(np.max(punch.pressure(np.linspace(-a, a, 2001))))
    ends = [(k, end) for k, zones in enumerate(punch.local_contact_set) for zone in zones
            for end in zone if abs(end) < a * (1.0 - 1e-12)]
    return max((float(punch.pressure([end])[0, k]) for k, end in ends), default=0.0) / scale


@pytest.mark.slow
def test_a_close_pair_lifting_off_under_creep_converges() -> None:
    """Both punches lift off 0.2 m apart: the coupling moves the zones (see the checks of
    the far pair above), and the answer converges to one on the finest rules."""
    # The reference asks 1e-8: its rule ends at the finest band panels (0.005) and its
    # estimate is 4.6e-8 (flagged tol_not_met, measured).
    reference = core.solve(_lifting_pair(0.2, 1e-8, count=10))
    for tol in (1e-4, 1e-6):
        result = core.solve(_lifting_pair(0.2, tol, count=10))
        # the right punch's zone (0.83 m of 1.2 m) puts its coating model's estimate at
        # 2.7 %: that punch alone, elastic at loading, measured 2.25 % (FE check with
        # lift-off) against model_tol 2 %, so the flag is right; the solve's own are none
        assert result.info["success"] and result.flags == ["punches[1].model_error"]
        for mine, best in zip(result.punches, reference.punches, strict=True):
            errors = _errors(mine, best)
            estimate = mine.info["error_estimate"]
            # measured, punch 0 / punch 1: at 1e-4 settlement 1.5e-8 / 4.0e-8, tilt 3.0e-8 /
            # 7.1e-8, force and moment 6e-15 (given) against the estimate 9.4e-7; zone ends
            # 1.2e-7 / 2.5e-8 half-widths against 3.0e-7; q 2.4e-7 / 6.9e-8 of its largest
            # value. At 1e-6 (finer grids) q 2.7e-8 / 4.2e-9 against 8.3e-8, the rest below
            # 1e-8. Against a reference beyond the solver's limits (band panels to 0.00125,
            # 1536 steps; its estimate 4.1e-9) q was 2.4e-7 / 7.0e-8 off at 1e-4, 2.8e-8 /
            # 4.4e-9 at 1e-6 (with q on the end panels' Gauss rule across the kink: 2.7e-7
            # / 2.0e-7 and 4.4e-8 / 2.1e-8).
            for q in QUANTITIES:
                assert errors[q] <= min(tol, estimate), (tol, q, errors)
            assert errors["ends"] <= min(ZONE_END_TOL, mine.info["zone_end_error"])
            assert errors["q"] <= estimate
            # q vanishes at the free ends it reports (each punch's end panels cut there,
            # its neighbour's pressure in its formula cut the same way): measured 1.3e-8 /
            # 1.1e-9 of the largest q at 1e-4, 9.8e-10 / 1.4e-10 at 1e-6 (the ends are
            # extrapolated in time, the cut is the finer grid's)
            assert _largest_at_free_ends(mine) <= min(2e-8, mine.info[
                "zone_end_pressure_error"])
    lifted, right = reference.punches
    # the neighbour's pressure changes the zones at a year (measured): punch 0 from -0.876
    # m alone to -0.783 m, punch 1 from 2.091 m to 2.050 m
    assert -0.80 < lifted.contact_set[-1][0][0] < -0.76
    assert 2.04 < right.contact_set[-1][0][1] < 2.06


def test_a_punch_pulled_away_between_output_times_is_refused_naming_it() -> None:
    """A creeping base remembers the loads between the output times: a pull there is
    refused as for one punch, naming the punch's field."""
    d = _lifting_pair(0.5, count=2)
    # zero at both output times (0 and 365 days), negative between them
    d["punches"][1]["loading"]["force"] = {"kind": "sine", "mean": 0.0,
                                           "amplitude": 1e5, "wavelength": 365.0,
                                           "phase": 0.0}
    d["punches"][1]["loading"]["moment"] = 0.0
    with pytest.raises(ValueError, match=r"punches\[1\]\.loading\.force: the punch is pulled"):
        core.solve(d)


def test_a_creep_lift_off_past_its_work_bound_names_the_load_that_varies() -> None:
    d = _lifting_pair(0.5, count=40)
    d["punches"][1]["loading"]["moment"] = {"kind": "linear", "start": 0.0, "end": -1e5}
    with work_bound(0.2), pytest.raises(ValueError) as refused:
        core.solve(d)
    message = str(refused.value)
    assert message.startswith("punches[1].loading.moment: the solve was stopped after 0.2 s")
    assert "several punches under creep" in message


def test_far_apart_punches_land_on_a_corner_touching_down_as_a_punch_alone() -> None:
    """The crowned punch of a far-apart pair spreads to its corners as the base creeps
    (touchdown at t = 1.19, inside a step): alone, its time grids land there
    (core.contact.creep.corner_contact_changes); paired, the march of several punches
    kept no pressure at the corners and missed it (its estimate 8.4e-6 against 1.16e-5
    alone, tol 1e-4). Now the pair's grids land on it too, and the punch answers as it
    does alone."""
    from core.contact import creep

    located: list[list[float]] = []
    changes = creep.corner_contact_changes

    def spy(run, floor=1e-9):
        located.append(changes(run, floor))
        return located[-1]

    d = _creeping(_pair(60.0, tol=1e-4, loads=({"force": 5e5, "moment": 0.0},
                                                {"force": 3e5, "moment": 0.0})),
                  {"model": "exponential", "modulus": 3.0e10, "compliance": 1.5e-10,
                   "rate": 0.1})
    d["times"] = {"end": 100.0, "count": 12}
    d["punches"][0]["shape"] = {"kind": "polynomial", "coefficients": [0.0, 0.0, 4e-5]}
    d["solver"]["contact"] = "unilateral"
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(creep, "corner_contact_changes", spy)
        alone = _single(d, 0)
        touchdown = located[-1]
        located.clear()
        punch = core.solve(d).punches[0]
    assert alone.contact_set[0] != [(-1.0, 1.0)] and alone.contact_set[-1] == [(-1.0, 1.0)]
    assert touchdown == [pytest.approx(1.190, abs=1e-3)]
    assert located[-1] == pytest.approx(touchdown, abs=1e-12)
    assert punch.info["success"] and alone.info["success"]
    assert punch.info["error_estimate"] == pytest.approx(alone.info["error_estimate"],
                                                         rel=1e-6)
    shifted = copy.copy(alone)
    shifted.contact_set = [[(punch.center + lo, punch.center + hi) for lo, hi in zones]
                           for zones in alone.contact_set]
    errors = _errors(punch, shifted)
    # the same rules and grids: measured 7e-16 in the histories, q 7.5e-13 (the coupling
    # at 15 base thicknesses, ~2e-14, as above)
    for q in (*QUANTITIES, "q"):
        assert errors[q] < 1e-9, (q, errors)
