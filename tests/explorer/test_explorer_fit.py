"""The Fit tab (explorer/views/fit.py): readings uploaded and drawn on the histories, scene
fields fitted to them (core.calibrate), the fitted values with their standard errors, the
forecast band, the fitted scene applied. The page runs the fit inline without a server."""

from __future__ import annotations

import asyncio
import html

import numpy as np
import pytest

from core import solve
from core.back_analysis import readings_csv
from explorer.model import plan_fit, readings_columns, readings_note, run_fit
from explorer.model.fit import read_upload

#: Reading times [day after loading] within the default scene's 365 days.
TIMES = [5.0, 10.0, 20.0, 40.0, 80.0, 160.0, 300.0]
#: The coating modulus the readings are made with [Pa]: 1.5 times the default scene's.
TRUE_MODULUS = 1.2e9


def _readings_text(scene: dict) -> str:
    """Settlement readings of ``scene`` with the coating modulus :data:`TRUE_MODULUS`, a
    deterministic scatter of 0.5 % (the fit then has a finite, nonzero noise)."""
    work = dict(scene, times=TIMES)
    work["coating"] = [dict(scene["coating"][0], modulus=TRUE_MODULUS)]
    result = solve(work)
    scatter = 1 + 0.005 * np.array([1, -1, 0.5, -0.5, 1, -1, 0.0])
    return readings_csv({"time": TIMES, "settlement": list(result.settlement * scatter)})


def _with_readings(explorer_app):
    """The default scene solved, and readings of :func:`_readings_text` uploaded to its
    Fit tab: ``(app, tab)``."""
    app = explorer_app(solved=True)
    tab = app.fit_tab
    tab.upload.param.update(filename="levelling.csv",
                            value=_readings_text(app.state.to_scene()).encode())
    return app, tab


def test_readings_are_drawn_fitted_and_the_fitted_scene_applied(explorer_app):
    app = explorer_app(solved=True)
    tab = app.fit_tab
    assert tab.fit_button.disabled  # nothing to fit yet
    assert "coating[0].modulus" in [s for s in tab.fields[0].options.values()]
    assert tab.fields[1].value == "(none)"
    text = _readings_text(app.state.to_scene())
    tab.upload.param.update(filename="levelling.csv", value=text.encode())
    assert "levelling.csv: 7 settlement readings" in tab.readings_status.object
    drawn = app.figures.readings_src["settlement"].data
    assert len(drawn["t"]) == 7 and not len(app.figures.readings_src["tilt"].data["t"])
    assert not tab.fit_button.disabled
    tab.fields[0].value = "coating[0].modulus"
    assert tab.start()
    outcome = tab.fit_run.outcome
    assert tab.fit_run.status == "done", tab.fit_run.message
    value = outcome.calibration.values["coating[0].modulus"]
    se = outcome.calibration.standard_errors["coating[0].modulus"]
    # the scatter of 0.5 % moves the fit by 0.1 % of the modulus with se 1.3 % (measured:
    # 1.2011e9 +/- 1.59e7 Pa): within 3 se of the truth, se below 5 %
    assert abs(value - TRUE_MODULUS) < 3 * se and 0 < se < 0.05 * TRUE_MODULUS
    table = tab.fit_table.object
    assert "coating 1: Young&#x27;s modulus" in table and "MPa" in table and "±" in table
    # no deviations given: no chi^2, whose weights' scale is then arbitrary
    assert "χ²/dof" not in table and "7 readings" in table
    assert "the noise estimated from the scatter about the fit, settlement " in table
    assert f"settlement {outcome.calibration.noise['settlement'] * 1e3:.3g} mm" in table
    # the interval by Student's t of the fit's 6 degrees of freedom (2.447 se each side),
    # the noise being estimated from the scatter
    low, high = outcome.calibration.intervals()["coating[0].modulus"]
    assert high - low == pytest.approx(2 * 2.446912 * se, rel=1e-3)
    assert "95 % interval" in table and "Student's t, 6 degrees of freedom" in table
    assert f"{low / 1e6:.4g} to {high / 1e6:.4g} MPa" in table
    band = app.figures.forecast_src["settlement"].data
    times = app.controller.view.times
    assert len(band["t"]) == len(times) and band["t"][-1] == pytest.approx(times[-1])
    assert np.all(np.asarray(band["lower"]) <= np.asarray(band["upper"]))
    assert not tab.apply_button.disabled
    name = app.state.to_scene()["name"]
    assert tab.apply()
    scene = app.state.to_scene()
    assert scene["coating"][0]["modulus"] == pytest.approx(value, rel=1e-9)
    # named as fitted and saying from what (it kept the preset's name: a saved file or
    # a report passed for the preset)
    assert scene["name"] == f"{name} (fitted)"
    assert scene["description"].startswith(
        f"Fitted on screen to the readings levelling.csv from the scene “{name}”: "
        "coating 1: Young's modulus")


def test_the_report_carries_the_fit_while_its_fitted_scene_is_shown(explorer_app):
    """Fitted and applied, the printable report has the section "Back-analysis" (the
    fitted value, the readings drawn over the settlement); before Apply, and once
    another value moves, the scene on screen is not the fitted one and the report says
    nothing of the fit."""
    app, tab = _with_readings(explorer_app)
    tab.fields[0].value = "coating[0].modulus"
    assert tab.start() and tab.fit_run.status == "done", tab.fit_run.message
    assert app.screen.fit is tab.fit_run.outcome

    def report() -> str:
        return asyncio.run(app.files_tab._report_file()).getvalue()

    assert "Back-analysis" not in report()  # the scene fitted, not the fitted one
    assert tab.apply()
    app.controller.wait()
    text = report()
    fitted = tab.fit_run.outcome.calibration.values["coating[0].modulus"]
    assert "Back-analysis" in text and "coating[0].modulus" in text
    assert f"{fitted:.6g}"[:5] in text
    assert "7 (settlement [m])" in text
    pdf = asyncio.run(app.files_tab._pdf_report_file()).getvalue()
    assert pdf.startswith(b"%PDF")
    app.state.loading.histories["force"].value *= 1.1
    app.controller.wait()
    assert "Back-analysis" not in report()


def test_a_bad_readings_file_is_refused_naming_line_and_column(explorer_app):
    app = explorer_app()
    tab = app.fit_tab
    tab.upload.param.update(filename="bad.csv",
                            value=b"time [day], settlement [mm]\n10, 1.0\n5, 1.2\n")
    message = tab.readings_status.object
    assert "The readings were not used: bad.csv: line 3, column time" in message
    assert tab.readings is None and tab.fit_button.disabled
    assert not tab.start() and "upload a readings file first" in tab.fit_status.object
    tab.upload.param.update(filename="bad.csv", value=b"\xff\xfe")
    assert "not a text file" in tab.readings_status.object
    tab.upload.param.update(filename="<b>x</b>.csv", value=b"time,settlement\n1,x\n")
    assert "<b>" not in tab.readings_status.object  # the file name is escaped


def test_a_refused_file_after_a_good_one_says_which_readings_the_fit_uses(explorer_app):
    """After good.csv, a refused text.csv said only "The readings were not used: ..."
    while Fit stayed enabled and ran on good.csv's readings: the page now says so."""
    app = explorer_app()
    tab = app.fit_tab
    tab.upload.param.update(filename="good.csv",
                            value=b"time [day], settlement [mm]\n10, 1.0\n20, 1.2\n40, 1.3\n")
    assert tab.readings is not None and not tab.fit_button.disabled
    tab.upload.param.update(filename="text.csv",
                            value=b"time [day], settlement [mm]\n10, 1.0\n20, abc\n")
    message = html.unescape(tab.readings_status.object)
    assert "The readings were not used: text.csv: line 3" in message
    assert "The Fit button still uses the previous readings, good.csv: 3 " in message, message
    assert tab.readings.source == "good.csv"


def test_new_readings_keep_the_last_fit_on_screen_saying_of_which(explorer_app):
    """New readings after a fit cleared its table and forecast and left "Done: fitted
    ..." over nothing: the fit now stays, said to be of the earlier readings (its forecast
    beside the new ones checks it), and Fit fits the new ones."""
    app, tab = _with_readings(explorer_app)
    tab.fields[0].value = "coating[0].modulus"
    assert tab.start() and tab.fit_run.status == "done", tab.fit_run.message
    table = tab.fit_table.object
    band = dict(app.figures.forecast_src["settlement"].data)
    tab.upload.param.update(filename="later.csv",
                            value=b"time [day], settlement [mm]\n10, 1.0\n20, 1.2\n40, 1.3\n")
    assert tab.readings.source == "later.csv"
    assert len(app.figures.readings_src["settlement"].data["t"]) == 3
    assert tab.fit_table.object == table
    assert dict(app.figures.forecast_src["settlement"].data) == band
    status = html.unescape(tab.fit_status.object)
    assert "made from the earlier readings, levelling.csv" in status
    assert "readings now shown, later.csv" in status and "Done:" not in status
    assert not tab.fit_button.disabled


def test_fields_are_checked_before_the_fit(explorer_app):
    app = explorer_app()
    scene = app.state.to_scene()
    with pytest.raises(ValueError, match="field 1: choose a field"):
        plan_fit(scene, [None, None, None])
    with pytest.raises(ValueError, match="field 2: chosen twice"):
        plan_fit(scene, ["loading.force", "loading.force"])
    with pytest.raises(ValueError, match="field 1: 'eccentricity' is not a field"):
        plan_fit(scene, ["eccentricity"])
    readings = read_upload(b"time,settlement\n1,1e-5\n2,2e-5\n", "r.csv")
    with pytest.raises(ValueError, match="cannot determine 2 field"):
        run_fit(scene, readings, ["loading.force", "coating[0].modulus"])
    # the tab says the core's reason and stays usable
    tab = app.fit_tab
    tab.show_readings(readings)
    tab.fields[0].value, tab.fields[1].value = "loading.force", "coating[0].modulus"
    tab.start()
    assert tab.fit_run.status == "failed"
    assert "Not fitted: measurements: 2 reading(s)" in tab.fit_status.object
    assert not tab.fit_button.disabled


def test_readings_columns_in_display_units_with_error_bars():
    readings = read_upload(b"time [day], settlement [mm], settlement_std, tilt [mrad]\n"
                           b"1, 1.0, 0.1, \n2, , , 0.5\n", "r.csv")
    columns = readings_columns(readings)
    assert columns["settlement"]["t"] == [1.0]
    assert columns["settlement"]["v"] == pytest.approx([1.0])  # mm
    assert columns["settlement"]["lower"] == pytest.approx([0.9])
    assert columns["tilt"]["v"] == pytest.approx([0.5])  # mrad, no deviation: no bar
    assert columns["tilt"]["upper"] == pytest.approx([0.5])
    assert readings_note(readings).startswith("1 settlement reading with standard "
                                              "deviations and 1 tilt reading")


def test_a_link_keeps_the_readings_and_the_fields(explorer_app):
    """The Fit tab's readings and fields go into the page's link, and a page opened from
    it draws the same readings and chooses the same fields (the fit is not run); bad or
    oversized readings in a link are refused with a message, the page opens."""
    from explorer.model.view_link import (
        MAX_LINK_READINGS,
        fit_settings,
        read_fit_query,
        view_query,
    )

    app = explorer_app(solved=True)
    tab = app.fit_tab
    assert tab.fit_settings() is None  # no readings: nothing for the link
    text = _readings_text(app.state.to_scene())
    tab.upload.param.update(filename="levelling.csv", value=text.encode())
    tab.fields[0].value = "coating[0].modulus"
    tab.fields[1].value = "loading.force"
    settings = tab.fit_settings()
    assert settings["fields"] == ["coating[0].modulus", "loading.force", None]
    query = view_query(app.controller.view.scene, 0, 0, [], None, settings)
    opened = explorer_app(query=query, solved=True)
    assert opened.fit_tab.chosen() == ["coating[0].modulus", "loading.force", None]
    assert opened.fit_tab.readings.to_dict() == tab.readings.to_dict()
    assert "levelling.csv: 7 settlement readings" in opened.fit_tab.readings_status.object
    assert len(opened.figures.readings_src["settlement"].data["t"]) == 7
    assert opened.fit_tab.fit_run.outcome is None and not opened.fit_tab.fit_button.disabled
    # more readings than a link holds (6000 characters, ~22 a noisy reading): left out of
    # the link, not cut short; the page keeps them
    count = 400
    noisy = np.random.default_rng(1).uniform(1e-5, 2e-5, count).tolist()
    many = dict(settings, readings={"time": list(range(1, count + 1)), "settlement": noisy})
    assert not view_query(app.controller.view.scene, 0, 0, [], None, many)["fit"]
    # settings a page never writes: refused with the setting named, the page opens
    readings = settings["readings"]
    for bad, reason in (({"fields": [], "readings": readings}, "fit fields"),
                        ({"fields": ["x" * 500], "readings": readings}, "fit fields"),
                        ({"fields": ["loading.force"], "readings": {"time": "1"}},
                         "fit readings"),
                        ({"fields": ["loading.force"],
                          "readings": {"time": list(range(MAX_LINK_READINGS + 1))}},
                         "fit readings"),
                        ({"fields": ["loading.force"],
                          "readings": dict(readings, settlement=["a"] * 7)},
                         "settlement")):
        with pytest.raises(ValueError, match=reason):
            fit_settings(bad)
    from explorer.model import encode_scene

    none, message = read_fit_query({"fit": encode_scene({"fields": 3})})
    assert none is None and message.startswith("The readings in the link were not used")
    opened = explorer_app(query={"fit": encode_scene({"fields": 3})})
    assert "The readings in the link were not used" in opened.screen.notice


def test_a_served_fit_runs_in_a_worker_at_the_lower_priority(explorer_app, monkeypatch):
    """Served with worker processes, a fit runs in one of them (it held the server's
    Python lock for its 0.3-6 s of CPU beside the event loop), at the lower priority of
    background work, and gives the page what it gives run inline."""
    from explorer.solving import controller, fit_runner
    from explorer.solving.worker_side import fit_outcome
    from explorer.solving.workers import SolverProcesses

    app = explorer_app(solved=True)
    scene = app.state.to_scene()
    tab = app.fit_tab
    tab.upload.param.update(filename="levelling.csv", value=_readings_text(scene).encode())
    keys = ["coating[0].modulus"]
    processes = SolverProcesses(1, 64 * 1024**2)
    asked = []
    run = processes.run_background

    def spy(lane, fn, *args):
        asked.append(fn)
        return run(lane, fn, *args)

    monkeypatch.setattr(processes, "run_background", spy)
    monkeypatch.setattr(controller, "worker_processes", lambda: processes)
    try:
        fit = fit_runner.FitRun()
        fit.start(scene, tab.readings, keys, background=False)
    finally:
        processes.shutdown()
    assert fit.status == "done", fit.message
    assert asked == [fit_outcome]
    inline = run_fit(scene, tab.readings, keys)
    # the solver is deterministic: the same numbers in the worker as here
    assert fit.outcome.calibration.values == inline.calibration.values
    assert fit.outcome.rows() == inline.rows()
    for name in ("settlement", "tilt", "settlement_std"):
        np.testing.assert_array_equal(getattr(fit.outcome.forecast, name),
                                      getattr(inline.forecast, name))


def test_the_forecast_is_drawn_apart_from_the_pins_and_punches():
    """The fitted curve was orange and dashed, as pin 2: a class read it as a pin."""
    from explorer.plots import PIN_COLORS, PUNCH_COLORS
    from explorer.plots.figures import FORECAST_COLOR

    assert FORECAST_COLOR not in (*PIN_COLORS, *PUNCH_COLORS)


def test_a_forecast_the_readings_do_not_determine_is_drawn_without_a_band() -> None:
    """An infinite band (a forecast of fields the readings do not fix) is a gap in the
    drawn band, not infinities sent to the page."""
    from core.back_analysis import Forecast
    from explorer.model import forecast_columns

    t = np.array([10.0, 100.0])
    forecast = Forecast(t, np.array([1e-4, 2e-4]), np.zeros(2), np.array([1e-6, np.inf]),
                        np.zeros(2), 0.95, solution=None)
    columns = forecast_columns(forecast)["settlement"]
    assert columns["v"] == pytest.approx([0.1, 0.2])  # mm
    assert columns["lower"][0] == pytest.approx(0.1 - 1.96e-3, rel=1e-3)
    assert np.isnan(columns["lower"][1]) and np.isnan(columns["upper"][1])


def test_a_fit_of_another_scene_says_so_and_applies_nothing(explorer_app):
    """A force typed after the fit: the table and the forecast looked current and Apply
    set the force back to the fitted scene's. Now the status says the fit is of the
    scene before, the forecast is hidden and Apply is off; back on the fitted scene, the
    fit is current again."""
    from explorer.views.fit import STALE_FIT

    app, tab = _with_readings(explorer_app)
    tab.fields[0].value = "coating[0].modulus"
    assert tab.start() and tab.fit_run.status == "done", tab.fit_run.message
    assert not tab.apply_button.disabled
    force = app.state.loading.histories["force"]
    start = force.value
    force.value = 1.3 * start
    app.controller.wait()
    assert tab.apply_button.disabled
    assert html.unescape(STALE_FIT) in html.unescape(tab.fit_status.object)
    assert len(app.figures.forecast_src["settlement"].data["t"]) == 0
    force.value = start
    app.controller.wait()
    assert not tab.apply_button.disabled
    assert tab.fit_status.object.count("Done: ") == 1
    assert len(app.figures.forecast_src["settlement"].data["t"]) > 0
    assert tab.apply()
    app.controller.wait()
    # the fitted scene on screen is the fit's too
    assert not tab.apply_button.disabled and "Done: " in tab.fit_status.object


def test_a_fit_the_readings_do_not_determine_is_not_applied(explorer_app):
    """A coating's thickness and modulus (their ratio alone counts) went to 11 m and
    279 GPa, and Apply installed them without a word; the warnings named the fields by
    their scene paths beside the table's names."""
    app, tab = _with_readings(explorer_app)
    tab.fields[0].value = "coating[0].thickness"
    tab.fields[1].value = "coating[0].modulus"
    assert tab.start() and tab.fit_run.status == "done", tab.fit_run.message
    assert tab.apply_button.disabled
    table = html.unescape(tab.fit_table.object)
    assert "Apply is off: the readings do not determine every field fitted" in table
    assert "not identifiable" in table and "coating[0]" not in table
    assert "coating 1: thickness" in table


def test_a_scene_changed_while_the_fit_runs_and_a_failed_fit_are_said(explorer_app,
                                                                       monkeypatch):
    """A force typed while the fit ran (seconds): its outcome came marked current, with
    Apply on. A fit that failed left the last fit's table and Apply on beside its
    failure, and back on that fit's scene the status read "Done: <the failure>"."""
    import explorer.solving.fit_runner as fit_runner
    from explorer.views.fit import STALE_FIT

    app, tab = _with_readings(explorer_app)
    tab.fields[0].value = "coating[0].modulus"
    force = app.state.loading.histories["force"]
    start = force.value
    fit_outcome = fit_runner.fit_outcome

    def typed_meanwhile(*args, **kwargs):
        outcome = fit_outcome(*args, **kwargs)
        force.value = 1.3 * start
        app.controller.wait()
        return outcome

    monkeypatch.setattr(fit_runner, "fit_outcome", typed_meanwhile)
    assert tab.start() and tab.fit_run.status == "done", tab.fit_run.message
    monkeypatch.undo()
    assert tab.apply_button.disabled
    assert html.unescape(STALE_FIT) in html.unescape(tab.fit_status.object)
    force.value = start
    app.controller.wait()
    assert not tab.apply_button.disabled and "Done: fitted" in tab.fit_status.object
    # a fit that fails takes the last one's values off the page
    tab.fields[1].value = "coating[0].modulus"  # chosen twice
    tab.start()
    assert tab.fit_run.status == "failed"
    assert tab.apply_button.disabled and tab.fit_table.object == ""
    force.value = 1.2 * start
    app.controller.wait()
    force.value = start
    app.controller.wait()
    assert tab.apply_button.disabled and "Not fitted: field 2: chosen twice" in (
        html.unescape(tab.fit_status.object))


def test_a_fit_ended_at_a_bound_shows_no_interval_past_it() -> None:
    """As the core's summary and report (tests/back_analysis/test_fit.py): the tab's
    interval column read an interval reaching past the bound the fit ended at."""
    from explorer.model.fit import FitOutcome, fit_choices
    from tests.back_analysis.test_fit import fit_at_a_bound

    fit = fit_at_a_bound()
    offered = {c.key: c for c in fit_choices(fit.base)}
    outcome = FitOutcome(fit, None, tuple(offered[p] for p in fit.paths), 0.0)
    assert outcome.intervals() == [fit.not_determined]
