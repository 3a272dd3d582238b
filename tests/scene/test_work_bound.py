"""Every solve runs under a bound on its CPU time (core.work, core.limits), also where its
cost cannot be predicted: lift-off under creep driven by a time-varying tilt ran 600 s."""

from __future__ import annotations

import threading

import numpy as np
import pytest

from core.limits import MAX_SOLVE_CPU_SECONDS
from core.scene import solve
from core.work import SolveCancelled, WorkLimitExceeded, cancellable, check_work, work_bound
from tests.conftest import scene_file


def _sine_tilt_on_creep() -> dict:
    """Statement 3 (tilt and force given), the tilt a sine in time, on the creeping base
    of uniform_flat: the heel lifts off and on, followed step by step (measured: over 600
    s of CPU before this bound; the bound below stops it after about 1 s)."""
    d = scene_file("uniform_flat")
    d["loading"] = {"tilt": {"kind": "sine", "mean": 0.0, "amplitude": 1e-4,
                             "wavelength": 100.0, "phase": 0.0},
                    "force": 500000.0}
    return d


def test_a_solve_past_its_bound_stops_and_names_the_costly_field():
    with work_bound(1.0), pytest.raises(ValueError) as refused:
        solve(_sine_tilt_on_creep())
    message = str(refused.value)
    assert message.startswith("loading.tilt: the solve was stopped after 1 s of CPU time")
    assert "following the contact zones under creep" in message


def _wavy_punch(half_width: float) -> dict:
    """The explorer's wavy punch (a 5 um wave of 0.5 m) on its elastic default base: it
    touches at its crests, one contact zone each."""
    d = scene_file("uniform_flat")
    d["punch"] = {"half_width": half_width,
                  "shape": {"kind": "sine", "mean": 0.0, "amplitude": 5e-6,
                            "wavelength": 0.5, "phase": 0.0}}
    d["coating"] = [{"thickness": 0.01, "modulus": 2e8, "poisson": 0.3}]
    d["base"] = {"thickness": 2.0, "poisson": 0.2, "age_at_loading": 28.0,
                 "creep": {"model": "elastic", "modulus": 3e10}}
    d["loading"] = {"force": 5e5, "moment": 0.0}
    d["times"] = {"end": 365.0, "count": 3, "spacing": "linear"}
    d["solver"] = {"tol": 1e-3}
    return d


def test_an_elastic_lift_off_of_many_zones_stops_at_its_bound_naming_the_shape():
    """A half-width of 28 m under the wave (47 zones, dense systems of 3000-5800 nodes,
    Broyden steps on 93 ends) ran over 12 minutes: the elastic zone solves did not check
    the bound (found by the property test's widget values)."""
    with work_bound(1.0), pytest.raises(ValueError) as refused:
        solve(_wavy_punch(28.3))
    message = str(refused.value)
    assert message.startswith("punch.shape: the solve was stopped after 1 s of CPU time")
    assert "locating the ends of" in message and "contact zone(s)" in message


def test_the_default_bound_is_the_limit_of_one_solve():
    assert MAX_SOLVE_CPU_SECONDS == 60.0
    d = _sine_tilt_on_creep()
    d["loading"]["tilt"]["amplitude"] = 1e-5  # stays in contact: 0.1 s
    with work_bound(None):  # no bound of its own: the default one of solve holds
        assert solve(d).info["contact"] == "full"


def test_the_bound_changes_no_answer():
    d = scene_file("eccentric_creep")
    free = solve(d)
    with work_bound(MAX_SOLVE_CPU_SECONDS):
        bounded = solve(d)
    for name in ("settlement", "tilt", "force", "moment"):
        assert np.array_equal(getattr(free, name), getattr(bounded, name))


def test_nested_bounds_keep_the_tighter_and_threads_their_own():
    check_work("nothing")  # no bound: nothing happens
    with work_bound(0.0):
        with work_bound(100.0), pytest.raises(WorkLimitExceeded, match="spinning"):
            while True:
                check_work("spinning")
        seen = []

        def other_thread() -> None:
            check_work("another solve")  # not bounded by this thread's bound
            seen.append(True)

        thread = threading.Thread(target=other_thread)
        thread.start()
        thread.join()
        assert seen == [True]


def test_a_solve_no_longer_wanted_stops_with_its_own_error():
    """A cancelled solve (a newer request of the same user superseded it) stops at its
    next check, mid-way, with an error no level of the solver words as a refusal."""
    asked = [0]

    def cancelled() -> bool:
        asked[0] += 1
        return asked[0] > 20  # after 20 checks: well inside the solve

    with work_bound(30.0), cancellable(cancelled), pytest.raises(SolveCancelled) as stopped:
        solve(_sine_tilt_on_creep())
    assert asked[0] == 21
    assert "following the contact zones under creep" in str(stopped.value)
    # outside, nothing is cancelled
    check_work("nothing")


def test_lift_off_under_creep_at_many_crests_stops_naming_the_shape():
    """The lift-off preset under a wavy punch (a 10 um wave of 10 mm: 34-51 zones) ran 64 s
    to its bound, reaching 1.9 GiB (3.8 GiB at 100 um), and the message named solver.tol:
    the zones' ends were corrected every end against every output time's cut panels.
    Its marches start after ~1.2 s of CPU (the wave sampled, the engine prepared), so the
    bound here is 3 s."""
    d = scene_file("eccentric_footing_liftoff")
    d["punch"]["shape"] = {"kind": "sine", "mean": 0.0, "amplitude": 1e-5,
                           "wavelength": 0.01, "phase": 0.0}
    with work_bound(3.0), pytest.raises(ValueError) as refused:
        solve(d)
    message = str(refused.value)
    assert message.startswith("punch.shape: the solve was stopped after 3 s of CPU time")
    assert "contact zone" in message


def test_several_punches_at_many_crests_stop_naming_the_shape() -> None:
    """The same for two punches, one of them wavy: the message named
    punches[0].loading... or punches, not the shape that made the zones."""
    d = scene_file("new_footing_beside_old")
    d["punches"][1]["shape"] = {"kind": "sine", "mean": 0.0, "amplitude": 1e-5,
                                "wavelength": 0.01, "phase": 0.0}
    d["solver"] = {**d.get("solver", {}), "contact": "unilateral"}
    with work_bound(3.0), pytest.raises(ValueError) as refused:
        solve(d)
    assert str(refused.value).startswith(
        "punches[1].shape: the solve was stopped after 3 s of CPU time"), refused.value
