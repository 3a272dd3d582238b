"""``python -m core``: solve to JSON and CSV, validate, and one-line errors (exit code 2)."""

from __future__ import annotations

import csv
import io
import json
import os
import subprocess
from pathlib import Path
from typing import Any

import pytest

import core
from core.cli import main as cli_main
from core.scene import MAX_SCENE_BYTES
from tests.cli_runs import run_cli
from tests.conftest import DELETE, base_scene, edited, scene_file
from tests.scene.test_scene_refusals import BAD_VALUES

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "core" / "presets" / "scenes"


def run(*args: str | os.PathLike, cwd: Path = ROOT) -> subprocess.CompletedProcess:
    return run_cli(*args, cwd=cwd)


def scene_dict() -> dict:
    return scene_file("uniform_flat")


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
    # as preset and sweep say it (a run with --output printed nothing at all)
    assert proc.stdout == f"written to {out}\n"
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
    # "N" alone read as a force to an engineer filing the file (a teacher's audit)
    assert result["units"]["moment"].startswith("N·m/m")
    assert result["force"][0] == pytest.approx(8e5, rel=1e-12)
    assert result["settlement"][-1] > result["settlement"][0] > 0


def test_solve_to_csv_with_pressure(tmp_path: Path):
    out = tmp_path / "history.csv"
    pressure = tmp_path / "q.csv"
    proc = run("solve", SCENES / "patched_insert.json", "-o", out, "--pressure-csv", pressure)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == f"written to {out} and {pressure}\n"
    # with one of them on standard output, nothing is said there but its data
    proc = run("solve", SCENES / "patched_insert.json", "-o", out, "--pressure-csv", "-")
    assert proc.stdout.startswith("# ") and "written to" not in proc.stdout
    rows = list(csv.reader(line for line in io.StringIO(out.read_text())
                           if not line.startswith("#")))
    assert rows[0] == ["time_day", "settlement_m", "tilt_rad", "force_N_per_m", "moment_N"]
    assert len(rows) == 1 + 50
    assert all(float(r[1]) == 5e-5 for r in rows[1:])  # the given settlement
    forces = [float(r[3]) for r in rows[1:]]
    assert forces[-1] < forces[0]  # relaxation under a held settlement
    qrows = list(csv.reader(line for line in io.StringIO(pressure.read_text())
                            if not line.startswith("#")))
    assert qrows[0] == ["time_day", "x_m", "pressure_Pa"]
    assert len(qrows) == 1 + 50 * 201
    assert all(float(r[2]) > 0 for r in qrows[1:])


def test_solve_without_output_prints_a_summary():
    proc = run("solve", SCENES / "rounded_graded.json")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith("solved 'Rounded punch on a graded coating'")
    # a moment per unit length reads in N·m/m (the CSV column keeps its name, moment_N)
    assert proc.stdout.splitlines()[1].split() == ["time_day", "settlement_m", "tilt_rad",
                                                   "force_N/m", "moment_N·m/m"]
    result = core.solve(core.load_scene(SCENES / "rounded_graded.json"))
    peak = result.pressure_on_grid.max()
    # in contact up to the punch's ends: unbounded there, given where the answer holds it
    assert (f"largest contact pressure q: unbounded at the corner x = 0.5 m (a rigid corner: "
            f"q ~ 1/sqrt(distance)); {peak:.6g} Pa at 2 mm from it") in proc.stdout
    assert "flags: none" in proc.stdout


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
                          "coating[0].modulus: must be >= 10000, is -3e+06 Pa at x = 0.12 m "
                          "(moduli are in Pa")


def test_validate_refuses_what_solve_would(tmp_path: Path):
    """A force that underflows once scaled by the base modulus: ``validate`` said ok (exit
    0) while ``solve`` failed (exit 1, naming ``force``); both now refuse it as input."""
    d = scene_dict()
    d["loading"]["force"] = 1e-320
    path = tmp_path / "tiny.json"
    path.write_text(json.dumps(d))
    for proc in (run("validate", path), run("solve", path)):
        assert_one_line_error(proc, "loading.force: 9.99989e-321 N/m at t = 0 days after "
                                    "loading is too small")


@pytest.mark.parametrize("field, value, line", [
    ("punch.half_width", -1.0, "punch.half_width: must be > 0 m, got -1 m"),
    ("base.thickness", -2.0, "base.thickness: must be > 0 m, got -2 m"),
    ("base.age_at_loading", -3.0, "base.age_at_loading: must be > 0 days, got -3 days"),
    ("coating[0].thickness", -0.01, "coating[0].thickness: must be > 0 m, got -0.01 m"),
])
def test_validate_and_solve_word_a_refused_number_alike(tmp_path: Path, field: str,
                                                        value: float, line: str):
    """The schema's check (``validate``) gave the unit, the validator (``solve``, the
    page, the API) did not ("must be > 0, got -1"); a constant coating thickness is a
    profile, which both word by where it fails ("is -0.01 m at x = -1 m")."""
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(edited(field, value, scene_dict())))
    validated = run("validate", path)
    assert_one_line_error(validated, line)
    if field.startswith("coating"):
        line = f"{field}: must be > 0, is {value:g} m at x = "
    assert_one_line_error(run("solve", path, "-o", tmp_path / "r.json"), line)


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
                          "coated-punch solve: the following arguments")
    assert_one_line_error(run("frobnicate"), "coated-punch: argument")
    assert_one_line_error(run("solve", SCENES / "uniform_flat.json", "-o", tmp_path / "r.txt"),
                          "--output: unsupported extension '.txt'")
    # a bare command said only what was missing; now where to read more
    bare = run()
    assert_one_line_error(bare, "coated-punch: the following arguments are required")
    assert bare.stderr.rstrip().endswith("(see 'coated-punch --help')"), bare.stderr
    # a summary has no format: --format csv without --output printed it all the same
    no_output = run("solve", "preset:worn_coating", "--format", "csv")
    assert_one_line_error(no_output, "--format: is the format of --output, which is not "
                                     "given (-o - writes CSV to standard output)")


@pytest.mark.parametrize(("path", "value", "message"), BAD_VALUES[::3],
                         ids=[f"{p}={v!r}"[:50] for p, v, _ in BAD_VALUES[::3]])
def test_bad_values_give_one_line_from_the_command_line(tmp_path: Path, capsys, path: str,
                                                        value: Any, message: str) -> None:
    file = tmp_path / "scene.json"
    file.write_text(json.dumps(edited(path, value)))
    assert cli_main(["solve", str(file)]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.count("\n") == 1 and captured.err.startswith("error: "), captured.err
    assert message.split(":")[0] in captured.err


def assert_refused(proc: subprocess.CompletedProcess, *parts: str) -> None:
    assert proc.returncode == 2, (proc.returncode, proc.stderr)
    assert "Traceback" not in proc.stderr and proc.stdout == ""
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), proc.stderr
    for part in parts:
        assert part in lines[0], lines[0]


def test_cli_refuses_a_file_of_100_mb_before_reading_it(tmp_path: Path) -> None:
    big = tmp_path / "huge.json"
    with big.open("wb") as fh:  # sparse: no disk space is used
        fh.truncate(100 * 2**20)
    proc = run_cli("solve", big, "--output", tmp_path / "out.json")
    assert_refused(proc, "huge.json: file is 104857600 bytes, over the limit of 1000000")
    assert not (tmp_path / "out.json").exists()


@pytest.mark.parametrize(("content", "parts"), [
    (b"this is not JSON {", ("not valid JSON",)),
    (b"\xff\xfe\x00\x01", ("not a text file in UTF-8",)),
    (b"[" * 200_000 + b"]" * 200_000, ("not valid JSON (nested too deeply)",)),
    (json.dumps(edited("punch.colour", "red")).encode(), ("punch: unknown field 'colour'",)),
    (json.dumps(edited("loading", {"force": 1.0})).encode(),
     ("loading: exactly two of settlement, tilt, force, moment",)),
    (json.dumps(edited("base.thickness", DELETE)).encode(),
     ("base.thickness: required field is missing",)),
    (json.dumps(edited("schema_version", 7)).encode(),
     ("schema_version: unsupported version 7 (this program reads 1)",)),
    # a 5000-digit integer is valid JSON; Python's int() refuses it with advice about
    # sys.set_int_max_str_digits, which is no message for a user
    (json.dumps(base_scene()).replace('"half_width": 1.0', '"half_width": ' + "9" * 5000)
     .encode(), ("punch.half_width: must be a finite number",)),
], ids=["not-json", "binary", "nested", "unknown-field", "one-load", "missing-field",
        "wrong-version", "5000-digits"])
def test_cli_answers_broken_files_with_one_line(tmp_path: Path, content: bytes,
                                                parts: tuple[str, ...]) -> None:
    file = tmp_path / "scene.json"
    file.write_bytes(content)
    assert_refused(run_cli("validate", file), *parts)


def test_cli_never_prints_a_traceback(monkeypatch, capsys) -> None:
    """An unexpected exception (a bug) still gives one line and a non-zero exit code."""
    def broken(path: str) -> None:
        raise TypeError("something unforeseen")

    monkeypatch.setattr("core.cli.load_scene", broken)
    assert cli_main(["solve", "whatever.json"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("error: internal error (TypeError: "), err


@pytest.mark.parametrize("loading, field", [
    ({"force": -5e5, "moment": 0.0}, "loading.force"),  # the punch is pulled away
    ({"force": 5e5, "moment": 6e5}, "loading.moment"),  # the resultant outside the punch
])
@pytest.mark.parametrize("command", ["validate", "solve"])
def test_a_load_no_contact_carries_is_the_users_input(tmp_path, command, loading, field):
    # SCENES.md: refused naming the field, exit code 2 (it was accepted by validate, and
    # solve exited 1 as if the solver had failed)
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(edited("loading", loading, scene_dict())))
    assert_one_line_error(run(command, path), field)


def test_the_summary_says_the_pressure_is_unbounded_at_a_bare_corner():
    proc = run("solve", "preset:bare_layer")
    assert proc.returncode == 0, proc.stderr
    assert ("largest contact pressure q: unbounded at the corner x = -1 m (a rigid corner: "
            "q ~ 1/sqrt(distance)); 2.67618e+06 Pa at 1 mm from it") in proc.stdout
    # and what the q table's held rows leave out (said in the table only, before)
    assert ("\ncorner: q grows without bound toward the rigid corner at x = -1 m and x = 1 m; "
            "within 0.001 m of it the rows hold its value at that distance, and so leave out "
            "up to 1.1 % of the force P") in proc.stdout



@pytest.mark.parametrize("contact", ["auto", "unilateral"])
@pytest.mark.parametrize("command", ["validate", "solve"])
def test_a_pulled_punch_of_several_is_the_users_input(tmp_path, command, contact):
    # validate said ok and solve exited 1 (an internal failure): lift-off needs every
    # punch pressed (the full-contact model, linear, answers a bonded punch)
    data = json.loads((SCENES / "new_footing_beside_old.json").read_text())
    data["punches"][1]["loading"] = {"force": -1e5, "moment": 0.0}
    data.setdefault("solver", {})["contact"] = contact
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(data))
    assert_one_line_error(run(command, path), "punches[1].loading.force: the punch is pulled")


def test_a_check_where_the_punch_touches_nothing_is_the_users_input(tmp_path):
    # exit 1 (as if the FE model had failed) for a time the user can change
    data = scene_dict()
    data["loading"] = {"settlement": -1e-3, "tilt": 0.0}  # held clear of the surface
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(data))
    assert_one_line_error(run("check", path),
                          "--time (default 0): the punch does not touch the coating")
    # the report is still written, said without a check
    out = tmp_path / "report.html"
    proc = run("report", path, "--fe-check", "-o", out)
    assert proc.returncode == 0, proc.stderr
    assert "warning: fe_check: not run: the punch does not touch" in proc.stderr
    assert out.stat().st_size > 0


def test_several_punches_without_coating_and_their_check_are_the_users_input(tmp_path):
    # validate said ok and solve exited 1 with "m: must be > 0" (an internal name);
    # check dumped an 11 kB line of the scene object and exited 1
    data = json.loads((SCENES / "new_footing_beside_old.json").read_text())
    data["coating"] = []
    path = tmp_path / "bare.json"
    path.write_text(json.dumps(data))
    for command in ("validate", "solve"):
        assert_one_line_error(run(command, path), "coating: several punches need at least "
                                                  "one coating layer")
    proc = run("check", SCENES / "new_footing_beside_old.json")
    assert_one_line_error(proc, str(SCENES / "new_footing_beside_old.json")
                          + ": the finite-element check is of one punch")
    assert len(proc.stderr) < 300


@pytest.mark.parametrize("command", ["validate", "solve"])
def test_one_punch_in_the_punches_form_is_refused_as_one_punch(tmp_path, command):
    # full contact: solve exited 1 naming loading.force, validate said ok
    data = json.loads((SCENES / "new_footing_beside_old.json").read_text())
    data["punches"] = data["punches"][:1]
    data["punches"][0]["loading"] = {"force": -1e5, "moment": 0.0}
    data["solver"]["contact"] = "full"
    path = tmp_path / "one.json"
    path.write_text(json.dumps(data))
    assert_one_line_error(run(command, path), "punches[0].loading.force: the punch is pulled")


def test_validate_says_why_a_scene_gives_both_forms(tmp_path):
    # validate said "loading: required field is missing"; solve gave the cause
    data = json.loads((SCENES / "new_footing_beside_old.json").read_text())
    data["punch"] = {"half_width": 1.0}
    path = tmp_path / "both.json"
    path.write_text(json.dumps(data))
    for command in ("validate", "solve"):
        assert_one_line_error(run(command, path), "punch: give either punch and loading")


def test_the_command_line_section_of_the_format_lists_every_command() -> None:
    """SCENES.md's synopsis left out ``report`` and ``calibrate``, and its exit codes
    spoke of ``solve --strict`` alone; the documentation's table said "solve, validate,
    check and sweep"."""
    import argparse
    import re

    from core.cli import build_parser

    parser = build_parser()
    commands = next(a for a in parser._actions
                    if isinstance(a, argparse._SubParsersAction)).choices
    root = Path(__file__).resolve().parents[2]
    text = (root / "core" / "SCENES.md").read_text(encoding="utf-8")
    section = text[text.index("## Command line"):]
    synopsis = section[:section.index("Exit codes")]
    listed = set(re.findall(r"coated-punch ([a-z]\w*)", synopsis))
    assert listed == set(commands), sorted(set(commands) ^ listed)
    for page in ("docs/reference/cli.md", "docs/getting_started.md"):
        row = next(line for line in (root / page).read_text(encoding="utf-8").splitlines()
                   if line.startswith("| `coated-punch`"))
        assert all(name in row for name in commands if name != "schema"), (page, row)


def test_the_summary_says_whose_coating_model_error_it_is() -> None:
    """The estimate is the worse of two parts: the force's (or the settlement's) and the
    moment's (or the tilt's); the summary names it, without Greek letters (a console's
    character set may not hold them), for one punch and for each of several."""
    done = run("solve", "preset:worn_coating")
    assert done.returncode == 0, done.stderr
    line = next(s for s in done.stdout.splitlines() if s.startswith("coating model error"))
    # the force is given: its settlement is the unknown
    assert " % of the settlement (solver.model_tol 2 %)" in line, line
    done = run("solve", "preset:new_footing_beside_old")
    lines = [s for s in done.stdout.splitlines() if "coating model error" in s]
    assert len(lines) == 2 and all(" % of the tilt (solver.model_tol 2 %)" in s
                                   for s in lines), lines
    assert not set("αδ") & set(done.stdout)
    # and the CSV's head (it gave the solver's 4e-7 beside a bare model_error flag)
    done = run("solve", "preset:eccentric_creep", "-o", "-", "--format", "csv")
    assert done.returncode == 0, done.stderr
    head = [s for s in done.stdout.splitlines() if s.startswith("# coating model error")]
    assert len(head) == 1 and head[0].endswith(" % of the tilt (solver.model_tol 2 %)"), head


def test_outputs_and_times_are_refused_before_any_solve(tmp_path: Path, monkeypatch):
    """A directory as the output read "unsupported extension ''"; q(x, t) went as CSV
    into a .json file and a PDF into a .html one; a report's --time out of range was
    said only after the solve. Each is refused by name, and no solve runs."""
    import core.cli as cli

    def no_solve(*args, **kwargs):
        raise AssertionError("solved before refusing the arguments")

    monkeypatch.setattr(cli, "solve", no_solve)
    assert_one_line_error(run("solve", "preset:worn_coating", "-o", tmp_path),
                          f"--output: {tmp_path} is a directory; give a file's path")
    assert_one_line_error(run("solve", "preset:worn_coating", "--pressure-csv",
                              tmp_path / "q.json"),
                          f"--pressure-csv: {tmp_path / 'q.json'}: q(x, t) is written as CSV")
    assert_one_line_error(run("report", "preset:worn_coating", "-o", tmp_path / "r.html",
                              "--format", "pdf"),
                          f"--format: pdf does not match --output {tmp_path / 'r.html'}")
    assert_one_line_error(run("report", "preset:worn_coating", "-o", tmp_path / "r.html",
                              "--time", "-5"),
                          "--time: -5 days is outside the output times")
    assert not list(tmp_path.iterdir())


def test_one_day_is_a_day_and_no_difference_reads_minus_zero(tmp_path: Path, monkeypatch):
    """The summary read "at t = 1 days"; the check's table "-0.00%" for a difference
    below its digits."""
    import core.scene

    scene = scene_dict()
    scene["times"] = [1.0, 10.0]
    scene["limits"] = {"allowable_pressure": 3e5}
    scene["loading"] = {"force": {"kind": "step", "values": [5e5, 2e5], "breaks": [5.0]},
                        "moment": 0.0}
    path = tmp_path / "s.json"
    path.write_text(json.dumps(scene))
    summary = run("solve", path)
    assert "t = 1 day," in summary.stdout and "1 days" not in summary.stdout

    fast = {"settlement": 2.43e-5, "tilt": -1e-21, "force": 5e5, "moment": 0.0}
    report = {"time_day": 0.0, "fast": fast, "fe": dict(fast, tilt=-2e-15),
              "errors": {"settlement": 2.4e-3, "tilt": -1e-7, "force": 0.0, "moment": -1e-9,
                         "pressure": 0.01},
              "pressure_fast_Pa": 3.2e5, "pressure_fe_Pa": 3.1e5, "pressure_error_at_m": 0.9,
              "model_error": 2.4e-3, "model_tol": 0.02, "estimate": 3e-3,
              "coating_model": "thin layer", "given": ["force", "moment"],
              "contact_lost": False, "lift_off": None, "scene_key": "", "half_width_m": 1.0,
              "fe_seconds": 1.0, "fe_dofs": 100}
    monkeypatch.setattr(core.scene, "check_scene", lambda *args, **kwargs: report)
    checked = run("check", path)
    assert "-0.00%" not in checked.stdout and "    0.00%" in checked.stdout, checked.stdout


def test_a_preset_is_listed_and_written_out_to_start_from(tmp_path: Path):
    """A user of the installed package had no scene file to follow the README's
    commands with (``footing.json``): ``preset`` lists the shipped scenes and writes one
    out, a file ``validate`` and ``solve`` read back as the preset."""
    listed = run("preset")
    assert listed.returncode == 0
    assert [line.split()[0] for line in listed.stdout.splitlines()] == list(
        core.presets.preset_names())
    path = tmp_path / "footing.json"
    written = run("preset", "eccentric_creep", "-o", path)
    assert written.returncode == 0, written.stderr
    assert core.load_scene(path) == core.load_scene("preset:eccentric_creep")
    assert run("validate", path).returncode == 0
    shown = run("preset", "preset:uniform_flat")  # as SCENE takes it; to standard output
    assert json.loads(shown.stdout) == core.load_scene("preset:uniform_flat").to_dict()
    assert_one_line_error(run("preset", "nope"), "preset:nope: no shipped scene of that name")
    assert_one_line_error(run("preset", "uniform_flat", "-o", tmp_path / "s.txt"),
                          f"--output: {tmp_path / 's.txt'}: a scene file is .json")


def test_a_reader_that_leaves_early_is_no_error() -> None:
    """``coated-punch solve ... | head -1`` read "error: internal error
    (BrokenPipeError...)", exit 1; a summary left in the buffer read "Exception ignored
    ... BrokenPipeError" at exit, exit 120. Now nothing is said and the code is the
    shell's of a closed pipe, 141: the reader gone before a line (a closed pipe) or after
    one, the output buffered as in a shell or written at once."""
    import sys

    from core.cli import EXIT_BROKEN_PIPE

    env = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}
    env["OPENBLAS_NUM_THREADS"] = "1"
    for args in (["preset"], ["solve", "preset:worn_coating"], ["--version"],
                 ["solve", "preset:worn_coating", "--pressure-csv", "-"]):
        read, write = os.pipe()
        os.close(read)  # the reader has left before the first line
        child = subprocess.run([sys.executable, "-m", "core", *args], cwd=ROOT, env=env,
                               stdout=write, stderr=subprocess.PIPE, timeout=120)
        os.close(write)
        assert (child.returncode, child.stderr.decode()) == (EXIT_BROKEN_PIPE, ""), args
    child = subprocess.Popen([sys.executable, "-m", "core", "solve", "preset:worn_coating",
                              "--pressure-csv", "-"], cwd=ROOT, env=env,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    assert child.stdout.readline()  # one line, then the reader leaves
    child.stdout.close()
    err = child.stderr.read().decode()
    assert child.wait(timeout=120) in (0, EXIT_BROKEN_PIPE) and err == "", err


def test_a_written_preset_is_not_overwritten_and_a_list_is_not_written(tmp_path: Path):
    """The file ``preset -o`` writes is the one to edit: a second run wiped the edits. A
    list asked to a file wrote nothing and said ok."""
    path = tmp_path / "mine.json"
    path.write_text('{"edited": true}')
    assert_one_line_error(run("preset", "uniform_flat", "-o", path),
                          f"--output: {path} exists (a scene being edited?)")
    assert path.read_text() == '{"edited": true}'
    assert run("preset", "uniform_flat", "-o", path, "--force").returncode == 0
    assert core.load_scene(path) == core.load_scene("preset:uniform_flat")
    assert_one_line_error(run("preset", "-o", tmp_path / "list.json"),
                          "--output: give the preset to write")
    assert not (tmp_path / "list.json").exists()


def test_a_run_stopped_by_sigterm_says_so_and_exits_as_the_shell_counts_it(tmp_path: Path):
    """SIGTERM left a study's run with the multiprocessing "leaked semaphore objects"
    warnings and exit -15; it now stops as Ctrl-C does: one line, exit 143 (a new user's
    audit of the wheel). A solve that cannot finish within the test's patience stands in
    for the study (its cluster is the same code path out)."""
    import signal
    import sys
    import time

    d = scene_file("eccentric_footing_liftoff")
    d["punch"]["shape"] = {"kind": "sine", "mean": 0.0, "amplitude": 1e-5,
                           "wavelength": 0.01, "phase": 0.0}   # runs for tens of seconds
    path = tmp_path / "slow.json"
    path.write_text(json.dumps(d))
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", PYTHONPATH=str(ROOT))
    child = subprocess.Popen([sys.executable, "-m", "core", "solve", str(path)], env=env,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)

    def catches_sigterm() -> bool:
        # the run's own handler is set (before it, SIGTERM ends the child at once)
        with open(f"/proc/{child.pid}/status") as fh:
            caught = next(line for line in fh if line.startswith("SigCgt:"))
        return bool(int(caught.split()[1], 16) >> (signal.SIGTERM - 1) & 1)

    deadline = time.monotonic() + 120
    while not catches_sigterm():
        assert child.poll() is None and time.monotonic() < deadline
        time.sleep(0.05)
    time.sleep(0.5)
    child.send_signal(signal.SIGTERM)
    out, err = child.communicate(timeout=60)
    assert child.returncode == 143, (child.returncode, err)
    assert err == "error: terminated\n", err
