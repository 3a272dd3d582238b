"""Hostile and broken input at every entry point: the Python API, scene files, the command
line, the explorer's files, links and widgets.

Each refusal must name the field and the reason in one line (the command line: exit code
2, no traceback); markup typed by a user must reach the page as text; a scene that would
take the shared server's memory or minutes of solving is refused before any work; saving
a scene writes the whole file or nothing.
"""

from __future__ import annotations

import json
import os
import shutil
import stat
import subprocess
import sys
import tempfile
import textwrap
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import core.scene.schema as scene_schema
from benchmarks.serving import CHROMIUM, CHROMIUM_ARGS
from core.cli import main as cli_main
from core.profiles import profile_from_csv
from core.scene import MAX_SCENE_BYTES, load_scene, save_scene, scene_from_dict, solve
from core.scene.files import parse_scene_json
from core.scene.schema import MAX_BREAKPOINTS, migrate
from explorer.model.links import MAX_JSON, PREFIX, decode_scene, encode_scene
from tests.browser_pages import require_browser, served_explorer
from tests.cli_runs import run_cli

ROOT = Path(__file__).resolve().parent.parent
SCENES = ROOT / "assets" / "scenes"

XSS = ['<script>window.__xss = 1</script>', '<img src=x onerror="window.__xss=1">',
       "<img src=x onerror=alert(1)>"]


def base_scene() -> dict[str, Any]:
    """A small valid scene (few output times: the solves below stay quick)."""
    scene = json.loads((SCENES / "uniform_flat.json").read_text())
    scene["times"] = {"end": 100.0, "count": 3, "spacing": "linear"}
    scene["solver"] = {"tol": 1e-3}
    return scene


def edited(path: str, value: Any, scene: dict[str, Any] | None = None) -> dict[str, Any]:
    """``scene`` (default :func:`base_scene`) with the field at dotted ``path`` set to
    ``value``, or removed when ``value`` is :data:`DELETE`."""
    scene = base_scene() if scene is None else scene
    *parents, last = path.replace("[", ".").replace("]", "").split(".")
    target: Any = scene
    for key in parents:
        target = target[int(key)] if key.isdigit() else target[key]
    if value is DELETE:
        del target[last]
    elif last.isdigit():
        target[int(last)] = value
    else:
        target[last] = value
    return scene


DELETE = object()

#: The issue's list of bad values, with the start of the message each must give.
BAD_VALUES: list[tuple[str, Any, str]] = [
    ("coating[0].thickness", -0.01, "coating[0].thickness: must be > 0"),
    ("coating[0].thickness", 0.0, "coating[0].thickness: must be > 0"),
    ("coating[0].modulus", -3e6, "coating[0].modulus: must be > 0"),
    ("coating[0].modulus", 0, "coating[0].modulus: must be > 0"),
    ("base.thickness", 0.0, "base.thickness: must be > 0"),
    ("base.creep.modulus", -3e10, "base.creep.modulus: must be > 0"),
    ("coating[0].poisson", 0.5, "coating[0].poisson: must be < 0.5"),
    ("coating[0].poisson", -1.0, "coating[0].poisson: must be > -1"),
    ("base.poisson", 0.5, "base.poisson: must be in (-1, 0.5)"),
    ("base.poisson", -1.2, "base.poisson: must be in (-1, 0.5)"),
    ("punch.half_width", 0.0, "punch.half_width: must be > 0"),
    ("punch.half_width", float("nan"), "punch.half_width: must be a finite number"),
    ("base.age_at_loading", float("inf"), "base.age_at_loading: must be a finite number"),
    ("loading.force", float("-inf"), "loading.force: must be a finite number"),
    ("punch.half_width", 10**400, "punch.half_width: must be a finite number"),
    ("base.creep.modulus", 10**400,
     "base.creep.modulus: must be finite, got an integer too large for a double"),
    ("coating[0].thickness", {"kind": "table", "points": [[0.5, 0.01], [-0.5, 0.02]]},
     "coating[0].thickness.points: must be strictly increasing in x (row 1)"),
    ("coating[0].thickness", {"kind": "table", "points": [[0.0, 0.01]]},
     "coating[0].thickness.points: must have at least 2 rows"),
    ("punch.hafl_width", 1.0, "punch: unknown field 'hafl_width' (did you mean 'half_width'?)"),
    ("base.poisson", DELETE, "base.poisson: required field is missing"),
    ("schema_version", 2, "schema_version: unsupported version 2 (this program reads 1)"),
    ("schema_version", 0, "schema_version: version 0 does not exist"),
    ("schema_version", DELETE, "schema_version: required field is missing"),
    ("base.creep.compliance", -3e-11, "base.creep.compliance: must be >= 0, got -3e-11: a "
                                      "negative value makes the compliance decrease in time"),
    ("base.creep", {"model": "kernel", "modulus": 3e10, "expr": "0.01 * exp(-(t - tau))"},
     "base.creep.expr: K(t, tau) must be <= 0 (the base creeps)"),
    ("base.creep", {"model": "kernel", "modulus": 3e10, "expr": "-1 / (t - tau)"},
     "base.creep.expr: creep kernel: not finite"),
    ("times", [-1.0, 10.0, 20.0], "times[0]: must be >= 0 days after loading"),
    ("times", [0.0, 20.0, 10.0], "times[2]: times must increase"),
]


@pytest.mark.parametrize(("path", "value", "message"), BAD_VALUES,
                         ids=[f"{p}={v!r}"[:50] for p, v, _ in BAD_VALUES])
def test_bad_values_are_refused_by_the_api_and_files(tmp_path: Path, path: str, value: Any,
                                                     message: str) -> None:
    scene = edited(path, value)
    with pytest.raises(ValueError) as api:
        solve(scene)
    assert str(api.value).startswith(message), str(api.value)
    # the same scene as a file (JSON writes NaN and Infinity, which Python reads back)
    file = tmp_path / "scene.json"
    file.write_text(json.dumps(scene))
    with pytest.raises(ValueError) as loaded:
        load_scene(file)
    # a 400-digit integer reaches the file reader as inf: the same field (named more
    # precisely for a creep parameter), another wording
    assert str(loaded.value).startswith(message.split(":")[0]), str(loaded.value)


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


# ------------------------------------------------- the command line, as a user runs it


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
    assert cli_main(["validate", "whatever.json"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("error: internal error (TypeError: "), err


# ---------------------------------------------------------- work bounded before solving


def test_many_jumps_are_refused_before_the_solver_sees_them() -> None:
    """Each jump or kink adds a graded cluster of panels to a dense operator: a 50-row
    linear shape table took 15 s and 2.4 GB and ended in an obscure error; a 10000-row
    table asked for a 15 TiB matrix. A served explorer must refuse them at once."""
    x = np.linspace(-1.0, 1.0, 50)
    rows = [[float(v), float(1e-5 * (1 + np.sin(20 * v)))] for v in x]
    scene = edited("punch.shape", {"kind": "table", "points": rows})
    with pytest.raises(ValueError, match=r"^punch\.shape: has 48 points where its value or "
                                         r"slope jumps .* more than the 16 "):
        scene_from_dict(scene)
    # the same rows interpolated smoothly have two breakpoints (the end rows): solved
    smooth = edited("punch.shape", {"kind": "table", "points": rows,
                                    "interpolation": "pchip"})
    smooth["times"]["count"] = 1  # accepted and solved is the point: 3 s of CPU, not 12
    assert np.all(np.isfinite(solve(smooth).settlement))
    steps = {"kind": "step", "values": [1e8 * (2 + (-1) ** k) for k in range(10_001)],
             "breaks": list(np.linspace(-0.999, 0.999, 10_000))}
    with pytest.raises(ValueError, match=r"^coating\[0\]\.modulus: has 10000 points"):
        scene_from_dict(edited("coating[0].modulus", steps))
    switches = {"expr": "0.01 * (1.5 + 0.5 * sign(sin(300 * x)))"}
    with pytest.raises(ValueError, match=r"^coating\[0\]\.thickness: has \d+ points"):
        scene_from_dict(edited("coating[0].thickness", switches))
    # jumps spread over several profiles count together
    a_few = {"kind": "step", "values": [0.01] * 10, "breaks": list(np.linspace(-0.9, 0.9, 9))}
    scene = edited("coating[0].thickness", a_few)
    scene = edited("coating[0].modulus", {"kind": "step", "values": [5e8] * 10,
                                          "breaks": list(np.linspace(-0.85, 0.95, 9))}, scene)
    assert MAX_BREAKPOINTS == 16
    with pytest.raises(ValueError, match=r"18 in the whole scene"):
        scene_from_dict(scene)


@pytest.mark.parametrize(("path", "value", "message"), [
    # a / H = 1000 measured 27 s and 5.5 GB; the solver itself accepts up to 1e4
    ("base.thickness", 1e-3, "base.thickness: the ratio punch.half_width / base.thickness "
                             "must be in [0.0001, 100], got 1000"),
    # a creep coefficient of 9e7 ran the time stepping to its step limit (13 s)
    ("base.creep.compliance", 3e-3, "base.creep: the creep coefficient"),
    ("base.creep", {"model": "kernel", "modulus": 3e10, "expr": "-2e4 * exp(-0.05 * (t - tau))"},
     "base.creep.expr: the creep coefficient"),
    # a coating modulus of 1e300 Pa ran 29 s and returned NaN
    ("coating[0].modulus", 1e300, "coating: the coating compliance relative to the base, m* ="),
    ("coating[0].modulus", 1e-300, "coating: the coating compliance relative to the base"),
    # a punch shape of 1e300 m gave an infinite pressure
    ("punch.shape", {"kind": "polynomial", "coefficients": [0, 1e300]},
     "punch.shape: the gap between the punch base and the coating surface is"),
    # a tiny age at loading makes the aging term A / age^2 infinite
    ("base.age_at_loading", 1e-300, "base.creep: the creep kernel K(t, tau) is"),
    # 1e200 m squared overflowed Python's float power (OverflowError, a traceback)
    ("punch.half_width", 1e200, "base.thickness: the ratio"),
])
def test_extreme_sizes_are_refused_with_the_field_to_change(path: str, value: Any,
                                                            message: str) -> None:
    with pytest.raises(ValueError) as info:
        solve(edited(path, value))
    assert str(info.value).startswith(message), str(info.value)


def test_a_solution_never_holds_nan(monkeypatch) -> None:
    """The last guard: were the solver to answer NaN, solve() refuses the answer."""
    from core import solver

    real = solver.solve_dimensionless

    def poisoned(*args: Any, **kwargs: Any) -> Any:
        solution = real(*args, **kwargs)
        solution.settlement[-1] = np.nan
        return solution

    monkeypatch.setattr(solver, "solve_dimensionless", poisoned)
    with pytest.raises(ValueError, match=r"^scene: the computed settlement is not finite at "
                                         r"t = 100 days"):
        solve(edited("loading.force", 4.1e5))


# ------------------------------------------------------------------------------ formulas

FORMULA_ATTACKS = [
    "x.__class__", "x.real", "().__class__.__bases__[0].__subclasses__()", "__import__('os')",
    "__builtins__", "import os", "lambda: 1", "(lambda x: x)(1)", "[x for x in (1, 2)]",
    "{x for x in (1,)}", "{x: 1 for x in (1,)}", "sum(x for x in (1,))", "9 ** 9 ** 9 ** 9",
    "x ** 1e10", "2 ** 1000", "(" * 500 + "x" + ")" * 500, "-" * 400 + "x", "sin(" * 30 + "x"
    + ")" * 30, "open('/etc/passwd').read()", "eval('1')", "getattr(x, 'real')",
    "<img src=x onerror=alert(1)>", "x; import os", "x\u0430", "0.01 + x" * 100,
]


@pytest.mark.parametrize("payload", FORMULA_ATTACKS, ids=range(len(FORMULA_ATTACKS)))
def test_formula_attacks_are_refused_at_every_formula_field(tmp_path: Path,
                                                            payload: str) -> None:
    sentinel = tmp_path / "touched"
    payload = payload.replace("/etc/passwd", str(sentinel))
    for path, variables in (("punch.shape", "x"), ("coating[0].modulus", "x"),
                            ("loading.force", "t")):
        text = payload.replace("x", variables) if variables != "x" else payload
        with pytest.raises(ValueError) as info:
            scene_from_dict(edited(path, {"expr": text}))
        assert str(info.value).startswith(f"{path}.expr: "), str(info.value)
    with pytest.raises(ValueError) as info:
        scene_from_dict(edited("base.creep", {"model": "kernel", "modulus": 3e10,
                                              "expr": payload.replace("x", "t")}))
    assert str(info.value).startswith("base.creep.expr: "), str(info.value)
    assert not sentinel.exists()


# ------------------------------------------------------------------------ saving, loading


def test_save_scene_writes_a_complete_file(tmp_path: Path) -> None:
    path = tmp_path / "scene.json"
    save_scene(base_scene(), path)
    assert load_scene(path) == scene_from_dict(base_scene())
    assert json.loads(path.read_text())["schema_version"] == 1
    assert [p.name for p in tmp_path.iterdir()] == ["scene.json"]


def _old_file(tmp_path: Path) -> tuple[Path, bytes]:
    path = tmp_path / "scene.json"
    save_scene(edited("name", "the old scene"), path)
    os.chmod(path, 0o640)
    return path, path.read_bytes()


@pytest.mark.parametrize("failure", ["write", "fsync", "replace"])
def test_a_failed_save_leaves_the_old_file_intact(tmp_path: Path, monkeypatch,
                                                  failure: str) -> None:
    path, old = _old_file(tmp_path)
    if failure == "write":
        real_fdopen = os.fdopen

        class HalfWriter:
            """Writes half of the text, then the disk is full."""

            def __init__(self, fh: Any) -> None:
                self.fh = fh

            def __enter__(self) -> HalfWriter:
                return self

            def __exit__(self, *exc: Any) -> None:
                self.fh.close()

            def write(self, text: str) -> int:
                self.fh.write(text[: len(text) // 2])
                self.fh.flush()
                raise OSError(28, "No space left on device")

        monkeypatch.setattr(os, "fdopen", lambda *a, **k: HalfWriter(real_fdopen(*a, **k)))
    elif failure == "fsync":
        def fsync(fd: int) -> None:
            raise OSError(5, "Input/output error")

        monkeypatch.setattr(os, "fsync", fsync)
    else:
        def replace(src: Any, dst: Any) -> None:
            raise OSError(13, "Permission denied")

        monkeypatch.setattr(os, "replace", replace)
    with pytest.raises(OSError):
        save_scene(edited("name", "the new scene"), path)
    monkeypatch.undo()
    assert path.read_bytes() == old
    assert stat.S_IMODE(path.stat().st_mode) == 0o640
    # the temporary file is gone too
    assert [p.name for p in tmp_path.iterdir()] == ["scene.json"]


def test_a_process_killed_during_a_save_leaves_the_old_file_intact(tmp_path: Path) -> None:
    """The process dies after writing the new text and before the rename (power cut)."""
    path, old = _old_file(tmp_path)
    script = textwrap.dedent(f"""
        import json, os, sys
        sys.path.insert(0, {str(ROOT)!r})
        from core.scene import save_scene
        scene = json.loads({json.dumps(json.dumps(edited("name", "the new scene")))})
        os.replace = lambda src, dst: os._exit(9)
        save_scene(scene, {str(path)!r})
    """)
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, timeout=120,
                          env=dict(os.environ, OPENBLAS_NUM_THREADS="1"))
    assert proc.returncode == 9, proc.stderr
    assert path.read_bytes() == old
    assert load_scene(path).name == "the old scene"
    # the complete new text is left in a hidden temporary file beside it
    leftovers = [p for p in tmp_path.iterdir() if p.name != "scene.json"]
    assert len(leftovers) == 1 and leftovers[0].name.startswith(".scene.json.")
    assert json.loads(leftovers[0].read_text())["name"] == "the new scene"


def test_an_invalid_scene_is_never_saved(tmp_path: Path) -> None:
    path, old = _old_file(tmp_path)
    with pytest.raises(ValueError, match=r"^coating\[0\]\.thickness: must be > 0"):
        save_scene(edited("coating[0].thickness", -1.0), path)
    assert path.read_bytes() == old


def test_older_and_newer_schema_versions_are_migrated_or_explained(monkeypatch) -> None:
    with pytest.raises(ValueError, match=r"^schema_version: version 0 does not exist \(the "
                                         r"first version of the schema is 1"):
        scene_from_dict(edited("schema_version", 0))
    with pytest.raises(ValueError, match=r"^schema_version: unsupported version 3 \(this "
                                         r"program reads 1\)"):
        parse_scene_json(json.dumps(edited("schema_version", 3)))
    with pytest.raises(ValueError, match=r"^schema_version: must be an integer, got 1\.5"):
        scene_from_dict(edited("schema_version", 1.5))
    # the migration chain: a program reading version 2 brings a version 1 file forward
    # step by step, without changing the caller's dict
    monkeypatch.setattr(scene_schema, "SCHEMA_VERSION", 2)

    def one_to_two(d: dict[str, Any]) -> dict[str, Any]:
        out = dict(d)
        out["title"] = out.pop("name")
        return out

    monkeypatch.setitem(scene_schema._MIGRATIONS, 1, one_to_two)
    old = base_scene()
    new = migrate(old)
    assert new["schema_version"] == 2 and new["title"] == old["name"] and "name" not in new
    assert old["schema_version"] == 1 and "name" in old


# ----------------------------------------------------------------------- uploaded tables


def test_uploaded_tables_have_limits_and_clear_errors() -> None:
    domain = (-1.0, 1.0)

    def refused(data: bytes | str, match: str, **kwargs: Any) -> None:
        with pytest.raises(ValueError, match=match):
            profile_from_csv(data, field="punch.shape", domain=domain, **kwargs)

    refused(b"x,f\n" + b"0,0\n" * 300_000, r"^punch\.shape: file is too large \(1200004 bytes")
    rows = "".join(f"{k / 20000},{k}\n" for k in range(10_001))
    refused(rows, r"^punch\.shape: file has too many rows \(10001, at most 10000\)")
    refused(b"x,f\n0.1,1\n", r"^punch\.shape: file needs at least 2 data rows, has 1")
    refused(b"x,f\n0.1,1\n0.2,=cmd|' /C calc'!A0\n", r"^punch\.shape: line 3, column 2: "
                                                   r"\"=cmd\|' /C calc'!A0\" is not a number")
    refused(b"x,f\n0.2,1\n0.1,2\n", r"^punch\.shape: x values must be strictly increasing "
                                    r"\(line 3: 0\.1 after 0\.2\)")
    refused(b"x,f\n0.1,1\n0.2,nan\n", r"line 3, column 2: 'nan' is not a number")
    refused(b"x,f\n0.1,1\n0.2,1e999\n", r"line 3, column 2: '1e999' is out of range")
    refused(b"x,f\n0.1,1,3\n0.2,1,4\n", r"line 2: expected 2 columns")
    refused(b"\x00\x01binary", r"file is not text")
    refused(b"", r"file is empty")
    # a header with markup is skipped, not echoed
    table = profile_from_csv(b"<img src=x onerror=alert(1)>,f\n-0.5,0\n0.5,1e-5\n",
                             field="punch.shape", domain=domain)
    assert table.spec["points"] == [[-0.5, 0.0], [0.5, 1e-5]]


# ------------------------------------------------------------------------------ explorer


def _rendered_markup(app: Any) -> list[str]:
    """The markup of every HTML and Markdown pane on the page (what the browser renders)."""
    import panel as pn

    texts = []
    for pane in app._layout.select(pn.pane.Markdown) + app._layout.select(pn.pane.HTML):
        texts.append(str(pane.object))
    texts += [str(app.results.notice_alert.object), str(app.results.alert.object)]
    return texts


def assert_inert(app: Any) -> None:
    for text in _rendered_markup(app):
        lowered = text.lower()
        assert "<script" not in lowered and "<img" not in lowered, text
        assert "onerror=" not in lowered or "&lt;" in lowered, text


def test_markup_in_a_link_is_shown_as_text(explorer_app) -> None:
    scene = base_scene()
    scene["name"] = XSS[0]
    scene["description"] = XSS[1]
    scene["punch"][XSS[2]] = 1.0
    app = explorer_app(query={"scene": encode_scene(scene)})
    assert "unknown field" in app.screen.notice and "default scene" in app.screen.notice
    assert "&lt;img src=x onerror=alert(1)&gt;" in app.results.notice_alert.object
    assert_inert(app)
    app = explorer_app(query={"preset": XSS[1]})
    assert "Unknown preset" in app.screen.notice
    assert_inert(app)


def test_markup_in_scene_files_and_fields_is_shown_as_text(explorer_app) -> None:
    app = explorer_app()
    good = base_scene()
    good["name"] = XSS[0]
    good["description"] = XSS[1]
    app.files_tab.load_file.filename = "scene.json"
    app.files_tab.load_file.value = json.dumps(good).encode()
    assert app.screen.notice == "" and app.state.scene_name == XSS[0]
    saved = app.files_tab.save_scene.filename
    assert "<" not in saved and "/" not in saved
    assert_inert(app)
    # the core echoes these texts in its messages
    for bad in (edited("base.creep", {"model": XSS[1], "modulus": 3e10}),
                edited("punch.shape", {"expr": "sin(x) + " + XSS[2]}),
                edited("punch.shape", {"kind": XSS[0]}),
                edited("loading.force", {"kind": "table", XSS[2]: 1})):
        app.files_tab.load_file.filename = XSS[1] + ".json"
        app.files_tab.load_file.value = json.dumps(bad).encode()
        assert app.screen.notice.startswith("The scene was not loaded"), app.screen.notice
        assert_inert(app)
    app.files_tab.load_file.value = b"{" + XSS[2].encode()
    assert "not valid JSON" in app.screen.notice
    assert_inert(app)
    # a value typed into the name field
    app.files_tab.scene_name.value = XSS[0]
    assert_inert(app)


def test_markup_in_an_uploaded_table_is_shown_as_text(explorer_app) -> None:
    app = explorer_app()
    app.punch_tab.shape_file.filename = XSS[1] + ".csv"
    app.punch_tab.shape_file.value = ("x,f\n-0.5,0\n0," + XSS[2] + "\n").encode()
    assert app.screen.notice.startswith("The shape table was not used: Punch, shape (punch.shape): "
                                 "line 3, column 2:"), app.screen.notice
    assert_inert(app)
    app.punch_tab.shape_file.value = b"x,f\n-0.5,0.00002\n0,0\n0.5,0.00001\n"
    assert app.state.punch.shape == "custom" and app.screen.notice == ""
    assert "&lt;img" in app.punch_tab.shape_note.object
    assert_inert(app)


def test_markup_in_a_solver_message_is_shown_as_text(explorer_app) -> None:
    """A valid file whose creep formula fails at solve time: the alert escapes it."""
    app = explorer_app()
    shown = app.controller.view
    app.state.base.param.update(creep_model="custom", custom={
        "model": "kernel", "modulus": 3e10, "expr": "0.01 * exp(-(t - tau))"})
    assert app.results.alert.visible and "base.creep.expr" in app.results.alert.object
    assert app.controller.view is shown
    app.controller.param.update(error="solve: " + XSS[1])
    assert_inert(app)


def test_uploads_over_the_limits_are_refused_with_a_notice(explorer_app) -> None:
    app = explorer_app()
    shown = app.controller.view
    app.files_tab.load_file.filename = "big.json"
    app.files_tab.load_file.value = b" " * (MAX_SCENE_BYTES + 1)
    assert "too large" in app.screen.notice and str(MAX_SCENE_BYTES) in app.screen.notice
    app.files_tab.load_file.filename = "deep.json"
    app.files_tab.load_file.value = b"[" * 100_000 + b"]" * 100_000
    assert "nested too deeply" in app.screen.notice
    app.punch_tab.shape_file.filename = "big.csv"
    app.punch_tab.shape_file.value = b"x,f\n" + b"0.0,0.0\n" * 200_000
    assert "punch.shape" in app.screen.notice and "too large" in app.screen.notice
    app.punch_tab.shape_file.filename = "rows.csv"
    rows = "".join(f"{k / 20000 - 0.25},0\n" for k in range(10_001))
    app.punch_tab.shape_file.value = rows.encode()
    assert "too many rows" in app.screen.notice
    assert app.controller.view is shown and app.controller.error == ""


def test_an_uploaded_scene_is_read_as_strictly_as_the_command_line_reads_it(explorer_app) -> None:
    """A field given twice is refused (json.loads would silently keep the second), as are
    text that is not UTF-8 and numbers beyond any double; the result on screen stays."""
    app = explorer_app()
    shown = app.controller.view
    text = json.dumps(base_scene())
    app.files_tab.load_file.filename = "twice.json"
    app.files_tab.load_file.value = text.replace('"name":', '"name": "first", "name":', 1).encode()
    assert app.screen.notice == "The file 'twice.json': duplicate field 'name' in one JSON object"
    app.files_tab.load_file.filename = "latin1.json"
    app.files_tab.load_file.value = b'{"name": "caf\xe9"}'  # Latin-1
    assert "not text in UTF-8" in app.screen.notice
    app.files_tab.load_file.filename = "huge.json"
    app.files_tab.load_file.value = text.replace(
        '"schema_version": 1', '"schema_version": ' + "9" * 500, 1).encode()
    assert app.screen.notice.startswith("The scene was not loaded"), app.screen.notice
    assert app.controller.view is shown and app.controller.error == ""


def test_an_uploaded_table_with_too_many_rows_for_the_solver_keeps_the_last_result(
        explorer_app) -> None:
    app = explorer_app()
    shown = app.controller.view
    rows = "".join(f"{x:.4f},{1e-5 * (1 + np.sin(20 * x)):.3e}\n"
                   for x in np.linspace(-0.9, 0.9, 40))
    app.punch_tab.shape_file.filename = "measured.csv"
    app.punch_tab.shape_file.value = ("x,f\n" + rows).encode()
    # every row of a linear table is a kink, the end rows too (the held value begins):
    # more than the solver allows, so the upload itself is refused, naming the limit
    assert app.state.punch.shape == "flat"
    assert "(punch.shape): a table of 40 rows" in app.screen.notice and "16" in app.screen.notice
    assert app.controller.view is shown


def test_a_deeply_nested_link_is_refused(explorer_app) -> None:
    import base64
    import zlib

    raw = b'{"a":' + b"[" * 90_000 + b"]" * 90_000 + b"}"
    assert len(raw) < MAX_JSON
    link = PREFIX + base64.urlsafe_b64encode(zlib.compress(raw, 9)).decode().rstrip("=")
    with pytest.raises(ValueError, match="nested too deeply"):
        decode_scene(link)
    app = explorer_app(query={"scene": link})
    assert "nested too deeply" in app.screen.notice and app.controller.view is not None


def test_the_server_listens_on_localhost_unless_told(monkeypatch) -> None:
    import explorer.__main__ as entry

    served: list[dict[str, Any]] = []  # the options pn.serve would be given
    monkeypatch.setattr(entry, "_serve", lambda pn, apps, **k: served.append(k))
    base = ["--port", "5999", "--warm-up", "none", "--solver-processes", "0"]
    assert entry.main(base) == 0
    assert served[-1]["address"] == "localhost" and served[-1]["websocket_origin"] is None
    assert entry.main([*base, "--address", "0.0.0.0"]) == 0
    origins = served[-1]["websocket_origin"]
    assert served[-1]["address"] == "0.0.0.0" and "localhost:5999" in origins
    assert entry.main([*base, "--address", "0.0.0.0",
                       "--allow-websocket-origin", "lab.example.org:80"]) == 0
    assert served[-1]["websocket_origin"] == ["lab.example.org:80"]
    count = len(served)
    assert entry.main([*base[:-1], "-1"]) == 2  # --solver-processes -1: refused, not served
    assert len(served) == count


# ------------------------------------------------------------------ in a real browser



@pytest.fixture(scope="module")
def served(request: pytest.FixtureRequest) -> Iterator[str]:
    require_browser()
    yield from served_explorer(request.getfixturevalue("explorer_server"))


@pytest.mark.browser
@pytest.mark.timeout(300)
def test_markup_in_a_link_and_an_upload_does_not_run_in_the_browser(served: str,
                                                                    tmp_path: Path) -> None:
    from playwright.sync_api import sync_playwright

    scene = base_scene()
    scene["punch"]['<img src=x onerror="window.__xss=1">'] = 1.0
    profile = tempfile.mkdtemp(prefix="security-chromium-")
    try:
        with sync_playwright() as p:
            context = p.chromium.launch_persistent_context(
                profile, executable_path=CHROMIUM, headless=True, args=CHROMIUM_ARGS)
            page = context.new_page()
            dialogs: list[str] = []
            page.on("dialog", lambda d: (dialogs.append(d.message), d.dismiss()))
            page.goto(f"{served}/app?scene={encode_scene(scene)}")
            notice = page.locator(".notice").first
            notice.wait_for(state="visible", timeout=60_000)
            text = notice.evaluate("e => (e.shadowRoot || e).textContent")
            assert '<img src=x onerror="window.__xss=1">' in text
            assert notice.evaluate("e => (e.shadowRoot || e).querySelectorAll('img, script')"
                                   ".length") == 0
            # an uploaded table with markup in a cell
            page.locator(".bk-tab", has_text="Punch").first.click()
            table = tmp_path / "shape.csv"
            table.write_text("x,f\n-0.5,0\n0,<img src=x onerror=alert(1)>\n")
            page.locator("input[type=file]").first.set_input_files(str(table))
            deadline = time.monotonic() + 60
            text = ""
            while "line 3" not in text and time.monotonic() < deadline:
                page.wait_for_timeout(200)
                text = notice.evaluate("e => (e.shadowRoot || e).textContent")
            assert "<img src=x onerror=alert(1)>" in text and "punch.shape" in text
            page.wait_for_timeout(500)  # an injected image would fail to load and fire
            assert page.evaluate("() => window.__xss") is None
            assert dialogs == []
            context.close()
    finally:
        shutil.rmtree(profile, ignore_errors=True)
