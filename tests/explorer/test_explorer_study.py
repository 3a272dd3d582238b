"""The Study tab without a browser: the study built from the scene on screen gives what a
serial loop of solves gives, bad ranges are refused naming the field, Cancel stops the
study's process, and the chart, CSV and PNG hold the result."""

from __future__ import annotations

import asyncio
import copy
import html
import json
import time

import numpy as np
import pytest

import core
from core import solve
from core.presets import read_preset
from core.study.definition import apply_point
from explorer.files import study_csv
from explorer.model import ExplorerState, presets
from explorer.model.study import (
    ECCENTRICITY,
    MAX_AXIS_POINTS,
    MAX_POINTS,
    OUTPUTS,
    Axis,
    plan_study,
    study_choices,
)
from explorer.solving import StudyRun


def screen_scene(times=(1.0, 365.0)) -> dict:
    """The scene on screen: the default preset with two output times (a short history)."""
    scene = copy.deepcopy(presets()["uniform_flat"])
    scene["times"] = list(times)
    state = ExplorerState()
    state.load_scene(scene)
    return state.to_scene()


def run(planned, timeout: float = 300.0) -> StudyRun:
    runner = StudyRun()
    runner.start(planned)
    assert runner.wait(timeout), "the study did not end"
    return runner


def test_study_from_the_scene_on_screen_equals_a_serial_loop():
    scene = screen_scene()
    planned = plan_study(scene, [Axis("loading.force", 300.0, 700.0, 3),
                                 Axis("coating[0].modulus", 200.0, 800.0, 2, "log")])
    runner = run(planned)
    assert runner.status == "done", runner.message
    result = runner.result
    assert result.flags.shape == (3, 2) and not result.failed.any()
    forces = [3e5, 5e5, 7e5]  # kN/m on screen -> N/m
    moduli = [2e8, 8e8]       # MPa on screen -> Pa
    for i, force in enumerate(forces):
        for j, modulus in enumerate(moduli):
            want = solve(apply_point(scene, {"loading.force": force,
                                             "coating[0].modulus": modulus}))
            q = want.pressure_on_grid
            expected = {"settlement": want.settlement, "tilt": want.tilt,
                        "q_max": q.max(axis=0), "q_min": q.min(axis=0)}
            for name, values in expected.items():
                got = result.outputs[name][i, j]
                # the same solver on the same scene: measured bitwise equal; 1e-12 of the
                # output's scale leaves room for stage caches prepared in another order.
                # The tilt of this centred load is round-off (~3e-21 rad): its scale is
                # the settlement over the half-width, not its own noise.
                scale = max(np.max(np.abs(values)), 1e-300)
                if name == "tilt":
                    scale = max(scale, float(np.max(np.abs(want.settlement)))
                                / float(scene["punch"]["half_width"]))
                np.testing.assert_allclose(got / scale, np.asarray(values) / scale,
                                           rtol=0, atol=1e-12, err_msg=name)
            # full contact (q_min > 0 here): the contact width is the punch's width
            assert np.all(q.min(axis=0) > 0)
            np.testing.assert_allclose(result.outputs["contact_width"][i, j], 2.0,
                                       rtol=1e-12)
    shown = result.shown("settlement", 1)
    np.testing.assert_allclose(shown, result.outputs["settlement"][..., 1] * 1e3)


def test_eccentricity_sets_the_moment_from_the_force():
    scene = screen_scene()
    keys = [c.key for c in study_choices(scene)]
    assert keys[:3] == ["loading.force", "loading.moment", ECCENTRICITY]
    planned = plan_study(scene, [Axis(ECCENTRICITY, 0.0, 0.3, 4)])
    (param,) = planned.study.parameters
    assert param.path == "loading.moment"
    force = scene["loading"]["force"]
    np.testing.assert_allclose(param.values, force * np.linspace(0.0, 0.3, 4), rtol=1e-15)
    np.testing.assert_allclose(planned.values[0], np.linspace(0.0, 0.3, 4))


@pytest.mark.parametrize(("axes", "starts"), [
    ([Axis("loading.force", 100.0, 900.0, 20), Axis("coating[0].modulus", 1.0, 9.0, 21)],
     f"parameter 2, points: the study has 420 points (20 x 21), more than the limit of "
     f"{MAX_POINTS}"),
    ([Axis("loading.force", 100.0, 900.0, 1)], "parameter 1, points: must be a whole number"),
    ([Axis("loading.force", 0.0, 900.0, 5, "log")], "parameter 1, from: a log spacing"),
    ([Axis("loading.force", 500.0, 500.0, 5)], "parameter 1, to: equals 'from'"),
    # an emptied box sends NaN (it read "must be a number, got nan")
    ([Axis("loading.force", float("nan"), 500.0, 5)], "parameter 1, from: is empty; give a"),
    ([Axis("loading.force", 100.0, float("inf"), 5)], "parameter 1, to: must be a number"),
    ([Axis("loading.force", 100.0, 900.0, 5), Axis("loading.force", 1.0, 2.0, 3)],
     "parameter 2: the same field as parameter 1"),
    ([Axis("loading.force", 100.0, 900.0, 5), Axis(ECCENTRICITY, 0.0, 0.2, 3)],
     "parameter 2: the eccentricity sets the moment"),
    ([Axis("solver.tol", 1e-6, 1e-4, 3)], "parameter 1: 'solver.tol' is not a field"),
    # the eccentricity, varied as the moment (it read "loading.moment = 7.5e+05")
    ([Axis(ECCENTRICITY, 0.0, 1.5, 4)],
     "parameter 1 (loading: eccentricity e = M/P): the scene is invalid at 1.5 m ("),
    ([Axis("coating[0].modulus", -100.0, 900.0, 3)],
     # the value as typed, in the tab's unit (it read "coating[0].modulus = -1e+08")
     "parameter 1 (coating 1: Young's modulus): the scene is invalid at -100 MPa ("),
])
def test_a_bad_study_is_refused_naming_the_field(axes, starts):
    with pytest.raises(ValueError) as info:
        plan_study(screen_scene(), axes)
    assert str(info.value).startswith(starts), str(info.value)


def test_cancel_stops_the_study_process():
    # 60 coating moduli: each a new geometry, several seconds of work on any machine
    scene = screen_scene(times=(1.0, 30.0, 365.0))
    planned = plan_study(scene, [Axis("coating[0].modulus", 50.0, 5000.0, 60, "log")])
    runner = StudyRun()
    runner.start(planned)
    deadline = time.monotonic() + 120
    while runner.status != "running" or runner.process is None:
        assert time.monotonic() < deadline, runner.message
        time.sleep(0.02)
    process = runner.process
    runner.cancel()
    assert runner.wait(30)
    assert runner.status == "cancelled", runner.message
    assert runner.result is None
    assert not process.is_alive() and process.exitcode is not None
    # the page can run the next study at once
    again = run(plan_study(scene, [Axis("loading.force", 300.0, 600.0, 2)]))
    assert again.status == "done", again.message


def test_the_tab_draws_the_chart_and_writes_the_files(explorer_app):
    from explorer.views.study import NONE

    state_scene = screen_scene()
    app = explorer_app(scene=state_scene)
    tab = app.study_tab
    assert tab.study_first.field.value == "loading.force"
    assert tab.study_second.field.value == NONE
    tab.study_first.fill(Axis("loading.force", 300.0, 700.0, 3))
    # refused: the message names the field, nothing runs
    tab.study_first.count.value = MAX_POINTS + 1
    assert not tab.start()
    assert "parameter 1, points" in tab.study_status.object
    # too few, as typed (the box once kept 1 or 0 while the study ran on 9 points)
    for typed in (1, 0, -3):
        tab.study_first.count.value = typed
        assert not tab.start()
        assert (f"parameter 1, points: must be a whole number from 2 to {MAX_AXIS_POINTS}, "
                f"got {typed}") in html.unescape(tab.study_status.object)
    tab.study_first.count.value = 3
    assert tab.start()
    assert tab.study_run.wait(300)
    assert tab.study_run.status == "done", tab.study_run.message
    data = tab.study_charts.source.data
    np.testing.assert_allclose(data["x"], [300.0, 500.0, 700.0])
    # one chart on the page: the linear line; the log line and the heat map hidden
    assert tab._chart_box.objects == [tab._chart_pane]
    assert tab._chart_pane.object is tab.study_charts.lines["linear"]
    assert not tab.study_charts.shown.legend.visible  # no flagged point, no "flagged" key
    result = tab.study_run.result
    np.testing.assert_allclose(data["y"], result.outputs["settlement"][:, -1] * 1e3)
    # the times offered read in four digits where they stay apart ("0.437764 days" read)
    from core.scene import days_text

    assert list(tab.study_time.options) == [days_text(float(t), 4) for t in result.times]
    tab.study_output.value = "q_max"
    np.testing.assert_allclose(tab.study_charts.source.data["y"],
                               result.outputs["q_max"][:, -1] * 1e-3)
    assert "kPa" in tab.study_charts.shown.yaxis.axis_label
    csv = tab._csv().getvalue().decode("utf-8").splitlines()
    header = next(line for line in csv if not line.startswith("#"))
    assert header.startswith("loading_force_p_kN_per_m,time_day,settlement_mm")
    # each point's estimate, as the command line's file has it (the page's had none)
    assert header.endswith(",error_estimate,flags,error")
    first = next(line for line in csv if not line.startswith("#") and line != header)
    estimate = float(first.split(",")[header.split(",").index("error_estimate")])
    assert 0.0 < estimate == pytest.approx(float(result.estimates[0]), rel=1e-2)
    assert estimate <= 1e-6  # the scene's tol
    assert len([line for line in csv if not line.startswith("#")]) == 1 + 3 * 2
    # a CSV over what the page sends is not offered, and the tab says what to do instead
    from explorer.files import MAX_PAGE_DOWNLOAD_BYTES

    data = tab._csv_data
    tab._offer_csv(result, b"x" * (MAX_PAGE_DOWNLOAD_BYTES + 1))
    assert tab.study_csv.disabled and "more than the page sends" in tab.study_csv.label
    assert "coated-punch sweep" in tab.study_status.object
    tab._offer_csv(result, data)
    png = asyncio.run(tab._png()).getvalue()
    assert png.startswith(b"\x89PNG\r\n\x1a\n") and len(png) > 5000
    assert not tab.study_csv.disabled and not tab.study_png.disabled
    assert set(OUTPUTS) <= set(result.outputs)
    # the fields offered follow the scene on screen
    assert "coating[1].modulus" not in tab.study_second.field.options.values()
    app.state.n_layers = 2  # solved at once: no server here
    assert app.controller.view.scene["coating"][1]
    assert "coating[1].modulus" in tab.study_second.field.options.values()
    assert tab.study_first.field.value == "loading.force"  # the choice made is kept


def test_flagged_points_are_marked_on_the_chart_and_in_the_csv():
    from explorer.plots import DesignChart

    scene = screen_scene()
    scene["solver"]["contact"] = "full"  # the full-contact answer, flagged when q < 0
    planned = plan_study(scene, [Axis(ECCENTRICITY, 0.0, 0.6, 4)])
    runner = run(planned)
    assert runner.status == "done", runner.message
    result = runner.result
    # e = 0.6 m > a/3 under a 2 m wide punch: the pressure at the heel is negative
    assert list(result.flagged) == [False, False, False, True]
    assert "contact_lost" in result.flags[-1]
    chart = DesignChart()
    chart.draw(result, "q_min", 1)
    np.testing.assert_allclose(chart.flagged.data["x"], [0.6])
    assert chart.shown.legend.visible  # the red cross is named
    # above the plot: at its top left it covered the first points
    assert chart.shown.legend[0] in chart.shown.above
    assert chart.flagged.data["y"][0] < 0  # kPa: the tension the flag is about
    rows = [line for line in study_csv(result).splitlines() if not line.startswith("#")]
    assert rows[-1].endswith('"contact_lost",""')
    # the file records the version, the base scene and its solver settings
    meta = dict(line[2:].split(": ", 1) for line in study_csv(result).splitlines()
                if line.startswith("# ") and ": " in line)
    assert meta["version"] == core.__version__
    assert json.loads(meta["scene_json"])["solver"]["contact"] == "full"
    assert json.loads(meta["solver"])["contact"] == "full"


def test_a_link_keeps_the_study_settings(explorer_app):
    """The Study tab's fields, ranges, spacing, counts and output go into the page's link
    and a page opened from it shows them again; bad settings are refused, not fatal."""
    from explorer.model.view_link import read_study_query, study_settings, view_query

    app = explorer_app()
    first, second = app.study_tab.study_first, app.study_tab.study_second
    first.field.value = "coating[0].modulus"
    first.start.value, first.stop.value = 150.0, 1200.0
    first.count.value, first.spacing.value = 7, "log"
    second.field.value = "loading.force"
    second.start.value, second.stop.value = 250.0, 650.0
    second.count.value, second.spacing.value = 5, "linear"
    app.study_tab.study_output.value = "tilt"
    settings = app.study_tab.study_settings()
    assert settings == {"axes": [["coating[0].modulus", 150.0, 1200.0, 7, "log"],
                                 ["loading.force", 250.0, 650.0, 5, "linear"]],
                        "output": "tilt"}
    query = view_query(app.controller.view.scene, 0, 0, [], settings)
    opened = explorer_app(query=query)
    assert opened.study_tab.study_settings() == settings
    assert opened.study_tab.study_second.field.value == "loading.force"
    first = opened.study_tab.study_first
    assert first.spacing.value == "log" and first.count.value == 7
    # one parameter: the second is left out
    one = {"axes": [["loading.force", 100.0, 900.0, 4, "linear"]], "output": "q_max"}
    opened = explorer_app(query=view_query(app.controller.view.scene, 0, 0,
                                                         [], one))
    assert opened.study_tab.study_settings() == one
    # settings a page never writes: refused with the setting named, the page opens
    for bad, reason in (({"axes": [], "output": "tilt"}, "study axes"),
                        ({"axes": [["x", 1.0, float("nan"), 3, "log"]], "output": "tilt"},
                         "'to' must be a finite number"),
                        ({"axes": [["x", 1.0, 2.0, 10**6, "log"]], "output": "tilt"},
                         "points must be an integer"),
                        ({"axes": [["x", 1.0, 2.0, 3, "cubic"]], "output": "tilt"},
                         "spacing"),
                        ({"axes": [["x", 1.0, 2.0, 3, "log"]], "output": "__import__"},
                         "study output")):
        with pytest.raises(ValueError, match=reason):
            study_settings(bad)
    from explorer.model import encode_scene

    settings, message = read_study_query({"study": encode_scene({"axes": "x"})})
    assert settings is None and message.startswith("The study settings in the link were "
                                                   "not used")


def test_a_failed_point_says_why_on_the_page(explorer_app):
    """A force from 100 kN/m with a moment of 300 kN m/m (the eccentricity then 3 m, off
    the 2 m base) to 750: the summary said "1 failed (no value)" and no more; it now
    gives the failed point's reason. An axis whose end no solve takes (a force from
    -100 kN/m, a punch pulled away) is not run at all, saying why."""
    app = explorer_app(scene=screen_scene())
    tab = app.study_tab
    tab.study_first.fill(Axis("loading.force", -100.0, 750.0, 3))
    assert not tab.start()
    said = html.unescape(tab.study_status.object)
    # in the tab's units, as typed (it read "loading.force = -100000 ... P = -100000 N/m")
    assert "Not run: parameter 1 (loading: force P): the scene is invalid at -100 kN/m " \
        "(loading.force: the punch is pulled away (P = -100 kN/m" in said, said
    tab.study_first.fill(Axis("loading.force", 100.0, 750.0, 3))
    tab.study_second.field.value = "loading.moment"
    tab.study_second.fill(Axis("loading.moment", 0.0, 300.0, 2))
    assert tab.start()
    assert tab.study_run.wait(300)
    assert tab.study_run.status == "done", tab.study_run.message
    assert int(tab.study_run.result.failed.sum()) == 1
    said = html.unescape(tab.study_status.object)
    assert "1 failed (no value). Failed: " in said, said
    assert "Failed: Loading, moment (loading.moment): the eccentricity" in said, said


def test_the_creep_coefficients_are_offered_and_vary_the_scene():
    """The Study and Fit tabs offered no creep field, not even a design code's relative
    humidity, although a back-analysis fits exactly those (docs/guides/back_analysis.md).
    Each model's coefficients are offered in screen units, inside the scene's bounds."""
    from explorer.model.fit import fit_choices
    from explorer.model.study import default_range

    offered = {name: {c.key: c for c in study_choices(read_preset(name))}
               for name in ("eccentric_creep", "young_concrete_50_years", "uniform_flat")}
    assert {"base.creep.compliance_final", "base.creep.rate", "base.creep.aging",
            "base.creep.beta", "base.creep.alpha"} <= set(offered["eccentric_creep"])
    humidity = offered["young_concrete_50_years"]["base.creep.relative_humidity"]
    assert (humidity.unit, humidity.value) == ("%", 60.0)
    axis = default_range(humidity, read_preset("young_concrete_50_years"))
    assert (axis.start, axis.stop) == (40.0, 90.0)  # not 30: the codes start at 40 %
    compliance = offered["uniform_flat"]["base.creep.compliance"]
    assert compliance.unit == "1/GPa" and compliance.value == pytest.approx(0.03)
    assert "base.creep.relative_humidity" in {
        c.key for c in fit_choices(read_preset("young_concrete_50_years"))}
    # a study over the final creep compliance: each point's scene carries it in SI
    scene = read_preset("uniform_flat")
    scene["times"] = [0.0, 30.0, 365.0]
    result = run(plan_study(scene, [Axis("base.creep.compliance", 0.02, 0.04, 2)])).result
    for j, c in enumerate((0.02e-9, 0.04e-9)):
        want = solve(apply_point(scene, {"base.creep.compliance": c}))
        np.testing.assert_allclose(result.outputs["settlement"][j], want.settlement,
                                   rtol=1e-12)
    assert result.outputs["settlement"][1, -1] > result.outputs["settlement"][0, -1]


def test_the_age_at_loading_is_offered_only_where_it_changes_the_answer():
    """On a base that does not age (an elastic one, or creep as a function of the time
    since loading alone) the age at loading changes nothing: a study of it drew a flat
    line, a fit of it could only end in "moves no reading"."""
    from core.presets import read_preset
    from explorer.model import fit_choices, study_choices

    for name, offered in (("uniform_flat", False), ("bare_layer", False),
                          ("patched_insert", False), ("eccentric_creep", True),
                          ("young_concrete_50_years", True)):
        scene = read_preset(name)
        for choices in (study_choices(scene), fit_choices(scene)):
            assert ("base.age_at_loading" in [c.key for c in choices]) == offered, name


def test_the_heat_map_png_labels_its_colour_bar() -> None:
    """The downloaded heat map's colour bar had no label (the output's unit was in the
    title alone): its name and unit now stand beside it, as the page's does."""
    import io

    from PIL import Image

    from explorer.plots.study_png import HEIGHT, WIDTH, design_chart_png

    planned = plan_study(screen_scene(), [Axis("loading.force", 300.0, 700.0, 2),
                                          Axis("coating[0].modulus", 400.0, 800.0, 2)])
    runner = run(planned)
    assert runner.status == "done", runner.message
    image = Image.open(io.BytesIO(design_chart_png(runner.result, "settlement", 0)))
    assert image.size == (WIDTH, HEIGHT)
    strip = np.asarray(image.convert("L"))[:, WIDTH - 26:WIDTH - 6]
    assert (strip < 128).sum() > 50  # the label's ink, right of the bar's ticks
