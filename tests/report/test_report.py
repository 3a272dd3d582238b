"""The printable report: what it says (validity, design check, results with units,
accuracy, the scene), its real plots (Bokeh in the HTML, Matplotlib in the PDF), the
command line's ``report``, and the message when the report's packages are missing."""

from __future__ import annotations

import re
import sys

import pytest

import core
from core.optional import MissingDependency
from core.presets import read_preset
from core.report import report_html, report_pdf, sections
from tests.cli_runs import run_cli

pytest.importorskip("holoviews")


@pytest.fixture(scope="module")
def checked() -> core.SceneSolution:
    """A lift-off preset with limits, one of them exceeded (the pressure peaks at
    1.97 MPa, measured)."""
    scene = read_preset("eccentric_footing_liftoff")
    scene["limits"] = {"allowable_pressure": 1.5e6, "settlement_limit": 0.01}
    return core.solve(scene)


def test_the_sections_say_validity_check_results_and_accuracy(checked):
    titles = [s.title for s in sections(checked)]
    assert titles == ["About", "Validity", "Design check", "Results", "Accuracy"]
    design = dict(sections(checked)[2].rows)
    assert sections(checked)[2].tone == "bad"
    assert design["largest contact pressure q_max"].endswith("FAIL")
    assert design["largest settlement"].endswith(": pass")
    about = dict(sections(checked)[0].rows)
    assert about["made by"].startswith(f"coated-punch {core.__version__}, ")
    assert about["statement"] == "4: force and moment given"
    results = dict(sections(checked)[3].rows)
    assert "smallest contact width" in results  # the punch lifts off
    assert re.fullmatch(r"[0-9.]+ kPa at x = 1 m, t = [0-9.]+ d",
                        results["largest contact pressure q"])


def test_no_design_section_without_limits():
    result = core.solve(read_preset("uniform_flat"))
    assert "Design check" not in [s.title for s in sections(result)]


def test_the_html_report_embeds_bokeh_plots_and_the_scene(checked):
    text = report_html(checked)
    assert text.startswith("<!DOCTYPE html>") and text.endswith("</html>")
    assert "Bokeh.embed" in text or "embed_items" in text  # the plots are Bokeh's
    assert "https://" not in text.split("<body>")[0].split("<script")[0]
    assert "class='bad'>A limit is exceeded." in text
    assert "&quot;allowable_pressure&quot;: 1500000.0" in text  # the scene file, escaped


def test_the_html_report_escapes_the_scene_name():
    scene = read_preset("uniform_flat")
    scene["name"] = "<script>alert(1)</script>"
    text = report_html(core.solve(scene))
    assert "<script>alert(1)</script>" not in text
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in text


def test_the_pdf_report_has_text_plot_and_scene_pages(checked):
    data = report_pdf(checked)
    assert data.startswith(b"%PDF-")
    # text, plots, scene file: three pages for this scene (measured)
    assert len(re.findall(rb"/Type\s*/Page\b", data)) == 3


def test_the_command_line_writes_both_and_is_strict(tmp_path):
    html_path, pdf_path = tmp_path / "r.html", tmp_path / "r.pdf"
    assert run_cli("report", "preset:uniform_flat", "-o", html_path).returncode == 0
    assert "Coated punch: " in html_path.read_text()
    assert run_cli("report", "preset:uniform_flat", "-o", pdf_path).returncode == 0
    assert pdf_path.read_bytes().startswith(b"%PDF-")
    bad = run_cli("report", "preset:uniform_flat", "-o", tmp_path / "r.txt")
    assert bad.returncode == 2 and "a report is .html or .pdf" in bad.stderr
    scene = read_preset("uniform_flat")
    scene["limits"] = {"settlement_limit": 1e-9}
    path = tmp_path / "tight.json"
    core.save_scene(scene, path)
    strict = run_cli("report", path, "-o", html_path, "--strict")
    assert strict.returncode == 3, strict.stderr
    assert "design check failed (settlement_limit)" in strict.stderr
    assert html_path.exists()  # written all the same


def test_a_missing_plotting_package_is_named_with_its_extra(monkeypatch, checked):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    with pytest.raises(MissingDependency, match=r"coated-punch\[report\]"):
        report_pdf(checked)
