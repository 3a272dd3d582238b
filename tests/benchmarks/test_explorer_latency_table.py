"""The pure parts of the explorer latency benchmark: percentiles, the drag's summary, the
preset list of the command line and the Markdown table (no browser)."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from benchmarks import explorer_latency as bench
from core.presets import preset_names


def test_percentile_interpolates_between_order_statistics():
    values = [40.0, 10.0, 30.0, 20.0, 50.0]
    assert bench.percentile(values, 50) == 30.0
    assert bench.percentile(values, 0) == 10.0
    assert bench.percentile(values, 100) == 50.0
    # numpy's default (linear): position 0.95 * 4 = 3.8 between 40 and 50
    assert bench.percentile(values, 95) == pytest.approx(48.0, abs=1e-12)
    assert bench.percentile([7.0], 95) == 7.0
    assert math.isnan(bench.percentile([], 50))
    assert bench.percentile([1.0, float("nan"), 3.0], 50) == 2.0  # a missed step is left out


def test_drag_summary_splits_updates_at_the_release():
    summary = bench.drag_summary([5.0, 120.0, 300.0, 1040.0, 1150.0], down=100.0, up=1000.0)
    assert summary == {"during": 2, "after": 2, "last_after_ms": 150.0, "drag_ms": 900.0,
                       "previewed": False}
    assert bench.drag_kind(summary) == "live"
    released = bench.drag_summary([1300.0], down=100.0, up=1000.0, previewed=True)
    assert (released["during"], released["after"]) == (0, 1)
    assert bench.drag_kind(released) == "release"   # said, but nothing drawn: no preview
    assert bench.drag_summary([], down=0.0, up=10.0)["last_after_ms"] == 0.0
    previewed = bench.drag_summary([120.0, 1300.0], down=100.0, up=1000.0, previewed=True)
    assert bench.drag_kind(previewed) == "preview" and bench.drag_kind({}) == ""


def test_presets_all_or_named_in_the_order_given():
    known = preset_names()
    assert bench.parse_args([]).presets == list(known)
    assert bench.parse_args(["--presets", "all"]).presets == list(known)
    assert bench.parse_args(["--presets", f"{known[1]}, {known[0]}"]).presets == \
        [known[1], known[0]]


def test_unknown_preset_is_refused_by_name(capsys):
    with pytest.raises(SystemExit) as stop:
        bench.parse_args(["--presets", "uniform_flat,no_such_scene"])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert "--presets: unknown preset no_such_scene" in err


def test_quick_takes_fewer_steps_unless_told(tmp_path: Path, capsys):
    args = bench.parse_args(["--quick"])
    assert (args.repeats, args.loads) == (3, 2)
    assert bench.parse_args(["--quick", "--repeats", "7"]).repeats == 7
    assert (bench.parse_args([]).repeats, bench.parse_args([]).loads) == (9, 5)
    with pytest.raises(SystemExit):
        bench.parse_args(["--repeats", "0"])
    assert "--repeats: " in capsys.readouterr().err
    with pytest.raises(SystemExit):
        bench.parse_args(["--markdown", str(tmp_path)])
    assert "--markdown: " in capsys.readouterr().err


def _row(preset, slider, keys, drag, goal="geometry", label="", hidden=False):
    return {"preset": preset, "slider": slider, "goal": goal, "label": label,
            "key_ms": keys, "page_cpu": [50.0] * len(keys), "solve_ms": [20.0] * len(keys),
            "parts": [], "drag": drag, **({"hidden": True} if hidden else {})}


def test_markdown_table_marks_goals_live_and_hidden_sliders():
    rows = [
        _row("uniform_flat", "load", [60.0, 70.0, 80.0, 90.0, 95.0],
             {"during": 19, "after": 1, "last_after_ms": 40.0, "drag_ms": 1000.0},
             goal="load", label="force"),
        _row("uniform_flat", "base thickness", [150.0, 160.0, 170.0, 180.0, 400.0],
             {"during": 0, "after": 1, "last_after_ms": 350.0, "drag_ms": 1000.0}),
        _row("uniform_flat", "punch shape", [], None, hidden=True),
    ]
    meta = {"commit": "abc1234", "date": "2026-11-29 04:00 UTC", "load_before": "1.00",
            "load_after": "2.00", "command": "python -m benchmarks.explorer_latency"}
    text = bench.markdown_report(rows, {"uniform_flat": None, "worn_coating": 620.0},
                                 [1500.0, 1700.0], meta)
    lines = text.splitlines()
    assert "Commit `abc1234`, 2026-11-29 04:00 UTC" in text
    assert "    python -m benchmarks.explorer_latency" in lines
    assert "First page (median of 2): 1600 ms (goal 2000)." in text
    assert "| uniform_flat | on the page already | 500 |" in lines
    assert "| worn_coating | 620 | 500 **missed** |" in lines
    # p95 of 60..95: 95 - 0.2 * 5 = 94; live: 19 frames during the drag
    assert ("| uniform_flat | load (force) | 80 | 94 | 100 ok | 50 | 20 | live | 19 | 1 "
            "| 40 ok | 1000 | 5 |") in lines
    assert ("| uniform_flat | base thickness | 170 | 356 | 100 **missed** | 50 | 20 | "
            "release | 0 | 1 | 350 **missed** | 1000 | 5 |") in lines
    assert any(line.startswith("| uniform_flat | punch shape | hidden on this preset")
               for line in lines)
    # the summary per preset: worst p95, live, previewed and release sliders, latest update
    assert ("| uniform_flat | on the page already | 356 (base thickness) | load |  | "
            "base thickness | 350 (base thickness) |") in lines
    assert "| worn_coating | 620 |  |  |  |  |  |" in lines
    # every table row has as many cells as its header
    for table_header in ("| preset | switch |", "| preset | slider |",
                         "| preset | switch | worst"):
        start = next(k for k, line in enumerate(lines) if line.startswith(table_header))
        width = lines[start].count("|")
        block = [line for line in lines[start:] if line.startswith("|")]
        block = block[:next((k for k, line in enumerate(block[1:], 1)
                             if line.startswith("| preset")), len(block))]
        assert all(line.count("|") == width for line in block)


def test_the_table_is_written_again_from_a_runs_json(tmp_path: Path):
    import json

    rows = [_row("uniform_flat", "load", [60.0, 70.0],
                 {"during": 19, "after": 1, "last_after_ms": 40.0, "drag_ms": 1000.0},
                 goal="load", label="force")]
    meta = {"commit": "abc1234", "date": "2026-11-29 04:00 UTC", "load_before": "1.00",
            "load_after": "2.00", "command": "python -m benchmarks.explorer_latency"}
    data = tmp_path / "run.json"
    data.write_text(json.dumps({"meta": meta, "first_page": [1500.0],
                                "preset_switch": {"uniform_flat": None}, "rows": rows}))
    out = tmp_path / "table.md"
    bench.main(["--from-json", str(data), "--markdown", str(out)])
    assert out.read_text() == bench.markdown_report(rows, {"uniform_flat": None}, [1500.0],
                                                    meta)


def test_switches_only_takes_rounds_and_writes_its_own_table(capsys):
    args = bench.parse_args(["--switches-only"])
    assert args.rounds == 3 and Path(args.markdown) == bench.SWITCH_RESULTS
    assert bench.parse_args(["--switches-only", "--rounds", "5"]).rounds == 5
    with pytest.raises(SystemExit):
        bench.parse_args(["--switches-only", "--rounds", "0"])
    assert "--rounds: " in capsys.readouterr().err
    meta = {"commit": "abc", "date": "today", "load_before": "0.1", "load_after": "0.2",
            "command": "python -m benchmarks.explorer_latency --switches-only"}
    text = bench.switch_report({"fast": [420.0, 380.0, 610.0], "slow": [700.0, 520.0],
                                "never": [float("nan")]}, [1500.0], meta)
    # one row per preset: median, least, largest, samples and the goal met or missed
    assert "| fast | 420 | 380 | 610 | 3 | 500 ok |" in text
    assert "| slow | 610 | 520 | 700 | 2 | 500 **missed** |" in text
    assert "| never | | | | 0 | 500 |" in text
