"""The benchmark commands refuse what would write their results in the wrong place."""

from __future__ import annotations

from pathlib import Path

import pytest

from benchmarks import cold_start, engines


def test_engines_out_is_a_folder_not_a_file_name(tmp_path: Path, capsys):
    target = tmp_path / "X.md"
    with pytest.raises(SystemExit) as stop:
        engines.main(["--out", str(target)])
    assert stop.value.code == 2
    assert "--out: " in capsys.readouterr().err
    assert not target.exists()  # no folder named like a file


def test_cold_start_out_is_a_folder_not_a_file_name(tmp_path: Path, capsys):
    target = tmp_path / "cold_start.md"
    target.write_text("kept\n")
    with pytest.raises(SystemExit) as stop:
        cold_start.main(["--out", str(target)])
    assert stop.value.code == 2
    assert "--out: " in capsys.readouterr().err
    assert target.read_text() == "kept\n"  # refused before any run
