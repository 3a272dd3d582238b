"""``python -m core`` on a scene of several punches: validate, solve (summary and JSON),
and the outputs not written for them yet refused, naming the option."""

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


def test_outputs_not_written_for_several_punches_are_refused(tmp_path: Path) -> None:
    path = _pair_file(tmp_path)
    proc = run_cli("solve", path, "--output", tmp_path / "answer.csv")
    assert proc.returncode == 2
    assert "--output: a scene of several punches is written as JSON" in proc.stderr
