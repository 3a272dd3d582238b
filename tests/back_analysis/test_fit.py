"""The back-analysis: exact readings give the exact fields, a degenerate pair is reported
as not identifiable, and the stated standard errors hold in ~95 % of noise draws."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import core
from core.back_analysis import Calibration, calibrate
from core.limits import MAX_FIT_PARAMETERS
from core.study import apply_point
from tests.support.creeping_footing import creeping_footing

#: The scene fitted (tests/support/creeping_footing.py).
SCENE = creeping_footing()
TRUTH = {"base.creep.compliance": 3e-9, "base.creep.rate": 0.02, "loading.force": 2e5}
TIMES = np.linspace(365 / 30, 365, 30)
#: Noise of the synthetic readings: ~1 % of the settlement (1.3 mm) and of the tilt.
SETTLEMENT_STD = 1e-5
TILT_STD = 1e-6


def _exact() -> core.SceneSolution:
    scene = apply_point(SCENE, TRUTH)
    scene["times"] = TIMES.tolist()
    return core.solve(scene)


def _noisy(exact: core.SceneSolution, rng: np.random.Generator) -> dict:
    """Readings of ``exact``'s settlements and tilts with normal noise of the stated
    deviations (drawn from ``rng``: the settlements first, then the tilts)."""
    return {"time": TIMES.tolist(),
            "settlement": (exact.settlement
                           + SETTLEMENT_STD * rng.standard_normal(TIMES.size)).tolist(),
            "settlement_std": SETTLEMENT_STD,
            "tilt": (exact.tilt + TILT_STD * rng.standard_normal(TIMES.size)).tolist(),
            "tilt_std": TILT_STD}


def test_exact_readings_give_the_exact_fields() -> None:
    exact = _exact()
    start = apply_point(SCENE, {path: 1.3 * v for path, v in TRUTH.items()})
    fit = calibrate(start, {"time": TIMES.tolist(), "settlement": exact.settlement.tolist()},
                    fit=list(TRUTH))
    assert isinstance(fit, Calibration)
    # measured: relative errors below 1e-11 (the readings are the working scene's
    # answers, so only the least-squares tolerance X_TOL = 1e-8 bounds them)
    for path, value in TRUTH.items():
        assert fit.values[path] == pytest.approx(value, rel=1e-7)
    # the residuals are at the solver's level: the fit says its errors are the solver's
    assert any("solver's error estimate" in w for w in fit.warnings)
    assert fit.scene.to_dict()["base"]["creep"]["rate"] == pytest.approx(0.02, rel=1e-7)
    assert fit.scene.to_dict()["times"]["end"] == 3650.0  # the scene's own times


def test_result_serialises_with_units_and_forecasts_a_band() -> None:
    exact = _exact()
    readings = _noisy(exact, np.random.default_rng(7))
    fit = calibrate(SCENE, readings, fit=["base.creep.compliance", "base.creep.rate"],
                    bounds={"base.creep.rate": (1e-3, 1.0)})
    assert fit.identifiable and fit.std_given
    d = json.loads(json.dumps(fit.to_dict(), allow_nan=False))
    assert d["fields"][1]["unit"] == "1/day" and d["fields"][1]["bounds"] == [1e-3, 1.0]
    assert d["readings"]["units"]["tilt_residual"] == "rad"
    assert set(fit.standard_errors) == set(fit.values) == set(fit.paths)
    assert fit.correlation.shape == (2, 2)
    assert "base.creep.rate" in fit.summary()
    band = fit.forecast([0.0, 365.0, 3650.0])
    assert band.times.tolist() == [0.0, 365.0, 3650.0]
    lower, upper = band.band("settlement")
    assert np.all(lower <= band.settlement) and np.all(band.settlement <= upper)
    # the creep at ten years is extrapolated: its band is wider than at loading
    assert band.settlement_std[-1] > band.settlement_std[0]
    json.dumps(band.to_dict(), allow_nan=False)


def test_core_calibrate_is_the_function_once_its_package_is_imported() -> None:
    import core.back_analysis as package

    readings = {"time": TIMES.tolist(), "settlement": _exact().settlement.tolist()}
    fit = core.calibrate(SCENE, readings, fit=["loading.force"])
    assert core.calibrate is package.calibrate
    assert package.calibrate.__module__ == "core.back_analysis.fit"
    assert fit.values["loading.force"] == pytest.approx(2e5, rel=1e-6)


def test_a_degenerate_pair_is_not_identifiable() -> None:
    # the thin coating enters through h / E alone: the readings fix the ratio only
    scene = dict(SCENE, times=TIMES.tolist())
    exact = core.solve(scene)
    start = apply_point(SCENE, {"coating[0].modulus": 3e8})
    fit = calibrate(start, {"time": TIMES.tolist(), "settlement": exact.settlement.tolist()},
                    fit=["coating[0].thickness", "coating[0].modulus"])
    assert not fit.identifiable
    assert any(w.startswith("not identifiable") for w in fit.warnings), fit.warnings
    assert set(fit.unidentified) == {"coating[0].thickness", "coating[0].modulus"}



def test_a_degenerate_pair_stops_once_the_combination_the_readings_fix_has_settled() -> None:
    """The readings fix h / E of the thin coating: the fit of both stops when the step
    along that combination is below STEP_TO_SE of its standard error, with that ratio the
    one the modulus alone fits, and neither field far from its start. Before, it ran on to
    X_TOL (55 solves), its first step taking the 20 mm coating to 20 km (the least-squares
    solver's first trust radius was the size of the logarithm of the start; it is 1 now),
    and ended at 360,000 km; now 11 solves."""
    import core.back_analysis.fit as fit_module

    exact = core.solve(dict(SCENE, times=TIMES.tolist()))
    rng = np.random.default_rng(3)
    readings = {"time": TIMES.tolist(), "settlement_std": SETTLEMENT_STD,
                "settlement": (exact.settlement
                               + SETTLEMENT_STD * rng.standard_normal(TIMES.size)).tolist()}
    one = calibrate(SCENE, readings, fit=["coating[0].modulus"])
    both = calibrate(SCENE, readings, fit=["coating[0].thickness", "coating[0].modulus"])
    assert not both.identifiable
    ratio_one = SCENE["coating"][0]["thickness"] / one.values["coating[0].modulus"]
    ratio_both = both.values["coating[0].thickness"] / both.values["coating[0].modulus"]
    relative_se = one.standard_errors["coating[0].modulus"] / one.values["coating[0].modulus"]
    # each fit stops within ~STEP_TO_SE standard errors of its minimum (measured 7e-4
    # standard errors apart)
    assert abs(ratio_both / ratio_one - 1.0) <= 2 * fit_module.STEP_TO_SE * relative_se
    if fit_module.STOPS_SETTLED:
        assert both.status == fit_module.SETTLED_DETERMINED
        assert both.solves <= 15
    # measured 0.81 and 0.77 (a factor 2.3 and 2.2: where the first steps along the
    # determined combination took them)
    for path, start in (("coating[0].thickness", 0.02), ("coating[0].modulus", 2e8)):
        assert abs(np.log(both.values[path] / start)) <= 1.5

@pytest.mark.parametrize(("kwargs", "message"), [
    ({"fit": ["coating[3].modulus"]}, "fit[0]: coating[3].modulus: no such field"),
    ({"fit": ["name"]}, "fit[0]: 'name' cannot be fitted"),
    ({"fit": ["base.creep.model"]}, "fit[0]: 'base.creep.model' holds 'exponential'"),
    ({"fit": ["loading.force", "loading.force"]}, "fit[1]: 'loading.force' is fitted twice"),
    ({"fit": ["loading.force"] * (MAX_FIT_PARAMETERS + 1)}, "fit: must be a list of 1 to 8"),
    ({"fit": ["loading.force"], "bounds": {"loading.force": (3e5, 4e5)}},
     "bounds[loading.force]: the scene's value 200000 (the start of the fit) is outside"),
    ({"fit": ["loading.force"], "bounds": {"loading.moment": (0, 1)}},
     "bounds[loading.moment]: not one of the fitted fields"),
    ({"fit": ["loading.force"], "bounds": {"loading.force": (5, 1)}},
     "bounds[loading.force]: high (1) must exceed low (5)"),
    # the solver's tolerance read "solver.tol = 7.77e-07 +/- 31"
    ({"fit": ["solver.tol"]}, "fit[0]: 'solver.tol' cannot be fitted (the solver's"),
    # a reading past the scene's last time was named as one of the scene's times
    ({"fit": ["loading.force"], "measurements": {"time": [10.0, 20.0, 2e5],
                                                 "settlement": [1e-3, 1.1e-3, 1.2e-3]}},
     "measurements: time[2]: must be <= 100000 days after loading"),
])
def test_bad_fits_are_named(kwargs: dict, message: str) -> None:
    kwargs = {"measurements": {"time": [10.0, 20.0, 30.0],
                               "settlement": [1e-3, 1.1e-3, 1.2e-3]}} | kwargs
    with pytest.raises(ValueError) as info:
        calibrate(SCENE, **kwargs)
    assert str(info.value).startswith(message), str(info.value)


def test_both_series_need_their_deviations() -> None:
    with pytest.raises(ValueError, match="^tilt_std: required when both"):
        calibrate(SCENE, {"time": [1.0, 2.0, 3.0], "settlement": [1e-3] * 3,
                          "settlement_std": 1e-4, "tilt": [1e-4] * 3}, fit=["loading.force"])


@pytest.mark.slow
def test_standard_errors_cover_the_truth_in_95_percent_of_draws() -> None:
    # 100 noise draws of settlements and tilts with stated deviations; each fit starts at
    # the truth (what is tested is the spread of the answers, not the way there). A
    # nominal 95 % interval covers in 95 % +/- 2.2 % (binomial, 100 draws): the accepted
    # [90 %, 99 %] is -2.3 and +1.8 of those (a chance failure of a right answer: 1.2 %
    # below, 0.6 % above). Measured on this seed 0.98 and 0.96 (and 0.93 / 0.97, 0.95 /
    # 0.96 on seeds 1 and 2; the same on this seed with the fit's relative-offset stop,
    # 8.6 solves a fit against ~11.4 run on to X_TOL). The scene is solved at tol 1e-4,
    # four orders below the readings' noise (1 %), where a fit costs ~0.35 s of CPU
    # instead of ~0.5 s at 1e-6 (200 draws at 1e-6 took 100-170 s of the suite).
    scene = dict(SCENE, solver={"tol": 1e-4})
    exact = core.solve(apply_point(scene, TRUTH) | {"times": TIMES.tolist()})
    rng = np.random.default_rng(20261129)
    paths = ["base.creep.compliance", "base.creep.rate"]
    hits = np.zeros(len(paths))
    draws = 100
    for _ in range(draws):
        fit = calibrate(scene, _noisy(exact, rng), fit=paths)
        for j, path in enumerate(paths):
            hits[j] += abs(fit.values[path] - TRUTH[path]) <= 1.96 * fit.standard_errors[path]
    coverage = hits / draws
    assert np.all((0.90 <= coverage) & (coverage <= 0.99)), coverage


def test_a_fit_stops_once_its_step_is_far_inside_the_standard_errors(monkeypatch) -> None:
    """Each iteration costs 1 + p solves: the fit stops when the Gauss-Newton step is
    below 1e-3 of every standard error instead of running on to X_TOL. The answer run on
    to X_TOL is the reference: measured 2.4e-4 standard errors away at most on 12 draws
    (the bound 1e-3 is the criterion itself: a first-order distance to the minimum)."""
    import core.back_analysis.fit as fit_module

    exact = _exact()
    readings = _noisy(exact, np.random.default_rng(11))
    paths = ["base.creep.compliance", "base.creep.rate"]
    fit = calibrate(SCENE, readings, fit=paths)
    assert not fit.warnings
    monkeypatch.setattr(fit_module, "STEP_TO_SE", 0.0)
    full = calibrate(SCENE, readings, fit=paths)
    assert "xtol" in full.status or "ftol" in full.status
    if fit_module.STOPS_SETTLED:
        assert fit.status == fit_module.SETTLED and fit.solves < full.solves
    else:  # SciPy < 1.16 (pyproject allows 1.10): no callback, the fit runs on as before
        assert fit.status == full.status and fit.solves == full.solves
    for path in paths:
        assert abs(fit.values[path] - full.values[path]) <= 1e-3 * full.standard_errors[path]
        assert fit.standard_errors[path] == pytest.approx(full.standard_errors[path], rel=1e-3)


def test_a_fit_pickles_and_its_copy_answers_the_same() -> None:
    """The explorer writes a report with the fit in a worker process: the fit is sent
    there by pickle, its caches (answers, validated scenes) left behind."""
    import pickle

    exact = _exact()
    fit = calibrate(SCENE, {"time": TIMES.tolist(), "settlement": exact.settlement.tolist()},
                    fit=["base.creep.rate"])
    fit.scene  # noqa: B018 - a cached Scene must not stop the pickle
    fit.solution  # noqa: B018
    copy = pickle.loads(pickle.dumps(fit))
    assert copy.values == fit.values and copy.standard_errors == fit.standard_errors
    assert copy.scene.to_dict() == fit.scene.to_dict()
    np.testing.assert_array_equal(copy.forecast([1.0, 3650.0]).settlement,
                                  fit.forecast([1.0, 3650.0]).settlement)


def test_a_fit_pushed_to_the_edge_of_the_accepted_values_says_so() -> None:
    """Readings of half the force, fitted by the base's Poisson ratio alone: the stiffest
    base the scene accepts (nu -> 0.5) is still too soft, so the fit ends at the edge of
    the accepted values. Its difference steps turn back there (they once crashed with
    the scene's refusal), and the answer is flagged as not identified although no bound
    was given."""
    times = np.linspace(365 / 30, 365, 30)
    half = apply_point(SCENE, {"loading.force": 0.5 * SCENE["loading"]["force"]})
    settled = core.solve(half | {"times": times.tolist()}).settlement
    fit = calibrate(SCENE, {"time": times.tolist(), "settlement": settled.tolist()},
                    fit=["base.poisson"])
    assert fit.values["base.poisson"] == pytest.approx(0.5, abs=1e-3)
    assert fit.unidentified == ("base.poisson",) and not fit.identifiable
    assert any("edge of the values the scene accepts" in w and "must be in (-1, 0.5)" in w
               for w in fit.warnings)


def test_a_linear_load_history_keeps_its_own_span_at_the_reading_times() -> None:
    """A ``linear`` load runs to its end value at the scene's last output time. The fit
    solves at the reading times and the forecast at its own: both once stretched the
    history over their span (a force rising from 100 to 500 kN/m over a year reached
    500 kN/m at the last reading, at half a year), and exact readings fitted from the
    truth gave a compliance 15 times too small. Now the readings of the scene's first
    half year give the truth back (measured 1.7e-15 relative: the working scene is the
    scene), and the forecast at the scene's own times is the scene's answer."""
    scene = dict(SCENE, loading={"force": {"kind": "linear", "start": 1e5, "end": 5e5},
                                 "moment": SCENE["loading"]["moment"]})
    scene["times"] = {"end": 365.0, "count": 40, "spacing": "linear"}
    own = core.solve(scene)
    half = (own.times > 0) & (own.times <= 190)
    readings = {"time": own.times[half].tolist(), "settlement": own.settlement[half].tolist()}
    fit = calibrate(scene, readings, fit=["base.creep.compliance"])
    assert fit.values["base.creep.compliance"] == pytest.approx(
        scene["base"]["creep"]["compliance"], rel=1e-9)
    np.testing.assert_allclose(fit.solution.force, own.force[half], rtol=1e-12)
    # the fitted scene is the scene itself, its linear history as given
    assert fit.scene.to_dict()["loading"]["force"]["kind"] == "linear"
    band = fit.forecast([100.0, 365.0])
    np.testing.assert_allclose(band.solution.force, [1e5 + 4e5 * 100 / 365, 5e5],
                               rtol=1e-12)
    np.testing.assert_allclose(band.settlement[-1], own.settlement[-1], rtol=1e-9)
    # past the scene's last time the history is held at its end, as a table's is
    later = fit.forecast([365.0, 730.0])
    np.testing.assert_allclose(later.solution.force, [5e5, 5e5], rtol=1e-12)


def test_a_linear_load_is_pinned_to_its_span_when_the_output_times_change() -> None:
    from core.scene import at_output_times

    scene = dict(SCENE, loading={"force": {"kind": "linear", "start": 1e5, "end": 5e5},
                                 "moment": SCENE["loading"]["moment"]})
    scene["times"] = [10.0, 200.0]
    moved = at_output_times(scene, [50.0, 100.0])
    assert moved["times"] == [50.0, 100.0]
    assert moved["loading"]["force"] == {"kind": "table", "interpolation": "linear",
                                         "points": [[0.0, 1e5], [200.0, 5e5]]}
    assert moved["loading"]["moment"] == scene["loading"]["moment"]
    np.testing.assert_allclose(core.solve(moved).force, [2e5, 3e5], rtol=1e-12)


def test_the_interval_factor_is_students_t_where_the_noise_is_estimated() -> None:
    from core.back_analysis import quantile

    assert quantile(0.95) == pytest.approx(1.959964, abs=1e-6)
    assert quantile(0.95, 3) == pytest.approx(3.182446, abs=1e-6)  # tables of t
    assert quantile(0.95, 10 ** 6) == pytest.approx(quantile(0.95), abs=1e-5)
    exact = _exact()
    times = TIMES[:4].tolist()
    estimated = calibrate(SCENE, {"time": times, "settlement": exact.settlement[:4].tolist()},
                          fit=["loading.force"])
    given = calibrate(SCENE, {"time": times, "settlement": exact.settlement[:4].tolist(),
                              "settlement_std": SETTLEMENT_STD}, fit=["loading.force"])
    assert estimated.dof == 3 and not estimated.std_given and given.std_given
    assert estimated.forecast([100.0]).z == pytest.approx(quantile(0.95, 3))
    assert given.forecast([100.0]).z == pytest.approx(quantile(0.95))
    for fit in (estimated, given):
        low, high = fit.intervals()["loading.force"]
        value = fit.values["loading.force"]
        assert low < value < high
        assert fit.to_dict()["fields"][0]["interval_95"] == pytest.approx([low, high])
        assert "95 % interval" in fit.summary()


@pytest.mark.slow
def test_intervals_and_bands_cover_at_their_level_from_four_readings() -> None:
    """Four readings without deviations, one field (the force, on which the settlement
    depends linearly): the noise estimated from 3 degrees of freedom scatters, and
    ``value -/+ 1.96 se`` covered the truth in 85.5 % of draws (P(|t_3| < 1.96)); the
    interval and the forecast's band with Student's t cover in 95 %. 400 draws: a right
    answer's coverage is 95 % +/- 1.1 % (binomial), and [92 %, 98 %] is ~2.75 of those
    each side (a chance failure 0.6 %); measured on this seed 0.953 and 0.955 (the
    normal factor 0.865). ~10 ms a fit."""
    scene = dict(SCENE, solver={"tol": 1e-4})
    times = [30.0, 90.0, 180.0, 365.0]
    exact = core.solve(apply_point(scene, TRUTH) | {"times": times})
    rng = np.random.default_rng(20261206)
    draws, interval, band, normal = 400, 0, 0, 0
    for _ in range(draws):
        noisy = exact.settlement * (1 + 0.01 * rng.standard_normal(len(times)))
        fit = calibrate(scene, {"time": times, "settlement": noisy.tolist()},
                        fit=["loading.force"])
        low, high = fit.intervals()["loading.force"]
        interval += low <= TRUTH["loading.force"] <= high
        normal += (abs(fit.values["loading.force"] - TRUTH["loading.force"])
                   <= 1.96 * fit.standard_errors["loading.force"])
        lower, upper = fit.forecast([365.0]).band("settlement")
        band += lower[0] <= exact.settlement[-1] <= upper[0]
    assert 0.92 <= interval / draws <= 0.98, interval / draws
    assert 0.92 <= band / draws <= 0.98, band / draws
    assert normal / draws < 0.9, normal / draws  # what the normal factor gave


def test_a_scene_of_several_punches_is_refused_in_one_line() -> None:
    readings = {"time": [10.0, 20.0, 30.0], "settlement": [1e-3, 1.1e-3, 1.2e-3]}
    for scene in ("preset:new_footing_beside_old",
                  core.load_scene("preset:new_footing_beside_old"),
                  core.load_scene("preset:new_footing_beside_old").to_dict()):
        with pytest.raises(ValueError) as info:
            calibrate(scene, readings, fit=["base.poisson"])
        assert str(info.value) == ("scene: holds 2 punches (punches); a fit takes a scene of "
                                   "one punch, whose readings are its settlement and tilt")


def test_a_scene_is_given_as_core_solve_takes_it(tmp_path) -> None:
    """A preset's name or a scene file's path, as ``core.solve`` takes them."""
    readings = {"time": [10.0, 20.0, 30.0], "settlement": [2e-5, 2.1e-5, 2.2e-5]}
    by_name = calibrate("preset:uniform_flat", readings, fit=["loading.force"])
    path = tmp_path / "scene.json"
    core.save_scene(core.load_scene("preset:uniform_flat"), path)
    by_path = calibrate(path, readings, fit=["loading.force"])
    assert by_name.values == by_path.values
    with pytest.raises(ValueError, match="^scene: must be a JSON object, got 3"):
        calibrate(3, readings, fit=["loading.force"])


def test_the_end_of_a_linear_load_history_is_fitted_on_its_own_span() -> None:
    """``loading.force.end`` of a ``linear`` history: the values are set on the scene at
    its own times, then the reading times (pinning the history first refused the path,
    a review found). Exact readings of the first half year give the end back (measured
    1.2e-13 relative), and the forecast at the scene's last time is the scene's."""
    scene = dict(SCENE, loading={"force": {"kind": "linear", "start": 1e5, "end": 5e5},
                                 "moment": SCENE["loading"]["moment"]})
    scene["times"] = {"end": 365.0, "count": 40, "spacing": "linear"}
    own = core.solve(scene)
    half = (own.times > 0) & (own.times <= 190)
    start = dict(scene, loading=dict(scene["loading"], force={"kind": "linear",
                                                               "start": 1e5, "end": 4e5}))
    fit = calibrate(start, {"time": own.times[half].tolist(),
                            "settlement": own.settlement[half].tolist()},
                    fit=["loading.force.end"])
    assert fit.values["loading.force.end"] == pytest.approx(5e5, rel=1e-8)
    band = fit.forecast([365.0])
    np.testing.assert_allclose(band.settlement, own.settlement[-1:], rtol=1e-8)


def test_the_interval_factor_and_level_are_checked_and_recorded() -> None:
    from core.back_analysis import quantile

    for bad, field in (((0.95, 0), "dof"), ((0.95, 2.7), "dof"), ((1.0, None), "level"),
                       (("high", None), "level"), ((float("nan"), 3), "level")):
        with pytest.raises(ValueError, match=f"^{field}: "):
            quantile(*bad)
    exact = _exact()
    fit = calibrate(SCENE, {"time": TIMES[:4].tolist(),
                            "settlement": exact.settlement[:4].tolist()}, fit=["loading.force"])
    with pytest.raises(ValueError, match="^level: must be a number in"):
        fit.intervals("high")
    d = fit.forecast([100.0]).to_dict()
    assert d["dof"] == 3 and d["z"] == pytest.approx(quantile(0.95, 3))


def test_a_scene_of_one_punch_written_as_punches_is_refused_saying_how_to_write_it() -> None:
    one = core.load_scene("preset:new_footing_beside_old").to_dict()
    one["punches"] = one["punches"][:1]
    with pytest.raises(ValueError) as info:
        calibrate(one, {"time": [10.0, 20.0, 30.0], "settlement": [1e-3, 1.1e-3, 1.2e-3]},
                  fit=["base.poisson"])
    assert str(info.value) == ("scene: is written in the form of several punches (punches); "
                               "a fit takes a scene of one punch written with punch and "
                               "loading")


#: Readings of the shipped creeping coating at seven times, 1 µm of noise.
FLAT_TIMES = [1.0, 3.0, 10.0, 30.0, 100.0, 200.0, 365.0]


def _flat_readings(truth: dict, seed: int) -> dict:
    scene = apply_point(core.load_scene("preset:uniform_flat").to_dict(), truth)
    scene["times"] = FLAT_TIMES
    exact = core.solve(scene)
    rng = np.random.default_rng(seed)
    return {"time": FLAT_TIMES,
            "settlement": (exact.settlement + 1e-6 * rng.standard_normal(7)).tolist()}


def test_the_fitted_value_does_not_depend_on_the_overall_size_of_the_deviations() -> None:
    """Scaling every deviation by one factor moves no least-squares minimum. The
    solver's gradient test was absolute: from a creep rate 500 times too fast (a nearly
    flat start), no deviations (weights of the largest reading, 44 µm) or 44 µm stopped
    the fit at its start, rate 25 +/- 1e11, while 1 µm found 0.047 (measured with the
    absolute test put back). The start was 1000 times too fast before: there the readings
    carry nothing of the rate (its differences of the settlements are the solver's own
    error, ~1e-9 µm, of either sign, whatever the time steps' aim), and the fit found
    0.047 or stopped at 65 as that error's sign fell."""
    readings = _flat_readings({"base.creep.rate": 0.05}, 9)
    start = apply_point(core.load_scene("preset:uniform_flat").to_dict(),
                        {"base.creep.rate": 25.0})
    fits = {std: calibrate(start, readings if std is None else {**readings,
                                                                 "settlement_std": std},
                           fit=["base.creep.rate"]) for std in (None, 1e-6, 4.4e-5)}
    rate = "base.creep.rate"
    ref = fits[1e-6]
    assert ref.values[rate] == pytest.approx(0.0471, abs=1e-4)
    for std, fit in fits.items():
        # each stops within STEP_TO_SE = 1e-3 of its standard error of the minimum
        assert abs(fit.values[rate] - ref.values[rate]) <= 1e-3 * (
            fit.standard_errors[rate] + ref.standard_errors[rate])
        if std is not None:
            # the covariance scales with the deviations squared (measured 0.45 % apart:
            # the linearisation taken at points 1e-3 standard errors apart)
            assert fit.standard_errors[rate] == pytest.approx(
                ref.standard_errors[rate] * std / 1e-6, rel=0.02)
    # the noise estimated from the scatter (7 draws of 1 µm) gives a like error
    assert fits[None].standard_errors[rate] == pytest.approx(ref.standard_errors[rate],
                                                             rel=0.3)


def test_a_field_the_readings_fix_is_not_flagged_for_its_small_influence() -> None:
    """The base's Poisson ratio moves the settlement little (a 0.1 % step of it moves no
    reading by 100 times the solver's tolerance, the old test), yet the readings fix it
    to 14 %: the differences on either side of the step agree to 1e-3 of it (measured),
    so its derivative and its standard error hold."""
    readings = _flat_readings({}, 7)
    start = apply_point(core.load_scene("preset:uniform_flat").to_dict(),
                        {"base.poisson": 0.3})
    fit = calibrate(start, {**readings, "settlement_std": 1e-6}, fit=["base.poisson"])
    assert fit.identifiable and not fit.warnings, fit.warnings
    low, high = fit.intervals()["base.poisson"]
    assert low < 0.2 < high


def test_a_field_whose_derivative_is_noise_is_flagged_with_its_measured_spread(
        monkeypatch) -> None:
    """Where the two sides of a step disagree (here, noise of 1e-4 of the settlement
    added to every solve, as an unresolved solver would give), the field is flagged with
    the measured disagreement, not a bound."""
    from core.back_analysis import model as model_module

    readings = _flat_readings({}, 7)
    start = apply_point(core.load_scene("preset:uniform_flat").to_dict(),
                        {"base.poisson": 0.3})
    values = model_module.Model.values
    rng = np.random.default_rng(3)

    def noisy(self, x):
        v = values(self, x)
        return v * (1.0 + 1e-4 * rng.standard_normal(v.shape))

    monkeypatch.setattr(model_module.Model, "values", noisy)
    fit = calibrate(start, {**readings, "settlement_std": 1e-6}, fit=["base.poisson"])
    assert any(w.startswith("base.poisson: its derivative is not resolved: the "
                            "differences on either side of a step of 0.001 disagree by")
               for w in fit.warnings), fit.warnings
    assert not fit.identifiable


def test_no_chi2_is_shown_where_the_noise_is_estimated_from_the_scatter() -> None:
    """Without deviations the weights' scale is arbitrary (the largest reading) and the
    estimated noise makes chi^2/dof 1 by construction: it read 0.0006, as if the model
    fitted far too well. The estimated noise is shown instead; with deviations chi^2/dof
    tests them."""
    from core.report.content import calibration_section

    readings = _flat_readings({}, 7)
    estimated = calibrate("preset:uniform_flat", readings, fit=["base.creep.rate"])
    assert np.isnan(estimated.chi2_per_dof)
    assert "chi^2" not in estimated.summary()
    assert "noise estimated from the scatter about the fit (6 dof): settlement " in (
        estimated.summary())
    goodness = estimated.to_dict()["goodness_of_fit"]
    assert goodness["chi2"] is None and goodness["chi2_per_dof"] is None
    rows = dict(calibration_section(estimated).rows)
    assert "χ²/dof" not in rows and rows["noise"].startswith("estimated from the scatter")
    stated = calibrate("preset:uniform_flat", {**readings, "settlement_std": 1e-6},
                       fit=["base.creep.rate"])
    assert 0.1 < stated.chi2_per_dof < 3.0  # 7 readings of the stated 1 µm noise
    assert stated.to_dict()["goodness_of_fit"]["chi2_per_dof"] == stated.chi2_per_dof
    assert f"chi^2/dof = {stated.chi2_per_dof:.3g} (6 dof)" in stated.summary()
    assert "χ²/dof" in dict(calibration_section(stated).rows)


def test_one_deviation_as_a_numpy_scalar_or_a_column_as_an_array_like_is_taken() -> None:
    """``settlement_std=np.array(1e-6)`` raised TypeError (len() of unsized object); a
    table's column (anything numpy reads as an array) was refused with its whole text."""

    class Column:  # a table library's column: not a list, read through __array__
        def __init__(self, values):
            self.values = values

        def __array__(self, dtype=None, copy=None):
            return np.asarray(self.values, dtype=dtype)

    readings = _flat_readings({}, 7)
    plain = calibrate("preset:uniform_flat", {**readings, "settlement_std": 1e-6},
                      fit=["base.creep.rate"])
    arrays = calibrate("preset:uniform_flat",
                       {"time": Column(readings["time"]),
                        "settlement": Column(readings["settlement"]),
                        "settlement_std": np.array(1e-6)}, fit=["base.creep.rate"])
    assert arrays.values == plain.values and arrays.standard_errors == plain.standard_errors
    # a masked entry is a row without that reading, never the value under the mask
    from core.back_analysis import readings_from_mapping

    masked = readings_from_mapping({"time": [1.0, 2.0, 3.0],
                                    "settlement": np.ma.masked_array([1e-3, 0.0, 1.2e-3],
                                                                     mask=[0, 1, 0]),
                                    "tilt": [1e-4, 1e-4, 1e-4]})
    assert np.isnan(masked.settlement[1]) and masked.settlement[2] == 1.2e-3


def test_readings_no_field_moves_give_warnings_and_no_numpy_warning() -> None:
    """The tilts of a centred punch are zero whatever its creep: no field moves them. The
    fit returned its start with warnings, and numpy's "invalid value" warnings leaked
    from the covariance (0 * inf) and from the trust region (0 / 0)."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for tilts in ([0.0, 0.0, 0.0], [1e-6, 0.0, 0.0]):
            fit = calibrate("preset:uniform_flat", {"time": [1.0, 10.0, 100.0],
                                                    "tilt": tilts},
                            fit=["base.creep.modulus"])
            assert fit.values["base.creep.modulus"] == pytest.approx(3e10, rel=1e-12)
            assert fit.standard_errors["base.creep.modulus"] == np.inf
            assert not fit.identifiable
            assert "base.creep.modulus: a step of 0.001 either way in its logarithm " \
                   "changes no reading: the readings do not depend on it" in fit.warnings


@pytest.mark.parametrize("bounds", [(1.5e5, 3e5), (1e5, 2.5e5), (0.0, 2.5e5)])
def test_a_fit_may_start_on_a_bound(bounds) -> None:
    """A start on its lower bound was refused for a field fitted by its logarithm and
    taken for the others (and on an upper bound for all): every start on a bound is
    taken, the least-squares solver moving it inside. Exact readings of 2e5 N/m."""
    exact = _exact()
    start = bounds[0] if bounds[0] > 0 else bounds[1]
    fit = calibrate(apply_point(SCENE, {"loading.force": start}),
                    {"time": TIMES.tolist(), "settlement": exact.settlement.tolist()},
                    fit=["loading.force"], bounds={"loading.force": bounds})
    assert fit.values["loading.force"] == pytest.approx(2e5, rel=1e-7)


def test_the_derivative_check_names_what_the_two_sides_say() -> None:
    """Two sides equal and opposite: a turning point (the message said "changes no
    reading", false at second order); both zero: no influence; disagreeing: not
    resolved, with the measured share."""
    from core.back_analysis.fit import _derivative_check
    from core.back_analysis.model import Field
    from core.back_analysis.readings import readings_from_mapping

    field = Field("loading.moment", 0.0, False, 1e5, (-1e5, 1e5), "N")
    readings = readings_from_mapping({"time": [1.0, 2.0], "settlement": [1e-3, 1e-3]})
    solution = type("S", (), {"settlement": np.array([1e-3, 1e-3])})()
    mask = np.ones(2, dtype=bool)

    def said(first, other):
        return _derivative_check([field], np.array(first, float)[:, None],
                                 np.array(other, float)[:, None], np.ones((2, 1)),
                                 solution, readings, mask, 1e-6)

    assert "moves the readings alike: the answer is at a turning point" in said(
        [1.0, 2.0], [-1.0, -2.0])[0]
    assert "changes no reading: the readings do not depend on it" in said(
        [0.0, 0.0], [0.0, 0.0])[0]
    assert "disagree by 50 % of it (more than 10 %)" in said([1.5, 3.0], [0.5, 1.0])[0]
    assert said([1.0, 2.0], [1.001, 2.002]) == []


def test_a_field_fitted_by_its_value_is_poorly_determined_beyond_its_scale() -> None:
    """Only a log-fitted field was warned of a standard error beyond a factor e; one
    fitted by its value over its scale now is, beyond that scale."""
    from core.back_analysis.fit import _identifiability
    from core.back_analysis.model import Field

    field = Field("loading.moment", 2e4, False, 2e4, (-math.inf, math.inf), "N")
    lo, hi = np.array([-np.inf]), np.array([np.inf])
    wide = _identifiability([field], np.array([[1.5 ** 2]]), 1.0, np.array([1.0]), lo, hi)
    assert wide == ["loading.moment: poorly determined (its standard error exceeds its "
                    "scale, 2e+04 N: the start's size, or half the range of its bounds)"]
    assert _identifiability([field], np.array([[0.5 ** 2]]), 1.0, np.array([1.0]), lo,
                            hi) == []


def test_a_degenerate_pairs_forecast_has_the_band_of_what_the_readings_fix() -> None:
    """The readings fix a coating's h / E alone, and the settlement forecast depends on
    it alone: its band is that of the one modulus fitted alone. Through the covariance of
    the undetermined combination (~1e24, the central differences' round-off) it read
    -0.04 to 0.04 m for a settlement of 4.1e-5 m."""
    exact = core.solve(dict(SCENE, times=TIMES.tolist()))
    rng = np.random.default_rng(3)
    readings = {"time": TIMES.tolist(), "settlement_std": SETTLEMENT_STD,
                "settlement": (exact.settlement
                               + SETTLEMENT_STD * rng.standard_normal(TIMES.size)).tolist()}
    one = calibrate(SCENE, readings, fit=["coating[0].modulus"]).forecast([3650.0, 7300.0])
    both = calibrate(SCENE, readings, fit=["coating[0].thickness", "coating[0].modulus"])
    assert not both.identifiable
    band = both.forecast([3650.0, 7300.0])
    # the same linearised band at points within STEP_TO_SE standard errors of the same
    # minimum: measured 2.1e-8 apart (the band) and 8.5e-7 (the value); the covariance
    # gave a band of width 0 here
    np.testing.assert_allclose(band.settlement_std, one.settlement_std, rtol=1e-6)
    np.testing.assert_allclose(band.settlement, one.settlement, rtol=1e-5)
    # the report says the fields' intervals are not determined, as the tab (it read "0 to not
    # finite Pa")
    from core.report.content import calibration_section

    rows = dict(calibration_section(both).rows)
    assert f"(95 % interval {both.not_determined}; start" in rows["coating[0].modulus"]


def test_an_ill_conditioned_but_resolved_fit_keeps_its_covariances_band() -> None:
    """Two fields correlated to 1 - 1e-9 (condition 5e4) are resolved by the central
    differences (their error ~1e-6): the forecast's band is the covariance's, not the
    infinite one of an unresolved combination (a first cut at the warning's condition
    1e3 gave inf)."""
    import types

    from core.back_analysis.fit import _covariance
    from core.back_analysis.result import Calibration

    rng = np.random.default_rng(0)
    a = rng.standard_normal(20)
    J = np.column_stack([a, a + 5e-5 * rng.standard_normal(20)])
    cov, condition = _covariance(J, 1.0)
    assert 1e4 < condition < 1e5
    fit = types.SimpleNamespace(jacobian=J, cov_x=cov, noise_scale=1.0)
    gradient = np.array([[1.0, 0.0], [1.0, 1.0], [1.0, -1.0]])
    np.testing.assert_allclose(Calibration._forecast_variance(fit, gradient),
                               np.einsum("ij,jk,ik->i", gradient, cov, gradient))



def fit_at_a_bound() -> Calibration:
    """Exact readings of the creep rate :data:`TRUTH`'s, fitted from 3 times it within
    bounds of 1.5 to 4 times it: the fit ends at the lower bound."""
    exact = _exact()
    rate = TRUTH["base.creep.rate"]
    readings = {"time": TIMES.tolist(), "settlement": exact.settlement.tolist(),
                "settlement_std": SETTLEMENT_STD}
    return calibrate(apply_point(SCENE, {**TRUTH, "base.creep.rate": 3 * rate}), readings,
                     fit=["base.creep.rate"], bounds={"base.creep.rate": (1.5 * rate, 4 * rate)})


def test_a_fit_ended_at_a_bound_gives_no_interval_past_it() -> None:
    """The truth outside the bounds given: the fit ends at the bound, says so, and its
    standard error does not hold there. Its summary read "95 % interval 2.72e+10 to
    2.882e+10" for a lower bound of 28 GPa; the summary and the report now say the
    readings do not determine it (the Fit tab too: tests/explorer/test_explorer_fit.py)."""
    from core.report.content import calibration_section

    fit = fit_at_a_bound()
    assert fit.values["base.creep.rate"] == pytest.approx(1.5 * TRUTH["base.creep.rate"],
                                                          rel=1e-6)
    assert "base.creep.rate" in fit.unidentified
    assert any("bound" in w for w in fit.warnings), fit.warnings
    assert fit.determined_intervals()["base.creep.rate"] is None
    assert f"95 % interval {fit.not_determined}; start" in fit.summary()
    rows = dict(calibration_section(fit).rows)
    assert f"(95 % interval {fit.not_determined}; start" in rows["base.creep.rate"]


def test_as_many_readings_as_fields_with_their_deviations_determine_them() -> None:
    """With its standard deviation given, one reading determines one field (the
    covariance is known): it was refused ("1 reading(s) cannot determine 1 field(s)").
    Without deviations the noise needs more readings than fields, and the refusal says
    so; chi^2/dof has no degree of freedom and is said to be none."""
    exact = _exact()
    k = 12
    one = {"time": [float(TIMES[k])], "settlement": [float(exact.settlement[k])],
           "settlement_std": SETTLEMENT_STD}
    start = apply_point(SCENE, {**TRUTH, "base.creep.rate": 1.5 * TRUTH["base.creep.rate"]})
    fit = calibrate(start, one, fit=["base.creep.rate"])
    se = fit.standard_errors["base.creep.rate"]
    # the one reading is exact: the fit stops within STEP_TO_SE (1e-3) of a standard
    # error of the truth (measured: 2.5e-7 1/day off, se 2.4e-3, 12 % of the rate)
    assert abs(fit.values["base.creep.rate"] - TRUTH["base.creep.rate"]) <= 1e-3 * se
    assert fit.identifiable and fit.dof == 0 and math.isnan(fit.chi2_per_dof)
    assert 0 < se < 0.25 * TRUTH["base.creep.rate"]
    assert "chi^2/dof = none (as many readings as fitted fields" in fit.summary()
    assert fit.to_dict()["goodness_of_fit"]["chi2_per_dof"] is None
    json.dumps(fit.to_dict(), allow_nan=False)
    del one["settlement_std"]
    with pytest.raises(ValueError, match=r"1 reading\(s\) cannot determine 1 field\(s\) and "
                                         r"the readings' noise; .* or the readings' standard"):
        calibrate(start, one, fit=["base.creep.rate"])


def test_one_field_the_readings_do_not_see_is_said_in_words_for_one() -> None:
    """Tilts of a centred punch (0 whatever the base) fitted by the base's creep rate:
    the warnings read "the readings determine only a combination of base.creep.rate ...
    fix all but one of them" for the one field, and "the solver's error estimate is inf
    of the noise" for readings met exactly without deviations."""
    times = TIMES[:3].tolist()
    centred = apply_point(SCENE, TRUTH)
    centred["loading"] = dict(centred["loading"], moment=0.0)
    fit = calibrate(centred, {"time": times, "tilt": [0.0, 0.0, 0.0]},
                    fit=["base.creep.rate"])
    assert not fit.identifiable
    text = " ".join(fit.warnings)
    assert ("not identifiable: the readings do not determine base.creep.rate (condition "
            "number") in text and "add readings that depend on it" in text
    assert "combination" not in text and "fix all but one" not in text
    assert "the fit meets every reading exactly" in text and "inf of the noise" not in text


def test_a_fit_to_a_scene_its_model_does_not_hold_for_warns() -> None:
    """Settlements given in m where they were in mm (0.0727 for 0.0727 mm) fitted the
    preset's concrete to ~17 MPa, an answer flagged large_settlement and large_tilt, and
    the fit carried no warning (an audit). It now says the fitted scene is flagged, and
    what most likely did it; readings in their unit fit with no such warning."""
    from core.back_analysis import readings_from_csv

    scene = core.load_scene("preset:eccentric_creep")
    rows = "30, 0.0727\n100, 0.0827\n300, 0.0841\n1000, 0.0841\n"
    good = calibrate(scene, readings_from_csv("time [day], settlement [mm]\n" + rows),
                     fit=["base.creep.modulus_final"])
    assert not any("flagged" in w for w in good.warnings), good.warnings
    wrong = calibrate(scene, readings_from_csv("time [day], settlement [m]\n" + rows),
                      fit=["base.creep.modulus_final"])
    (warning,) = [w for w in wrong.warnings if "fitted scene's answer is flagged" in w]
    assert "large_settlement" in warning and "wrong unit (mm read as m)" in warning, warning
