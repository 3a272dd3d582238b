"""A scene's answer in a notebook: a notebook that solves a preset, shows the result (its
HTML table), its xarray Dataset and its HoloViews plot runs headless in a real kernel
(nbclient, ipykernel) without an error, and each cell shows what it should."""

from __future__ import annotations

import os
from pathlib import Path

import ipykernel  # noqa: F401  (installed by the test set-up)
import nbclient
import nbformat
import pytest

ROOT = Path(__file__).resolve().parents[2]
PRESET = ROOT / "core" / "presets" / "scenes" / "eccentric_footing_liftoff.json"
#: The libraries that only the data and plot methods load.
LATE = ("holoviews", "xarray", "bokeh")

CELLS = [
    "import sys\n"
    "import core\n"
    "from core.scene import load_scene\n"
    f"r = core.solve(load_scene({str(PRESET)!r}))\n"
    "print(core.__file__)",
    "r",
    f"print(sorted(m for m in {LATE!r} if m in sys.modules))",
    "ds = r.to_xarray()\n"
    "print(dict(ds.sizes), ds.pressure.attrs['units'], ds.attrs['version'])\n"
    "ds",
    "import holoviews as hv\n"
    "hv.extension('bokeh')\n"
    "r.plot()",
]


def _texts(output: dict) -> str:
    if output["output_type"] == "stream":
        return output["text"]
    return "".join(str(v) for v in output.get("data", {}).values())


@pytest.mark.slow
def test_a_notebook_shows_the_result_its_dataset_and_its_plot(tmp_path: Path) -> None:
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_code_cell(source) for source in CELLS]
    # the kernel imports this checkout's core, whatever is installed
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(ROOT)] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]),
        OPENBLAS_NUM_THREADS="1")
    client = nbclient.NotebookClient(nb, kernel_name="python3", timeout=300,
                                     resources={"metadata": {"path": str(tmp_path)}})
    client.execute(env=env)
    outputs = [cell.outputs for cell in nb.cells]
    errors = [o for cell in outputs for o in cell if o["output_type"] == "error"]
    assert not errors, "\n".join(f"{e['ename']}: {e['evalue']}" for e in errors)

    solved, shown, late, dataset, plot = outputs
    # jupyter_client runs the kernel spec's "python" as this Python; core is this checkout's
    assert _texts(solved[0]).strip() == str(ROOT / "core" / "__init__.py")
    html = shown[0]["data"]["text/html"]
    assert html.startswith('<div class="coated-punch-solution">')
    assert "contact width" in html and "lift-off" in html
    assert shown[0]["data"]["text/plain"].startswith("SceneSolution 'Eccentric footing")
    # solving and showing the result loaded none of the plotting or data libraries
    assert _texts(late[0]).strip() == "[]"
    assert _texts(dataset[0]).startswith("{'x': 201, 'time': 20} Pa ")
    assert "xarray.Dataset" in dataset[-1]["data"]["text/plain"]
    # the layout, rendered by the Bokeh backend into the cell's HTML
    shown_plot = plot[-1]
    assert shown_plot["output_type"] == "execute_result"
    assert shown_plot["data"]["text/plain"].startswith(":Layout")
    assert "application/vnd.holoviews_exec.v0+json" in shown_plot["data"]
    page = shown_plot["data"]["text/html"]
    for text in ("contact pressure q(x, t)", "lift-off at t = 1000 days (2.7 years)", "q (MPa)",
                 "settlement (mm)", "tilt (mrad)"):
        assert text in page, text
