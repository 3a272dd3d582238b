"""A load that oscillates faster than the output times sample it is flagged: the answer is
right at each output time, but a sine force of period 10 days (the page's default period)
over 40 output times a year was drawn as 2.5 slow swings where it makes 36.5, and the
largest values read at the output times (the design check's) can miss its peaks, unsaid."""

from __future__ import annotations

import numpy as np

from core.profiles import profile_from_spec
from core.scene import FLAG_MESSAGES, solve
from core.scene.load_rates import SAMPLES_PER_PERIOD, undersampled_loads
from tests.conftest import scene_file


def _sine_force(wavelength: float, count: int, spacing: str = "linear") -> dict:
    d = scene_file("uniform_flat")
    d["loading"]["force"] = {"kind": "sine", "mean": 5e5, "amplitude": 1e5,
                             "wavelength": wavelength}
    d["times"] = {"end": 365.0, "count": count, "spacing": spacing}
    return d


def test_a_sine_load_sampled_too_sparsely_is_flagged_and_named() -> None:
    result = solve(_sine_force(10.0, 40))  # the page's default period; 9.4 days apart
    assert "undersampled_load" in result.flags
    assert result.info["undersampled_loads"] == ["loading.force"]
    assert "times.count" in result.flag_messages["undersampled_load"]
    assert FLAG_MESSAGES["undersampled_load"] == result.flag_messages["undersampled_load"]
    # what the flag warns of: drawn through the output times, the force crosses its mean
    # 6 times where it does 73 (aliased to a slow wave)
    crossings = np.count_nonzero(np.diff(np.sign(result.force - 5e5)) != 0)
    assert crossings == 6
    finer = solve(_sine_force(10.0, 313))  # 1.17 days apart: 8.5 per period
    assert "undersampled_load" not in finer.flags
    assert np.count_nonzero(np.diff(np.sign(finer.force - 5e5)) != 0) >= 72


def test_a_sine_of_amplitude_zero_is_no_oscillation() -> None:
    """The page's sine starts at the amplitude it had (0 from a constant): a constant
    load, flagged as aliased (a teacher's audit)."""
    d = _sine_force(10.0, 40)
    d["loading"]["force"]["amplitude"] = 0.0
    assert "undersampled_load" not in solve(d).flags


def test_log_spacing_is_judged_at_its_widest_spacing() -> None:
    """Dense early, 40 log-spaced times are 68 days apart at the end."""
    assert "undersampled_load" in solve(_sine_force(300.0, 40, "log")).flags
    assert "undersampled_load" not in solve(_sine_force(300.0, 40, "linear")).flags


def test_the_bound_is_eight_output_times_per_period() -> None:
    sine = profile_from_spec({"kind": "sine", "mean": 1.0, "amplitude": 0.5,
                              "wavelength": 8.0}, field="loading.force", variable="t",
                             domain=(0.0, 80.0))
    steady = profile_from_spec(1.0, field="loading.moment", variable="t", domain=(0.0, 80.0))
    loads = {"loading.force": sine, "loading.moment": steady}
    assert SAMPLES_PER_PERIOD == 8
    assert undersampled_loads(loads, np.linspace(0.0, 80.0, 81)) == []  # 1 day apart
    assert undersampled_loads(loads, np.linspace(0.0, 80.0, 80)) == ["loading.force"]
    assert undersampled_loads(loads, np.array([80.0])) == []  # one time: nothing drawn


def test_the_page_shows_it_beside_the_histories(explorer_app) -> None:
    from explorer.views import badges_html

    app = explorer_app(scene=_sine_force(10.0, 40), solved=True)
    badges = badges_html(app.screen.shown(), "history")
    assert "flag-undersampled_load" in badges and "Time tab: more output times" in badges


def test_a_sine_chosen_on_the_page_starts_with_an_amplitude() -> None:
    """Chosen after a constant, the page's sine took the constant's "second" value, 0: no
    sine at all. It starts at SINE_SHARE of its mean; a file's sine of amplitude 0, or a
    second value set before, is kept."""
    from explorer.model.loading_state import SINE_SHARE, HistoryState

    force = HistoryState("force", value=500.0, name="force")
    force.kind = "sine"
    assert force.second == SINE_SHARE * 500.0 and force.to_spec()["amplitude"] == 1e5
    filed = HistoryState("force", value=500.0, name="filed")
    filed.load_spec({"kind": "sine", "mean": 5e5, "amplitude": 0.0, "wavelength": 10.0,
                     "phase": 0.0})
    assert filed.kind == "sine" and filed.second == 0.0
    ramped = HistoryState("force", value=500.0, name="ramped")
    ramped.kind, ramped.second = "ramp", 100.0
    ramped.kind = "sine"
    assert ramped.second == 100.0
