"""``python -m core`` for batches of checks: ``--strict`` exit codes, ``-`` for standard
input and output, ``--version``, ``schema``, ``validate`` against the JSON Schema, and
the version, scene and solver settings in every file written."""

from __future__ import annotations

import io
import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import core
from core.cli import EXIT_BAD_INPUT, EXIT_DESIGN_FAILED, EXIT_FLAGGED, EXIT_OK
from core.scene import load_json_schema, scene_from_dict, schema_text, solve
from tests.cli_runs import run_cli
from tests.conftest import base_scene, edited

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "core" / "presets" / "scenes"
STUDY = ROOT / "core" / "presets" / "studies" / "eccentric_design.json"


def quick_scene(**limits: float) -> dict:
    """The eccentric preset over 100 days at 4 times (a solve of ~0.1 s), with limits."""
    scene = json.loads((SCENES / "eccentric_creep.json").read_text())
    scene["times"] = {"end": 100.0, "count": 4}
    if limits:
        scene["limits"] = limits
    return scene


def flagged_scene(**limits: float) -> dict:
    """A footing past the middle third under full contact: flagged contact_lost."""
    scene = edited("loading", {"force": 5e5, "moment": 5e5 * 0.6})
    scene["times"] = {"end": 1.0, "count": 1}
    scene["solver"]["contact"] = "full"
    if limits:
        scene["limits"] = limits
    return scene


def extremes(scene: dict) -> tuple[float, float]:
    """The largest pressure [Pa] and tilt [rad] of the scene's answer."""
    result = solve(scene)
    return float(np.max(result.pressure_on_grid)), float(np.max(np.abs(result.tilt)))


def test_version() -> None:
    proc = run_cli("--version")
    assert proc.returncode == 0 and proc.stdout == f"coated-punch {core.__version__}\n"
    child = run_cli("--version", subprocess=True, timeout=60)
    assert child.returncode == 0 and child.stdout == proc.stdout


@pytest.mark.parametrize("kind", ["scene", "study"])
def test_schema_prints_the_shipped_schema(kind: str) -> None:
    proc = run_cli("schema", kind)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == schema_text(load_json_schema(kind))
    assert run_cli("schema").stdout == schema_text(load_json_schema("scene"))


def test_solve_from_stdin_to_stdout_records_version_scene_and_settings() -> None:
    scene = quick_scene(allowable_pressure=1e9)
    proc = run_cli("solve", "-", "-o", "-", stdin=json.dumps(scene))
    assert proc.returncode == EXIT_OK, proc.stderr
    data = json.loads(proc.stdout)
    assert list(data)[:4] == ["format", "program", "version", "solver"]
    assert data["version"] == core.__version__ and data["program"] == "coated-punch"
    settings = {"tol": 1e-6, "model_tol": 0.02, "contact": "auto"}
    assert {k: data["solver"][k] for k in settings} == settings
    assert data["solver"]["contact_model"] == "full" and data["solver"]["method"] == "nystrom"
    assert data["scene"] == scene_from_dict(scene).to_dict()
    assert data["design_check"]["passed"] is True
    assert len(data["times"]) == 4


def test_solve_from_stdin_as_csv_with_its_header() -> None:
    scene = quick_scene()
    proc = run_cli("solve", "-", "-o", "-", "--format", "csv", stdin=json.dumps(scene))
    assert proc.returncode == EXIT_OK, proc.stderr
    meta = dict(line[2:].split(": ", 1) for line in proc.stdout.splitlines()
                if line.startswith("# ") and ": " in line)
    assert meta["version"] == core.__version__
    assert json.loads(meta["scene_json"]) == scene_from_dict(scene).to_dict()
    assert json.loads(meta["solver"]) == {"tol": 1e-6, "model_tol": 0.02, "contact": "auto"}
    assert meta["flags"] == "none" and "design_check" not in meta
    table = pd.read_csv(io.StringIO(proc.stdout), comment="#")
    assert list(table.columns) == ["time_day", "settlement_m", "tilt_rad", "force_N_per_m",
                                   "moment_N"]
    assert len(table) == 4 and table["force_N_per_m"].iloc[0] == pytest.approx(8e5)


def test_pressure_csv_to_stdout_and_both_files_record_the_scene(tmp_path: Path) -> None:
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(quick_scene()))
    out = tmp_path / "result.json"
    proc = run_cli("solve", path, "-o", out, "--pressure-csv", "-")
    assert proc.returncode == EXIT_OK, proc.stderr
    assert proc.stdout.startswith(f"# coated-punch {core.__version__}: contact pressure")
    assert f"\n# version: {core.__version__}\n# scene_json: " in proc.stdout
    table = pd.read_csv(io.StringIO(proc.stdout), comment="#")
    assert list(table.columns) == ["time_day", "x_m", "pressure_Pa"] and len(table) == 4 * 201
    assert json.loads(out.read_text())["version"] == core.__version__


def test_only_one_output_may_be_stdout() -> None:
    proc = run_cli("solve", SCENES / "uniform_flat.json", "-o", "-", "--pressure-csv", "-")
    assert proc.returncode == EXIT_BAD_INPUT and proc.stdout == ""
    assert proc.stderr == "error: --pressure-csv: only one output may be '-' (standard " \
                          "output)\n"


def test_a_bad_scene_on_stdin_is_one_line() -> None:
    proc = run_cli("solve", "-", stdin="{not json")
    assert proc.returncode == EXIT_BAD_INPUT
    assert proc.stderr.startswith("error: <stdin>: not valid JSON") and proc.stdout == ""


def test_strict_passes_a_design_within_its_limits() -> None:
    q_max, tilt = extremes(quick_scene())
    scene = quick_scene(allowable_pressure=1.01 * q_max, tilt_limit=1.01 * tilt)
    proc = run_cli("solve", "-", "--strict", stdin=json.dumps(scene))
    assert proc.returncode == EXIT_OK and proc.stderr == ""
    assert "design check (whole history): pass" in proc.stdout


def test_strict_fails_an_exceeded_limit_with_its_own_code() -> None:
    q_max, _ = extremes(quick_scene())
    scene = json.dumps(quick_scene(allowable_pressure=0.99 * q_max))
    lax = run_cli("solve", "-", stdin=scene)
    assert lax.returncode == EXIT_OK
    assert lax.stderr.startswith("warning: design_check: largest contact pressure q_max")
    assert "FAIL" in lax.stderr and "design check (whole history): FAIL" in lax.stdout
    strict = run_cli("solve", "-", "--strict", "-o", "-", stdin=scene)
    assert strict.returncode == EXIT_DESIGN_FAILED == 3
    assert strict.stderr.splitlines()[-1] == ("error: strict: the design check failed "
                                              "(allowable_pressure); exit code 3")
    assert json.loads(strict.stdout)["design_check"]["passed"] is False  # still written


def test_strict_fails_a_flagged_answer_and_the_flag_wins() -> None:
    lax = run_cli("solve", "-", stdin=json.dumps(flagged_scene()))
    assert lax.returncode == EXIT_OK and lax.stderr.startswith("warning: contact_lost: ")
    strict = run_cli("solve", "-", "--strict", stdin=json.dumps(flagged_scene()))
    assert strict.returncode == EXIT_FLAGGED == 4
    assert strict.stderr.splitlines()[-1] == ("error: strict: the answer is flagged "
                                              "(contact_lost); exit code 4")
    # a flagged answer that also exceeds a limit: its check cannot be trusted
    both = run_cli("solve", "-", "--strict", stdin=json.dumps(flagged_scene(
        settlement_limit=0.0)))
    assert both.returncode == EXIT_FLAGGED
    assert "warning: design_check: largest settlement" in both.stderr


def test_a_pass_on_a_flagged_answer_is_qualified_everywhere(tmp_path: Path) -> None:
    """A two-layer pad whose coating model was 70 % off read "design check: pass" and
    "Every limit the scene sets holds." beside its model_error flag: the verdict on a
    flagged answer now says what it is worth, in the summary, the CSV and the report."""
    from core.report import sections

    scene = flagged_scene(settlement_limit=1.0)   # a limit that holds by far
    summary = run_cli("solve", "-", stdin=json.dumps(scene))
    assert summary.returncode == EXIT_OK, summary.stderr
    caution = ("pass (on an answer flagged contact_lost: the check is only as good as "
               "that answer, not to be relied on)")
    assert f"design check (whole history): {caution}" in summary.stdout
    written = run_cli("solve", "-", "-o", tmp_path / "r.csv", stdin=json.dumps(scene))
    assert written.returncode == EXIT_OK, written.stderr
    assert f"\n# design_check: {caution}; largest contact pressure" in \
        (tmp_path / "r.csv").read_text()
    design = next(s for s in sections(solve(scene)) if s.title == "Design check")
    assert design.lead == ("Every limit the scene sets holds, on an answer flagged "
                           "contact_lost: the check is only as good as that answer, not "
                           "to be relied on.") and design.tone == "bad"
    plain = next(s for s in sections(solve(quick_scene(settlement_limit=1.0)))
                 if s.title == "Design check")
    assert plain.lead == "Every limit the scene sets holds." and plain.tone == "good"


def test_strict_in_a_process_of_its_own(tmp_path: Path) -> None:
    q_max, _ = extremes(quick_scene())
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(quick_scene(allowable_pressure=0.5 * q_max)))
    proc = run_cli("solve", path, "--strict", "-o", tmp_path / "r.csv", subprocess=True)
    assert proc.returncode == EXIT_DESIGN_FAILED, proc.stderr
    text = (tmp_path / "r.csv").read_text()
    assert "\n# design_check: FAIL; largest contact pressure q_max" in text


def test_validate_a_study_and_a_scene_from_stdin() -> None:
    proc = run_cli("validate", STUDY)
    assert proc.returncode == EXIT_OK, proc.stderr
    assert proc.stdout.startswith("ok: study 'Eccentric strip footing") and "338 points" in \
        proc.stdout
    proc = run_cli("validate", "-", stdin=json.dumps(base_scene()))
    assert proc.returncode == EXIT_OK and proc.stdout.startswith("ok: 'Uniform coating")


def test_validate_reports_every_schema_problem_with_its_field(tmp_path: Path) -> None:
    scene = edited("solver", {"tol": 1.0, "contact": "sticky"})
    scene["coating"][0]["poisson"] = 0.7
    scene["limits"] = {"allowable_pressure": -5.0}
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(scene))
    proc = run_cli("validate", path)
    assert proc.returncode == EXIT_BAD_INPUT and proc.stdout == ""
    assert proc.stderr.splitlines() == [
        "error: coating[0].poisson: must be < 0.5, got 0.7",
        "error: solver.tol: must be in [1e-12, 0.01], got 1",
        "error: solver.contact: must be one of 'auto', 'full', 'unilateral', got 'sticky'",
        # with the field's unit, as the validator gives it
        "error: limits.allowable_pressure: must be >= 0 Pa, got -5 Pa",
    ]


def test_validate_then_checks_what_the_schema_cannot(tmp_path: Path) -> None:
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(edited("times", [0.0, 20.0, 10.0])))  # not increasing
    proc = run_cli("validate", path)
    assert proc.returncode == EXIT_BAD_INPUT
    assert proc.stderr == "error: times[2]: times must increase, got 10 after 20\n"
    study = json.loads(STUDY.read_text())
    study["scene"] = str(STUDY.parent / study["scene"])  # where the study file is not
    study["vary"][0]["field"] = "coating[3].modulus"
    path.write_text(json.dumps(study))
    proc = run_cli("validate", path)
    assert proc.returncode == EXIT_BAD_INPUT
    assert proc.stderr.startswith("error: vary[0].field: coating[3].modulus: no such field")
