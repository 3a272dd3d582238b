"""The benchmark commands refuse what would write their results in the wrong place."""

from __future__ import annotations

from pathlib import Path

import pytest

from benchmarks import cold_start, compare_servers, compare_trees, engines, suite_at_load


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


@pytest.mark.parametrize("args", [["--out", "FILE"], ["--runs", "0"], ["--hogs", "-1"]])
def test_suite_at_load_refuses_before_any_run(tmp_path: Path, capsys, args: list[str]):
    """A file for the report's folder, no runs or negative hogs: refused before a clone."""
    target = tmp_path / "suite_at_load.md"
    target.write_text("kept\n")
    args = [str(target) if a == "FILE" else a for a in args]
    with pytest.raises(SystemExit) as stop:
        suite_at_load.main(args)
    assert stop.value.code == 2
    assert f"{args[0]}: " in capsys.readouterr().err
    assert target.read_text() == "kept\n"


def test_compare_trees_refuses_a_folder_without_the_package(tmp_path: Path, capsys):
    with pytest.raises(SystemExit) as stop:
        compare_trees.main([str(tmp_path), "bare_layer", "--no-write"])
    assert stop.value.code == 2
    assert "other: " in capsys.readouterr().err


def test_compare_trees_measures_this_tree_against_itself(capsys):
    """Two workers of the same tree, two short rounds each: the table's row."""
    root = Path(compare_trees.__file__).resolve().parent.parent
    compare_trees.main([str(root), "bare_layer", "--rounds", "2", "--seconds", "0.01",
                        "--no-write"])
    row = capsys.readouterr().out.strip().splitlines()[-1]
    assert row.startswith("| bare_layer | ") and row.count("|") == 6
    cells = [c.strip() for c in row.strip("|").split("|")]
    mine, theirs, ratio = (float(c) for c in cells[1:4])
    assert mine > 0.0 and theirs > 0.0 and 0.0 < ratio < float("inf")


def test_compare_trees_names_the_tree_whose_worker_ended(tmp_path: Path):
    """A tree whose worker cannot solve (here: its core package fails to import) ends
    the run with a message naming it."""
    (tmp_path / "core").mkdir()
    (tmp_path / "core" / "__init__.py").write_text("raise ImportError('a broken tree')\n")
    with pytest.raises(SystemExit) as stop:
        compare_trees.main([str(tmp_path), "bare_layer", "--rounds", "1", "--seconds",
                            "0.01", "--no-write"])
    assert "worker of the other tree ended" in str(stop.value)


def test_compare_servers_refuses_a_folder_without_the_package(tmp_path: Path, capsys):
    with pytest.raises(SystemExit) as stop:
        compare_servers.main([str(tmp_path), "--no-write"])
    assert stop.value.code == 2
    assert "other: " in capsys.readouterr().err


def test_compare_servers_refuses_an_unknown_preset_before_starting_a_server():
    root = Path(compare_servers.__file__).resolve().parent.parent
    with pytest.raises(SystemExit) as stop:
        compare_servers.main([str(root), "no_such_preset", "--no-write"])
    assert "presets: unknown no_such_preset" in str(stop.value)


def _scripts() -> list[Path]:
    folder = Path(cold_start.__file__).resolve().parent
    # (those with an option parser of their own answer --help through it)
    return sorted(p for p in folder.glob("*.py")
                  if p.name != "__init__.py" and 'if __name__ == "__main__":' in p.read_text()
                  and "argparse" not in p.read_text())


@pytest.mark.parametrize("script", _scripts(), ids=lambda p: p.stem)
def test_every_benchmark_answers_help_without_running(script: Path):
    """``--help`` prints what the script measures and writes nothing: a script without
    its own option parser ran its benchmark (45 s) and wrote over its committed report."""
    import subprocess
    import sys

    root = script.parent.parent
    results = root / "benchmarks" / "results"
    before = {p: p.stat().st_mtime_ns for p in results.iterdir()}
    done = subprocess.run([sys.executable, "-m", f"benchmarks.{script.stem}", "--help"],
                          cwd=root, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip(), "no help printed"
    assert {p: p.stat().st_mtime_ns for p in results.iterdir()} == before
