"""A cold ``python -m core solve`` loads only what its scene needs.

The command line's start-up is mostly imports (``python -m benchmarks.cold_start``): these
modules are imported where they are used, so a solve that needs none of them never loads
them. Checked in a fresh process (this one has imported everything already), by what is
in ``sys.modules`` after the solve, not by timing.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

#: What a solve of a scene off the exact layered path, without the FE check, a report, a
#: plot or a study does not import.
NOT_LOADED = (
    "scipy.fft",  # the exact layered kernel's Galerkin matrix only
    "scipy.special",  # behind scipy.fft
    "core.scene.coating_check",  # the FE check (core.scene.check_scene)
    "core.coating.fem_check",  # its finite elements (core.coating.solve_stack)
    "core.coating.fem_stack",
    "core.coating.fem_mesh",
    "skfem",
    "jsonschema",  # `validate` and the schema errors only
    "core.report",
    "core.study",
    "dask",
    "holoviews",
    "panel",
    "bokeh",
    "matplotlib",
)

_CHILD = """
import json, sys
from core.cli import main
code = main(["solve", sys.argv[1], "-o", sys.argv[2]])
print(json.dumps({"code": code, "loaded": [m for m in sys.argv[3:] if m in sys.modules]}))
"""


@pytest.mark.parametrize("preset", ["worn_coating", "uniform_flat"])
def test_a_solve_loads_no_module_it_does_not_use(preset: str, tmp_path: Path):
    env = dict(os.environ, PYTHONPATH=str(ROOT), OPENBLAS_NUM_THREADS="1")
    proc = subprocess.run(
        [sys.executable, "-c", _CHILD, f"preset:{preset}", str(tmp_path / "out.json"),
         *NOT_LOADED], cwd=ROOT, env=env, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    answer = json.loads(proc.stdout.splitlines()[-1])
    assert answer["code"] == 0, proc.stderr
    assert answer["loaded"] == []
    assert (tmp_path / "out.json").is_file()


def test_the_lazy_names_are_the_modules_own():
    """Loaded on first use, the names are the same objects under their one import path."""
    import core.coating
    import core.scene
    from core.coating import CoatingStrip, Stack, solve_stack
    from core.coating.fem_check import solve_stack as fem_solve_stack
    from core.coating.fem_stack import CoatingStrip as FemStrip
    from core.coating.fem_stack import Stack as FemStack
    from core.scene import check_scene
    from core.scene.coating_check import check_scene as own_check_scene

    assert (solve_stack, CoatingStrip, Stack) == (fem_solve_stack, FemStrip, FemStack)
    assert check_scene is own_check_scene
    assert {"solve_stack", "CoatingStrip", "Stack"} <= set(dir(core.coating))
    assert "check_scene" in dir(core.scene)
    with pytest.raises(AttributeError, match="no attribute 'no_such_name'"):
        core.scene.no_such_name  # noqa: B018
    with pytest.raises(AttributeError, match="no attribute 'no_such_name'"):
        core.coating.no_such_name  # noqa: B018


_FIT_CHILD = """
import json, sys
import core
from core.presets import read_preset

scene = read_preset("uniform_flat")
measured = core.solve(scene)
readings = {"time": measured.times.tolist(), "settlement_std": 1e-6,
            "settlement": (1.01 * measured.settlement).tolist()}
fit = core.calibrate(scene, readings, fit=["base.creep.modulus"])
fit.forecast([1.0, 3650.0]).band("settlement")
print(json.dumps({"warnings": len(fit.warnings), "stats": "scipy.stats" in sys.modules}))
"""


def test_a_fit_and_its_band_load_no_statistics_module():
    # the chi^2 range and the band's normal quantile come from scipy.special: scipy.stats
    # cost a cold fit ~0.5 s (1.5 s beside a test run) to import for two numbers
    env = dict(os.environ, PYTHONPATH=str(ROOT), OPENBLAS_NUM_THREADS="1")
    proc = subprocess.run([sys.executable, "-c", _FIT_CHILD], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout.splitlines()[-1])["stats"] is False
