"""The report of a fitted scene with its back-analysis (``calibration=``): a section
"Back-analysis" with the readings, the fitted values with standard errors and units, the
correlation, chi^2/dof and the warnings; the HTML draws the readings over the settlement
history; the PDF prints the section."""

from __future__ import annotations

import holoviews  # noqa: F401  (installed by the test set-up)
import numpy as np
import pytest

import core
from core.presets import read_preset
from core.report import report_html, report_pdf, sections, write_report
from core.scene import number_text
from tests.cli_runs import run_cli

#: Reading times [day after loading] within the preset's output times.
TIMES = [5.0, 10.0, 20.0, 40.0, 80.0, 160.0, 300.0]


@pytest.fixture(scope="module")
def fitted() -> tuple[core.SceneSolution, object]:
    """The default-like creeping preset fitted by its coating modulus and the base's age
    at loading to settlements of the scene itself with a 1 % standard deviation."""
    scene = read_preset("uniform_flat")
    truth = core.solve(dict(scene, times=TIMES))
    scatter = 1 + 0.01 * np.array([1, -1, 0.5, -0.5, 1, -1, 0.0])
    readings = {"time": TIMES, "settlement": list(truth.settlement * scatter),
                "settlement_std": list(0.01 * truth.settlement)}
    calibration = core.calibrate(scene, readings,
                                 fit=["coating[0].modulus", "base.age_at_loading"])
    return core.solve(calibration.scene), calibration


def test_the_back_analysis_section_lists_the_fit(fitted):
    result, calibration = fitted
    titles = [s.title for s in sections(result, calibration=calibration)]
    assert titles.index("Back-analysis") == titles.index("Results") + 1
    assert "Back-analysis" not in [s.title for s in sections(result)]
    section = next(s for s in sections(result, calibration=calibration)
                   if s.title == "Back-analysis")
    rows = dict(section.rows)
    assert rows["readings"].startswith("7 (settlement [m]), t = 5 to 300 d")
    assert "with standard deviations" in rows["readings"]
    # value ± error, the 95 % interval (the page's column) and the start, each in its unit
    assert " ± " in rows["coating[0].modulus"] and rows["coating[0].modulus"].count(" Pa") == 3
    # the age, which this creep hardly feels (a standard error of 1e10 days), has an
    # unbounded interval, said so as on the Fit tab
    assert rows["base.age_at_loading"].count(" day") == 2
    assert ("(95 % interval not determined by the readings (see the warnings); start 28 day)"
            in rows["base.age_at_loading"])
    low, high = calibration.intervals(0.95)["coating[0].modulus"]
    assert f"(95 % interval {number_text(low, 4)} to {number_text(high, 4)} Pa; start" in (
        rows["coating[0].modulus"])
    corr = rows["correlation coating[0].modulus ~ base.age_at_loading"]
    assert corr == f"{calibration.correlation[0, 1]:+.3f}"
    assert rows["χ²/dof"].startswith(f"{calibration.chi2_per_dof:.3g} (5 dof)")
    assert [n.removeprefix("warning: ") for n in section.notes] == list(calibration.warnings)


def test_the_html_draws_the_readings_and_the_pdf_prints_the_section(fitted, tmp_path):
    result, calibration = fitted
    page = report_html(result, calibration=calibration)
    assert "<section class='report-back-analysis'>" in page
    assert "<div class='report-readings'><div" in page
    assert "readings and the fitted scene" in page
    plain = report_html(result)
    assert "report-back-analysis" not in plain and "report-readings" not in plain
    pdf = report_pdf(result, calibration=calibration)
    assert pdf.startswith(b"%PDF")
    write_report(result, tmp_path / "fit.html", calibration=calibration)
    assert "Back-analysis" in (tmp_path / "fit.html").read_text()


def test_the_command_line_writes_the_report_of_a_fit(tmp_path):
    readings = tmp_path / "levelling.csv"
    readings.write_text("time [day], settlement [mm]\n5, 0.0280\n10, 0.0309\n20, 0.0348\n"
                        "40, 0.0385\n80, 0.0406\n160, 0.0408\n300, 0.0408\n")
    report = tmp_path / "fit.html"
    done = run_cli("calibrate", "preset:uniform_flat", readings, "--fit",
                   "coating[0].modulus", "--report", report)
    assert done.returncode == 0, done.stderr
    page = report.read_text()
    assert "report-back-analysis" in page and "coating[0].modulus" in page
    bad = run_cli("calibrate", "preset:uniform_flat", readings, "--fit",
                  "coating[0].modulus", "--report", tmp_path / "fit.txt")
    assert bad.returncode == 2 and "--report: " in bad.stderr
