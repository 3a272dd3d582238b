"""The explorer's "check the coating model" button, without a browser."""

from __future__ import annotations

from explorer.views.coating import check_report_html


class _Held:
    """An executor that keeps the work until the test runs it."""

    def __init__(self) -> None:
        self.work: list = []

    def submit(self, fn, *args):
        self.work.append((fn, args))




def test_the_check_runs_off_the_page_and_shows_the_model_error_beside_its_estimate(
        explorer_app, monkeypatch):
    from explorer.views import coating

    held = _Held()
    app = explorer_app()
    app.controller._executor = held  # a served session's solves run off the page
    started: list = []  # the check: on a thread of its own (it may wait for another)
    monkeypatch.setattr(coating, "start_in_background", started.append)
    check = app.coating_tab.check
    check.run()
    # while the FE model solves, the page shows progress and the button waits
    assert len(started) == 1 and check.progress.visible and check.button.disabled
    assert held.work == []  # not on the solver pool, which serves the slider solves
    started.pop()()
    assert not check.progress.visible and not check.button.disabled
    text = check.result.object
    assert "model error: measured" in text and "estimated" in text, text
    assert "Coating model: thin layer" in text  # the default preset's base creeps
    for row in ("settlement [mm]", "tilt [mrad]", "pressure"):
        assert row in text


def test_report_marks_the_given_quantities():
    report = {"errors": {"settlement": 0.01, "tilt": 0.02, "force": 0.0, "moment": 0.0,
                         "pressure": 0.03},
              "fast": {"settlement": 1e-3, "tilt": 1e-4, "force": 1e5, "moment": 1e4},
              "fe": {"settlement": 0.99e-3, "tilt": 0.98e-4, "force": 1e5, "moment": 1e4},
              "model_error": 0.02, "estimate": 0.015, "coating_model": "thin layer",
              "given": ["force", "moment"], "fe_dofs": 25000, "fe_seconds": 1.2}
    text = check_report_html(report)
    assert text.count("given") == 2 and "+1.000" in text and "measured 2 %" in text


def test_report_of_a_lifting_punch_shows_both_contact_sets():
    report = {"errors": {"settlement": -0.84, "tilt": 0.70, "force": 0.0, "moment": 0.0,
                         "pressure": 0.39, "contact_ends": 0.0205},
              "fast": {"settlement": -6e-4, "tilt": 7.5e-4, "force": 5e5, "moment": 4.75e5},
              "fe": {"settlement": -3.3e-4, "tilt": 4.4e-4, "force": 5e5, "moment": 4.75e5},
              "model_error": 0.84, "estimate": 0.046, "coating_model": "thin layer",
              "given": ["force", "moment"], "fe_dofs": 66087, "fe_seconds": 4.5,
              "contact_lost": False,
              "lift_off": {"fast": [[0.8463, 1.0]], "fe": [[0.8258, 1.0]],
                           "fe_end_uncertainty": 2e-4, "fe_sweeps": 4, "fe_converged": True}}
    text = check_report_html(report)
    assert "compared with lift-off" in text
    assert "fast [0.8463, 1] m, FE [0.8258, 1] m" in text and "0.0205 a apart" in text


def test_round_off_of_a_centred_load_reads_zero():
    # the FE tilt of a centred load is round-off (-2.5e-18 rad): it read "-2.4826e-15"
    report = {"errors": {"settlement": 0.01, "tilt": 0.0, "force": 0.0, "moment": 0.0,
                         "pressure": 0.03},
              "fast": {"settlement": 1e-3, "tilt": 3e-20, "force": 1e5, "moment": 1e-11},
              "fe": {"settlement": 0.99e-3, "tilt": -2.4826e-18, "force": 1e5,
                     "moment": 2e-10},
              "model_error": 0.01, "estimate": 0.015, "coating_model": "thin layer",
              "half_width_m": 1.0, "given": ["force", "moment"], "fe_dofs": 25000,
              "fe_seconds": 1.2}
    text = check_report_html(report)
    assert "e-1" not in text and "e-2" not in text
    assert "<td>tilt [mrad]</td><td>0</td><td>0</td>" in text


def test_a_report_of_an_earlier_scene_says_so_until_that_scene_is_back(explorer_app):
    app = explorer_app(solved=True)
    check = app.coating_tab.check
    check.run()  # no executor: solved here
    assert "model error: measured" in check.result.object
    assert "Made for an earlier scene" not in check.result.object
    force = app.state.loading.histories["force"]
    force.value = 400.0
    app.controller.solve_now()
    # the report stayed as if it were this scene's (the badges had gone back to the
    # estimate, the panel had not)
    assert check.result.object.startswith("<span class='cp-msg coating-check-stale-note'>")
    force.value = 500.0
    app.controller.solve_now()
    assert "Made for an earlier scene" not in check.result.object


def test_a_report_arriving_after_the_scene_changed_says_it_is_of_an_earlier_scene(
        explorer_app, monkeypatch):
    from explorer.views import coating

    app = explorer_app(solved=True)
    app.controller._executor = _Held()
    started: list = []
    monkeypatch.setattr(coating, "start_in_background", started.append)
    check = app.coating_tab.check
    check.run()
    app.controller._executor = None
    app.state.loading.histories["force"].value = 400.0  # changed while the FE model solves
    app.controller.solve_now()
    started.pop()()
    # the report came unmarked, as if it were of the scene on screen
    assert check.result.object.startswith("<span class='cp-msg coating-check-stale-note'>")


def test_a_pressure_error_over_the_model_tolerance_is_said_with_where():
    """The check read "pressure 42.750" beside "model error: measured 0.39 %" with no word
    (the verdict weighs the unknown scalars); and the default scene's FE tilt read
    "-2.0939e-12" mrad (8.6e-11 of its settlement over a)."""
    report = {"errors": {"settlement": 0.0, "tilt": 0.0, "force": -0.0039, "moment": 0.0,
                         "pressure": 0.4275},
              "fast": {"settlement": 5e-5, "tilt": 0.0, "force": 8.42e5, "moment": 5e-12},
              "fe": {"settlement": 5e-5, "tilt": -2.09e-15 / 0.75, "force": 8.45e5,
                     "moment": 4.5e-5},
              "model_error": 0.0039, "estimate": 0.0059, "coating_model": "thin layer",
              "half_width_m": 0.75, "given": ["settlement", "tilt"], "fe_dofs": 85803,
              "fe_seconds": 1.1, "pressure_error_at_m": 0.15, "model_tol": 0.02,
              "pressure_fast_Pa": 1.52e6, "pressure_fe_Pa": 1.065e6}
    text = check_report_html(report)
    # the two pressures there, in kPa (the cells were empty: an error beside no values)
    assert ("pressure q [kPa], |x| &le; 0.9 a (at x = 0.15 m, where they differ most)"
            "</td><td>1520</td><td>1065</td><td>42.750</td>") in text
    assert "check-pressure-caution" in text and "by 42.75 % at x = 0.15 m" in text
    assert "e-1" not in text
    report["errors"]["pressure"] = 0.01            # within the tolerance: nothing said
    assert "check-pressure-caution" not in check_report_html(report)
