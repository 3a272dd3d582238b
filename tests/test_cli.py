"""``python -m core``: solve to JSON and CSV, validate, and one-line errors (exit code 2)."""

from __future__ import annotations

import csv
import io
import json
import os
import subprocess
from pathlib import Path

import pytest

from core.scene import MAX_SCENE_BYTES
from tests.cli_runs import run_cli

ROOT = Path(__file__).resolve().parent.parent
SCENES = ROOT / "assets" / "scenes"


def run(*args: str | os.PathLike, cwd: Path = ROOT) -> subprocess.CompletedProcess:
    return run_cli(*args, cwd=cwd)


def scene_dict() -> dict:
    return json.loads((SCENES / "uniform_flat.json").read_text())


def assert_one_line_error(proc: subprocess.CompletedProcess, starts: str) -> None:
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("error: " + starts), lines[0]
    assert "Traceback" not in proc.stderr
    assert proc.stdout == ""


def test_solve_to_json(tmp_path: Path):
    out = tmp_path / "result.json"
    # the real entry point, in a process of its own
    proc = run_cli("solve", SCENES / "eccentric_creep.json", "--output", out, subprocess=True)
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr == ""  # no flags on a shipped scene, no warnings of any library
    result = json.loads(out.read_text())
    assert result["scene"]["name"] == "Eccentric force on young, aging concrete"
    n = len(result["times"])
    assert n == 60
    for key in ("settlement", "tilt", "force", "moment"):
        assert len(result[key]) == n
    assert len(result["x"]) == 201
    assert len(result["pressure"]) == 201 and all(len(row) == n for row in result["pressure"])
    assert result["flags"] == []
    assert result["units"]["force"] == "N/m"
    assert result["force"][0] == pytest.approx(8e5, rel=1e-12)
    assert result["settlement"][-1] > result["settlement"][0] > 0


def test_solve_to_csv_with_pressure(tmp_path: Path):
    out = tmp_path / "history.csv"
    pressure = tmp_path / "q.csv"
    proc = run("solve", SCENES / "patched_insert.json", "-o", out, "--pressure-csv", pressure)
    assert proc.returncode == 0, proc.stderr
    rows = list(csv.reader(io.StringIO(out.read_text())))
    assert rows[0] == ["time_day", "settlement_m", "tilt_rad", "force_N_per_m", "moment_N"]
    assert len(rows) == 1 + 50
    assert all(float(r[1]) == 5e-5 for r in rows[1:])  # the given settlement
    forces = [float(r[3]) for r in rows[1:]]
    assert forces[-1] < forces[0]  # relaxation under a held settlement
    qrows = list(csv.reader(io.StringIO(pressure.read_text())))
    assert qrows[0] == ["time_day", "x_m", "pressure_Pa"]
    assert len(qrows) == 1 + 50 * 201
    assert all(float(r[2]) > 0 for r in qrows[1:])


def test_solve_without_output_prints_a_summary():
    proc = run("solve", SCENES / "rounded_graded.json")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith("solved 'Rounded punch on a graded coating'")


def test_validate():
    proc = run("validate", SCENES / "stepped_punch.json")
    assert proc.returncode == 0
    assert proc.stdout.startswith("ok: 'Stepped punch base': statement 2")


def test_flags_are_warnings(tmp_path: Path):
    d = scene_dict()
    d["loading"] = {"force": 5e5, "moment": 5e5 * 0.6}
    d["times"] = {"end": 1.0, "count": 1}
    d.setdefault("solver", {})["contact"] = "full"  # "auto" would answer with lift-off
    path = tmp_path / "eccentric.json"
    path.write_text(json.dumps(d))
    proc = run("solve", path, "--output", tmp_path / "r.json")
    assert proc.returncode == 0
    assert proc.stderr.startswith("warning: contact_lost: ")
    assert json.loads((tmp_path / "r.json").read_text())["flags"] == ["contact_lost"]


def test_bad_field(tmp_path: Path):
    d = scene_dict()
    d["loading"] = {"forse": 5e5, "moment": 0.0}
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(d))
    for command in ("solve", "validate"):
        proc = run(command, path, "--output", tmp_path / "r.json") if command == "solve" \
            else run(command, path)
        assert_one_line_error(proc, "loading: unknown field 'forse'")
    assert not (tmp_path / "r.json").exists()


def test_bad_value(tmp_path: Path):
    d = scene_dict()
    d["coating"][0]["modulus"] = {"kind": "step", "values": [1e9, -3e6], "breaks": [0.12]}
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(d))
    assert_one_line_error(run("validate", path),
                          "coating[0].modulus: must be > 0, is -3e+06 at x = 0.12 m")


def test_not_json(tmp_path: Path):
    path = tmp_path / "scene.json"
    path.write_text("{\n  \"schema_version\": 1,\n  oops\n}\n")
    assert_one_line_error(run("solve", path, "-o", tmp_path / "r.json"),
                          f"{path}: not valid JSON (")


def test_too_large(tmp_path: Path):
    path = tmp_path / "huge.json"
    d = scene_dict()
    d["description"] = "y" * (MAX_SCENE_BYTES + 10)
    path.write_text(json.dumps(d))
    assert_one_line_error(run("validate", path), f"{path}: file is ")


def test_missing_file(tmp_path: Path):
    path = tmp_path / "nope.json"
    assert_one_line_error(run("validate", path), f"{path}: No such file or directory")


def test_bad_arguments(tmp_path: Path):
    assert_one_line_error(run_cli("solve", subprocess=True),
                          "python -m core solve: the following arguments")
    assert_one_line_error(run("frobnicate"), "python -m core: argument")
    assert_one_line_error(run("solve", SCENES / "uniform_flat.json", "-o", tmp_path / "r.txt"),
                          "--output: unsupported extension '.txt'")
