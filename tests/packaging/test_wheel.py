"""What a user gets from the built wheel, not from this checkout.

The wheel is built from a copy of the working tree, installed (not editable) in a new
virtual environment, and run from a folder outside the checkout with ``PYTHONPATH``
unset: the console scripts answer, the shipped data is found through the package, and the
served explorer shows every preset and every lesson in Chromium.

The environment sees this machine's packages (``--system-site-packages``), so that the
requirements are met without downloads; that the requirements are complete is checked
against the imports in ``test_metadata.py``.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tarfile
import zipfile
from pathlib import Path

import pytest

from tests.browser_pages import JS_READY, chromium_context, patience, require_browser

pytestmark = [pytest.mark.browser, pytest.mark.slow]

ROOT = Path(__file__).resolve().parents[2]


def _run(*args: str | Path, cwd: Path, timeout: float = 600) -> str:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["OPENBLAS_NUM_THREADS"] = "1"
    run = subprocess.run([str(a) for a in args], cwd=cwd, env=env, capture_output=True,
                         text=True, timeout=timeout)
    assert run.returncode == 0, f"{args}:\n{run.stdout[-2000:]}\n{run.stderr[-3000:]}"
    return run.stdout


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> dict[str, Path]:
    """The wheel, and a virtual environment with it installed; ``away``: a folder outside
    the checkout to run from."""
    base = tmp_path_factory.mktemp("wheel")
    # the working tree as git would commit it (tracked and new files, nothing ignored), but
    # for this test run's own temporary folders where --basetemp puts them in the checkout
    # (their "current" links point outside it, which the extraction below refuses)
    runs = tmp_path_factory.getbasetemp().resolve()
    files = subprocess.run(["git", "ls-files", "-co", "--exclude-standard", "-z"], cwd=ROOT,
                           capture_output=True, check=True).stdout.split(b"\0")
    source = base / "source"
    with tarfile.open(base / "tree.tar", "w") as tar:
        for name in filter(None, files):
            path = ROOT / name.decode()
            if path.exists() and not path.is_relative_to(runs):
                tar.add(path, arcname=name.decode())
    with tarfile.open(base / "tree.tar") as tar:
        tar.extractall(source, filter="data")
    dist = base / "dist"
    _run(sys.executable, "-m", "pip", "wheel", "--no-deps", "--disable-pip-version-check",
         "-q", "-w", dist, source, cwd=base)
    venv = base / "venv"
    _run(sys.executable, "-m", "venv", "--system-site-packages", venv, cwd=base)
    wheel = next(dist.glob("coated_punch-*.whl"))
    _run(venv / "bin" / "python", "-m", "pip", "install", "-q", "--disable-pip-version-check",
         wheel, cwd=base)
    away = base / "away"
    away.mkdir()
    return {"wheel": wheel, "bin": venv / "bin", "away": away, "venv": venv}


def test_the_wheel_carries_the_data_the_code_reads(installed):
    names = set(zipfile.ZipFile(installed["wheel"]).namelist())
    from core.presets import preset_names, study_names

    for name in preset_names():
        assert f"core/presets/scenes/{name}.json" in names
    for name in study_names():
        assert f"core/presets/studies/{name}.json" in names
    assert {"core/SCENES.md", "core/coating/error_table.json", "core/py.typed",
            "core/scene/schemas/scene.schema.json",
            "core/scene/schemas/study.schema.json"} <= names
    assert any(n.endswith(".dist-info/licenses/LICENSE") for n in names)
    meta = zipfile.ZipFile(installed["wheel"]).read(
        next(n for n in names if n.endswith(".dist-info/METADATA"))).decode()
    assert "License-Expression: BSD-3-Clause" in meta
    assert 'Provides-Extra: explorer' in meta


def test_the_installed_package_runs_outside_the_checkout(installed):
    away, bin_ = installed["away"], installed["bin"]
    where = _run(bin_ / "python", "-c",
                 "import core, explorer; print(core.__file__); print(explorer.__file__)",
                 cwd=away)
    assert all(line.startswith(str(installed["venv"])) for line in where.split()), where
    import core

    for script in ("coated-punch", "coated-punch-explorer"):
        assert _run(bin_ / script, "--version", cwd=away).strip() \
            == f"coated-punch {core.__version__}"
    # the format document the help names is installed, and a preset solves by its name
    usage = "".join(_run(bin_ / "coated-punch", "--help", cwd=away).split())  # unwrapped
    assert f"{installed['venv']}/lib/" in usage and "/site-packages/core/SCENES.md" in usage
    solved = json.loads(_run(bin_ / "coated-punch", "solve", "preset:uniform_flat", "-o", "-",
                             cwd=away))
    assert solved["version"] == core.__version__
    assert _run(bin_ / "coated-punch", "validate", "preset:worn_coating", cwd=away)
    script = ("import core; from core.presets import preset_names, read_preset; "
              "print(len(preset_names())); "
              "print(core.solve(read_preset('worn_coating')).settlement[-1])")
    count, settlement = _run(bin_ / "python", "-c", script, cwd=away).split()
    from core.presets import preset_names, read_preset

    assert int(count) == len(preset_names())
    # the same code on the same machine: the same number to the last digit
    assert float(settlement) == core.solve(read_preset("worn_coating")).settlement[-1]


def test_the_installed_explorer_shows_every_preset_and_lesson(installed):
    require_browser()
    from explorer.model import lessons, preset_label, presets
    from tests.support.serving import ExplorerProcess

    expected_presets = [preset_label(k, v) for k, v in presets().items()]
    expected_lessons = [lesson.title for lesson in lessons().values()]
    program = [str(installed["bin"] / "coated-punch-explorer")]
    with ExplorerProcess(program=program, cwd=installed["away"], ready_timeout=240,
                         args=["--solver-processes", "1"],
                         env={"OPENBLAS_NUM_THREADS": "1"}) as server:
        for context in chromium_context(1400, 900):
            page = context.new_page()
            page.goto(server.url + "/app?preset=worn_coating")
            page.wait_for_function(JS_READY, timeout=120_000 * patience())
            shown = page.locator(".preset-select select option").all_inner_texts()
            assert [s.strip() for s in shown if s.strip() in expected_presets] \
                == expected_presets, shown
            # the link's preset is the scene on screen
            page.wait_for_function("() => Bokeh.documents[0].get_model_by_name("
                                   "'scene_figure').title.text.includes('Worn')",
                                   timeout=60_000 * patience())
            page.locator(".bk-tab", has_text="Lessons").first.click()
            select = page.locator(".lesson-select select").first
            select.wait_for(state="visible", timeout=30_000 * patience())
            options = [s.strip() for s in select.locator("option").all_inner_texts()]
            assert [o for o in options if o in expected_lessons] == expected_lessons, options
            page.close()
        assert "Traceback" not in server.output(), server.output()[-3000:]
