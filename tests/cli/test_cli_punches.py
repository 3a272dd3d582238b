"""``python -m core`` on a scene of several punches: validate, solve (summary, JSON, the
histories and q over the surface as CSV, --strict per punch) and the report."""

from __future__ import annotations

import json
from pathlib import Path

from tests.cli_runs import run_cli
from tests.conftest import scene_file


def _pair_file(tmp_path: Path) -> Path:
    d = scene_file("uniform_flat")
    d["base"]["creep"] = {"model": "elastic", "modulus": 3.0e10}
    d["times"] = {"end": 10.0, "count": 3}
    del d["punch"], d["loading"]
    d["punches"] = [{"center": -1.5, "half_width": 1.0, "loading": {"force": 5e5, "moment": 0}},
                    {"center": 1.5, "half_width": 0.6, "loading": {"tilt": 0, "force": 3e5}}]
    path = tmp_path / "pair.json"
    path.write_text(json.dumps(d))
    return path


def test_validate_and_solve_a_pair(tmp_path: Path) -> None:
    path = _pair_file(tmp_path)
    proc = run_cli("validate", path)
    assert proc.returncode == 0, proc.stderr
    assert "2 punches (statements 4, 3)" in proc.stdout
    proc = run_cli("solve", path)
    assert proc.returncode == 0, proc.stderr
    assert "punches[0] at x = -1.5 m" in proc.stdout and "punches[1] at x = 1.5 m" in proc.stdout
    out = tmp_path / "answer.json"
    proc = run_cli("solve", path, "--output", out)
    assert proc.returncode == 0, proc.stderr
    answer = json.loads(out.read_text())
    assert [p["center"] for p in answer["punches"]] == [-1.5, 1.5]
    assert answer["punches"][1]["force"][0] == 3e5
    assert answer["scene"]["punches"][1]["loading"] == {"tilt": 0.0, "force": 300000.0}


def test_a_pair_is_written_as_csv(tmp_path: Path) -> None:
    path = _pair_file(tmp_path)
    out, pressure = tmp_path / "answer.csv", tmp_path / "q.csv"
    proc = run_cli("solve", path, "--output", out, "--pressure-csv", pressure)
    assert proc.returncode == 0, proc.stderr
    head = [line for line in out.read_text().splitlines() if line.startswith("#")]
    assert any(line.startswith("# scene_json: {") and '"punches"' in line for line in head)
    table = [line for line in out.read_text().splitlines() if not line.startswith("#")]
    assert table[0].startswith("time_day,punches[0].settlement_m,punches[0].tilt_rad,")
    assert table[0].endswith(",punches[1].force_N_per_m,punches[1].moment_N")
    assert len(table) == 1 + 3  # the header and the three output times
    rows = [line.split(",") for line in pressure.read_text().splitlines()
            if not line.startswith("#")]
    assert rows[0] == ["time_day", "x_m", "pressure_Pa"]
    x = [float(r[1]) for r in rows[1:] if float(r[0]) == 0.0]
    assert x[0] == -2.5 and x[-1] == 2.1  # the global x, from the first zone to the last


def test_the_csv_goes_to_standard_output_and_strict_names_the_punch(tmp_path: Path) -> None:
    d = json.loads(_pair_file(tmp_path).read_text())
    d["limits"] = {"allowable_pressure": 4.0e5}  # punch 0 reaches 4.06e5 Pa at its edge
    path = tmp_path / "limited.json"
    path.write_text(json.dumps(d))
    proc = run_cli("solve", path, "--output", "-", "--format", "csv", "--strict")
    assert proc.returncode == 3
    assert "# punches[0] design_check: FAIL" in proc.stdout
    assert "# punches[1] design_check: pass" in proc.stdout
    assert "warning: punches[0].design_check: largest contact pressure" in proc.stderr
    assert "x = -2.5 m" in proc.stderr  # where it is reached, in the global x
    assert "(punches[0].allowable_pressure); exit code 3" in proc.stderr


def test_a_report_of_a_pair(tmp_path: Path) -> None:
    path = _pair_file(tmp_path)
    out = tmp_path / "report.html"
    proc = run_cli("report", path, "--output", out, "--time", "10")
    assert proc.returncode == 0, proc.stderr
    text = out.read_text()
    assert "punches[0]" in text and "punches[1]" in text
    proc = run_cli("report", path, "--output", out, "--fe-check")
    assert proc.returncode == 2
    assert "--fe-check: the finite-element check is of one punch" in proc.stderr
