"""The report speaks of the coating model's error from the best evidence: the FE
check's measurement when it was made for the scene, else the estimate."""

from __future__ import annotations

import holoviews  # noqa: F401  (installed by the test set-up)
import pytest

import core
from core.presets import read_preset
from core.report import report_html
from core.report.content import describe
from core.scene import check_scene, checked_key, model_error_evidence
from tests.cli_runs import run_cli
from tests.support.epoxy_on_pad import ESTIMATE, MEASURED, epoxy_on_pad_scene

MEASURED_ROW = "coating model error (measured by the FE check, relative)"
ESTIMATED_ROW = "coating model error (estimated, relative)"


@pytest.fixture(scope="module")
def result() -> core.SceneSolution:
    return core.solve(epoxy_on_pad_scene())


def _check(scene: dict, error: float) -> dict:
    """What check_scene reports, as far as the evidence reads it."""
    return {"scene_key": checked_key(scene), "model_error": error, "time_day": 0.0}


def test_the_estimate_alone_flags_this_scene(result):
    assert result.model_error["estimate"] == pytest.approx(ESTIMATE, abs=1e-4)
    assert "model_error" in result.flags
    text = describe(result)
    assert "estimated" in text["Validity"]["rows"]["model_error"]
    assert MEASURED_ROW not in text["Accuracy"]["rows"]


def test_a_measurement_of_the_scene_overrides_the_estimate(result):
    text = describe(result, check=_check(epoxy_on_pad_scene(), MEASURED))
    validity = text["Validity"]
    assert validity["tone"] == "bad"
    assert "3.58 %" in validity["rows"]["model_error"]
    assert "measured by the FE check" in validity["rows"]["model_error"]
    rows = text["Accuracy"]["rows"]
    # in percent, as the page writes them (the report read "3.6e-02")
    assert rows[MEASURED_ROW].startswith("3.58 % at t = 0 days (FLAGGED: above "
                                         "solver.model_tol 2 %)")
    # next to it, not replaced; "1.39 % (flagged above 2 %)" read as a flag where none was
    assert rows[ESTIMATED_ROW].startswith(
        "4.64 % of the tilt α (FLAGGED: above solver.model_tol 2 %)")


def test_a_measurement_names_its_unknown_and_both_answers(result):
    """The report read "135 % at t = 0 days" where the page names the unknown measured
    and shows the fast and the resolved answer (an engineer's audit)."""
    check = {**_check(epoxy_on_pad_scene(), MEASURED),
             "errors": {"settlement": 0.004, "tilt": MEASURED, "force": 0.0, "moment": 0.0},
             "fast": {"settlement": 4.2e-5, "tilt": 6.2e-5, "force": 8e5, "moment": 2e5},
             "fe": {"settlement": 4.18e-5, "tilt": 5.9857e-5, "force": 8e5, "moment": 2e5}}
    rows = describe(result, check=check)["Accuracy"]["rows"]
    assert rows[MEASURED_ROW].startswith(
        "3.58 % of the tilt α (6.2e-05 rad fast against 5.9857e-05 rad resolved) at t = 0 "
        "days (FLAGGED"), rows[MEASURED_ROW]


def test_a_measurement_within_the_tolerance_lowers_an_estimated_flag(result):
    scene = epoxy_on_pad_scene()
    scene["solver"] = {"model_tol": 0.01}  # the estimate 4.64 % is flagged
    strict = core.solve(scene)
    assert "model_error" in strict.flags
    text = describe(strict, check=_check(scene, 0.005))
    assert "model_error" not in text["Validity"]["rows"]
    assert "(within solver.model_tol 1 %)" in text["Accuracy"]["rows"][MEASURED_ROW]


def test_a_measurement_of_another_scene_is_ignored(result):
    other = epoxy_on_pad_scene()
    other["loading"]["moment"] = 0.0  # another eccentricity: another model error
    evidence = model_error_evidence(result.scene, ESTIMATE, _check(other, MEASURED))
    assert evidence["source"] == "estimated" and evidence["flagged"]
    assert MEASURED_ROW not in describe(result, check=_check(other, MEASURED))["Accuracy"]["rows"]


def test_the_output_times_and_solver_settings_do_not_void_a_measurement():
    scene = epoxy_on_pad_scene()
    changed = epoxy_on_pad_scene()
    changed["times"] = [1.0, 10.0]
    changed["solver"] = {"tol": 1e-5, "model_tol": 0.03}
    changed["name"] = "renamed"
    assert checked_key(scene) == checked_key(changed)


@pytest.mark.slow
def test_the_report_carries_the_real_check(result):
    check = check_scene(result.scene, 0.0, level=0)
    assert check["model_error"] == pytest.approx(MEASURED, abs=1e-3)
    text = report_html(result, check=check)
    assert MEASURED_ROW in text and "3.58 %" in text


@pytest.mark.slow
def test_the_command_line_report_runs_the_check(tmp_path):
    path = tmp_path / "scene.json"
    core.save_scene(epoxy_on_pad_scene(), path)
    plain = run_cli("report", path, "-o", tmp_path / "plain.html")
    assert plain.returncode == 0 and "warning: model_error" in plain.stderr
    # the pad lies inside the model's measured map: nothing is said to be extrapolated
    assert "beyond_model_map" not in plain.stderr
    done = run_cli("report", path, "-o", tmp_path / "checked.html", "--fe-check")
    assert done.returncode == 0, done.stderr
    assert "3.58 % measured by the FE check" in done.stderr
    assert "warning: model_error" in done.stderr
    assert MEASURED_ROW in (tmp_path / "checked.html").read_text()
    strict = run_cli("report", path, "-o", tmp_path / "strict.html", "--fe-check",
                     "--strict")
    assert strict.returncode == 4 and "model_error" in strict.stderr


def test_without_a_check_only_the_threshold_is_read(monkeypatch):
    """A result's scene was validated when it was solved: without a check, the evidence
    reads its solver.model_tol (default or given, checked) and nothing else of it, the
    same answer as from the validated scene."""
    import core.scene.evidence as evidence_module

    scene = epoxy_on_pad_scene()
    validated = core.scene_from_dict(scene)
    expected = model_error_evidence(validated, ESTIMATE)
    assert expected["model_tol"] == pytest.approx(0.02)  # the default
    calls = []
    monkeypatch.setattr(evidence_module, "scene_from_dict",
                        lambda d: calls.append(d) or validated)
    assert model_error_evidence(scene, ESTIMATE) == expected and calls == []
    scene["solver"] = {"model_tol": 0.05}
    assert not model_error_evidence(scene, ESTIMATE)["flagged"]  # 4.6 % within 5 %
    scene["solver"] = {"model_tol": 2.0}
    with pytest.raises(ValueError, match=r"solver\.model_tol: must be in"):
        model_error_evidence(scene, ESTIMATE)
    # with a check the whole scene is validated, to compare it with the checked one
    model_error_evidence(epoxy_on_pad_scene(), ESTIMATE, _check(epoxy_on_pad_scene(), MEASURED))
    assert len(calls) >= 1


def test_an_estimate_within_the_tolerance_reads_within_it():
    # "1.39 % (flagged above 2 %)" read as a flag where the estimate was within tol
    quiet = core.solve(read_preset("uniform_flat"))
    assert "model_error" not in quiet.flags
    row = describe(quiet)["Accuracy"]["rows"][ESTIMATED_ROW]
    assert row.endswith("(within solver.model_tol 2 %)") and "FLAGGED" not in row


def test_the_fe_checks_pressure_is_reported_and_qualifies_the_design_check():
    """``report --fe-check`` gave the settlement's measurement alone: the check's pressure
    difference (8.5 % at x = -0.82 m, which the command line warns of) was not in the
    report, and its design check passed a pressure limit with no word of it."""
    scene = epoxy_on_pad_scene()
    scene["limits"] = {"allowable_pressure": 1e8}
    result = core.solve(scene)
    check = {**_check(scene, MEASURED), "errors": {"pressure": 0.085}, "model_tol": 0.02,
             "pressure_fast_Pa": 3.0e5, "pressure_fe_Pa": 2.7e5, "pressure_error_at_m": -0.82}
    text = describe(result, check=check)
    assert text["Accuracy"]["rows"]["contact pressure against the FE model"] == (
        "300 kPa against 270 kPa at x = -0.82 m, where they differ most: 8.5 % of the "
        "largest pressure (FLAGGED: above solver.model_tol 2 %)")
    design = text["Design check"]
    assert design["tone"] == "bad"
    assert design["notes"] == ["FE check: the fast answer's q differs from the resolved "
                               "model's by 8.50 % at x = -0.82 m (over solver.model_tol 2 %):"
                               " q there, its largest value and a pressure limit checked on "
                               "it are not to be relied on (the thin layer's q is local: it "
                               "follows the coating's compliance at each point, where the "
                               "resolved layers spread the load; beside an abrupt change of "
                               "the coating it jumps)"]
    # a scene that limits its settlement alone (its model error measured within tol, so
    # no flag qualifies the verdict): the note, and no red for it
    scene["limits"] = {"settlement_limit": 1.0}
    settled = describe(core.solve(scene), check={**check, "model_error": 0.01,
                                                 "scene_key": checked_key(scene)})
    assert settled["Design check"]["notes"] == design["notes"]
    assert settled["Design check"]["tone"] == "good"
    # without the check, or with one of another scene, neither is said
    plain = describe(result)
    assert "contact pressure against the FE model" not in plain["Accuracy"]["rows"]
    assert plain["Design check"]["notes"] == []
