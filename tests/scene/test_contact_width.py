"""The contact width and the lift-off length: one definition (the length of the contact
set, :mod:`core.scene.contact_zone`) read the same from every output of an answer: the
``SceneSolution`` attributes, ``to_xarray``, ``to_dataframe``, the CSV histories and
the ``repr`` (the report: tests/report; a study: tests/study; the explorer:
tests/explorer). The lift-off preset at M = 480 kN m/m
touches on [-0.3486, 1] m at 1000 days: 1.3486 m of the 2 m, where the pressure is >= 0
(q = 0 on the lifted heel) over the whole base."""

from __future__ import annotations

import numpy as np
import pytest

from core.scene import SceneSolution, contact_width, lift_off_length, lifts_off, solve
from tests.conftest import scene_file

#: The lift-off preset's contact zone at 1000 days [m], as core.solve gives it
#: (-0.34864037417663657, 1.0): 1.3486 m in contact, 0.6514 m lifted off.
LAST_WIDTH = 1.3486
#: Digits of the figures above: 5e-5 m (the zone end's tolerance is 1e-6 a).
DIGITS = 5e-5


@pytest.fixture(scope="module")
def lift_off() -> SceneSolution:
    """The lift-off preset as shipped (``auto``: the unilateral model answers)."""
    return solve(scene_file("eccentric_footing_liftoff"))


@pytest.fixture(scope="module")
def pulled() -> SceneSolution:
    """The lift-off preset under the full-contact model: flagged ``contact_lost``."""
    scene = scene_file("eccentric_footing_liftoff")
    scene["times"] = {"end": 100.0, "count": 4, "spacing": "log"}
    scene["solver"]["contact"] = "full"
    return solve(scene)


def test_the_width_is_the_length_of_the_contact_zones() -> None:
    a = 1.5
    # the last: overlapping zones, one past the edge, counted once and within [-a, a]
    zones = [[(-a, a)], [(-0.5, 1.5)], [(-1.5, -1.0), (0.0, 1.5)], [],
             [(0.0, 1.0), (0.5, 2.0)]]
    np.testing.assert_array_equal(contact_width(zones, a), [3.0, 2.0, 2.0, 0.0, 1.5])
    np.testing.assert_array_equal(lift_off_length(zones, a), [0.0, 1.0, 1.0, 3.0, 1.5])
    np.testing.assert_array_equal(lifts_off(zones, a), [False, True, True, True, True])
    # a zone end a rounding error inside the edge is full contact, not a lift-off
    assert not lifts_off([[(-a * (1 - 1e-15), a)]], a)[0]
    assert contact_width([], a).shape == (0,)


def test_a_lift_off_answer_has_the_width_of_its_contact_set(lift_off: SceneSolution) -> None:
    a = lift_off.scene.half_width
    assert lift_off.info["contact"] == "unilateral"
    assert lift_off.contact_set[-1][0][0] == pytest.approx(-0.3486, abs=DIGITS)
    widths = lift_off.contact_width
    want = [sum(hi - lo for lo, hi in zones) for zones in lift_off.contact_set]
    np.testing.assert_array_equal(widths, want)
    assert widths[-1] == pytest.approx(LAST_WIDTH, abs=DIGITS)
    np.testing.assert_array_equal(lift_off.lift_off_length, 2 * a - widths)
    # the pressure's sign would count the lifted heel (q = 0 there) as contact
    assert np.min(lift_off.pressure_on_grid) == 0.0


def test_every_output_of_the_answer_gives_that_width(lift_off: SceneSolution) -> None:
    import pandas  # noqa: F401  (installed by the test set-up)
    import xarray  # noqa: F401  (installed by the test set-up)
    widths = lift_off.contact_width
    np.testing.assert_array_equal(lift_off.to_xarray().contact_width.values, widths)
    np.testing.assert_array_equal(lift_off.to_dataframe()["contact_width"].to_numpy(), widths)
    lines = lift_off.to_csv(header=False).splitlines()
    column = lines[0].split(",").index("contact_length_m")
    np.testing.assert_array_equal([float(line.split(",")[column]) for line in lines[1:]],
                                  widths)
    assert f"contact width {widths[-1]:.4g} m of 2a = 2 m (lift-off" in repr(lift_off)


def test_a_full_contact_answer_that_pulls_keeps_the_whole_width(pulled: SceneSolution
                                                                ) -> None:
    """The full-contact model keeps the whole base in contact: its width is 2a, and the
    flag contact_lost (q < 0) marks the answer as not physical."""
    import xarray  # noqa: F401  (installed by the test set-up)
    a = pulled.scene.half_width
    assert "contact_lost" in pulled.flags and np.min(pulled.pressure_on_grid) < 0
    np.testing.assert_array_equal(pulled.contact_width, 2 * a)
    np.testing.assert_array_equal(pulled.lift_off_length, 0.0)
    np.testing.assert_array_equal(pulled.to_xarray().contact_width.values, 2 * a)
    assert "contact width" not in repr(pulled)  # nothing lifts off


def test_a_contact_shrinking_to_a_point_is_never_a_success() -> None:
    """The lift-off preset at e = 0.9999 a: the unilateral solver finds the contact
    shrinking to a point and refuses; the full-contact answer that is left (q < 0, the
    flag contact_lost) is not this scene's answer, so it is no success, and says why.
    (It was a success: its estimate, 1e-7, met tol.)"""
    from core.presets import read_preset

    scene = read_preset("eccentric_footing_liftoff")
    scene["loading"] = {"force": 8e5, "moment": 8e5 * 0.9999}
    scene["solver"] = {"tol": 1e-6}
    result = solve(scene)
    assert result.info["contact"] == "full" and "contact_lost" in result.flags
    assert result.info["success"] is False
    assert "shrinks to a point" in result.info["unilateral_refused"]
    assert "unilateral contact refused" in result.info["message"]


def test_the_narrowest_zone_is_over_every_zone_and_time() -> None:
    from core.scene import narrowest_zone

    assert narrowest_zone([[(-1.0, 1.0)], [(-1.0, 1.0)]], 1.0) is None
    assert narrowest_zone([[(-1.0, 1.0)], [(-0.5, 1.0)], [(-1.0, -0.8), (0.2, 1.0)]],
                          1.0) == pytest.approx(0.2)
    assert narrowest_zone([[(-1.0, 1.0 - 1e-12)]], 1.0) is None  # rounding: full contact
