"""The two-punch entry of the work-precision report runs, and what it reports holds: its
reference converges, each run's error is within its estimate."""

from __future__ import annotations

import json
from pathlib import Path

from benchmarks import work_precision


def test_the_two_punch_entry_alone(tmp_path: Path) -> None:
    assert work_precision.main(["--quick", "--scenes", "two_punches",
                                "--out", str(tmp_path)]) == 0
    data = json.loads((tmp_path / "work_precision.json").read_text())
    entry = data["two_punches"]
    # tol 1e-11 against 1e-12: 7.6e-14 measured
    assert max(entry["reference"]["agreement"].values()) < 1e-12
    assert [run["setting"] for run in entry["runs"]] == ["tol=1e-04", "tol=1e-07"]
    for run in entry["runs"]:
        # measured: 6.0e-9 and 5.3e-9 against estimates 1.0e-7 and 6.8e-8
        assert run["error"] <= run["estimate"]
    report = (tmp_path / "work_precision.md").read_text()
    assert "| two_punches | " in report and "### Two punches (`two_punches`)" in report
    assert (tmp_path / "two_punches.png").exists()
