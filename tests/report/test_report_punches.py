"""The printable report of several punches (core/report/punches.py): each punch's results
in the global x, what the punches share said once and the rest per punch, the design
check per punch, q(x) over the whole surface and the histories with a line per punch, in
the HTML and the PDF."""

from __future__ import annotations

import re
from typing import Any

import holoviews  # noqa: F401  (installed by the test set-up)
import numpy as np
import pytest

import core
from core.report import report_html, report_pdf, sections
from core.report.content import key_numbers
from core.report.punches import local_view
from core.scene import PunchesSolution, days_text
from tests.support.punch_pairs import wide_and_narrow

CREEP = {"model": "exponential", "modulus": 3.0e10, "compliance": 3.0e-11, "rate": 0.05}


def _pair(**extra: Any) -> dict[str, Any]:
    """Two punches on a creeping base: a wide one under a force and a moment, a narrow
    one held level under a force (its moment changes as the base creeps)."""
    return wide_and_narrow(CREEP, {"end": 365.0, "count": 6, "spacing": "log"}) | extra


@pytest.fixture(scope="module")
def pair() -> PunchesSolution:
    # q peaks at 550 kPa under punches[0] and 489 kPa under punches[1] (measured)
    return core.solve(_pair(limits={"allowable_pressure": 5.0e5}))


def _rows(result: PunchesSolution, title: str, time: float | None = None) -> dict[str, str]:
    return next(dict(s.rows) for s in sections(result, time) if s.title.startswith(title))


def test_a_section_of_results_per_punch(pair: PunchesSolution) -> None:
    titles = [s.title for s in sections(pair)]
    assert titles == ["About", "Validity", "Design check", "Results: punches[0] at x = -1.5 m",
                      "Results: punches[1] at x = 1.5 m", "Accuracy", "Inputs"]
    about = _rows(pair, "About")
    assert about["statements"] == ("punches[0] 4: force and moment given; punches[1] 3: "
                                   "tilt and force given")
    design = next(s for s in sections(pair) if s.title == "Design check")
    assert design.tone == "bad" and design.lead == "A limit is exceeded under punches[0]."
    rows = dict(design.rows)
    assert rows["punches[0] largest contact pressure q_max"].endswith(": FAIL")
    assert rows["punches[1] largest contact pressure q_max"].endswith(": pass")


def test_a_punch_is_said_as_one_punch_in_the_global_x(pair: PunchesSolution) -> None:
    for k, punch in enumerate(pair.punches):
        rows = _rows(pair, f"Results: punches[{k}]", time=30)
        single = dict(key_numbers(local_view(punch), 30))
        for label in ("largest settlement δ", "largest tilt α", "force P at the last time",
                      "moment M at the last time"):
            assert rows[label] == single[label]
        # the largest pressure is at the punch's edge: the same place, told from 0
        x = float(re.search(r"at x = (-?[0-9.]+) m", rows["largest contact pressure q"])[1])
        x_own = float(re.search(r"at x = (-?[0-9.]+) m",
                                single["largest contact pressure q"])[1])
        assert x == pytest.approx(punch.center + x_own, abs=1e-3)  # printed to 4 digits
        j = int(np.argmin(np.abs(pair.times - 30)))
        assert f"t = {pair.times[j]:.4g}".rstrip("0").rstrip(".") in \
            next(label for label in rows if label.startswith("at t = "))
        assert rows["flags"] == "none"
        assert rows[next(label for label in rows if label.startswith("contact at"))] == \
            f"full contact: the whole width 2a = {2 * punch.scene.half_width:g} m touches"


def test_what_the_punches_share_is_said_once(pair: PunchesSolution) -> None:
    inputs = _rows(pair, "Inputs")
    assert inputs["coating layer 1"].startswith("h = 20 mm, E = 800 MPa")
    assert inputs["base creep"].startswith("exponential creep")
    assert inputs["punches[0]"] == ("centre x = -1.5 m, half-width a = 1 m (width 2a = 2 m); "
                                    "base flat")
    assert inputs["punches[1] force P (given)"] == "300 kN/m"
    assert inputs["punches[1] tilt α (given)"] == "0 mrad"
    assert not any(label.startswith("punches[0] coating") for label in inputs)
    accuracy = _rows(pair, "Accuracy")
    assert accuracy["solved by"].startswith("nystrom engine")
    assert "target 1e-06: met" in accuracy["punches[1] numerical error (estimated, relative)"]


def test_a_coating_that_varies_along_x_is_said_under_each_punch() -> None:
    d = _pair()
    d["base"]["creep"] = {"model": "elastic", "modulus": 3.0e10}
    d["coating"][0]["thickness"] = {"kind": "linear", "start": 0.01, "end": 0.03}
    # free to tilt: held level, the narrow punch would pull on the thin side of its coating
    d["punches"][1]["loading"] = {"force": 3e5, "moment": 0.0}
    inputs = _rows(core.solve(d), "Inputs")
    assert "coating layer 1" not in inputs
    # the span of the punches is -2.5 to 2.1 m: 10 mm at its start, 30 mm at its end
    assert inputs["punches[0] coating layer 1"].startswith("h = 10 to 18.7 mm (linear")
    assert inputs["punches[1] coating layer 1"].startswith("h = 24.78 to 30 mm (linear")


def test_the_fe_check_and_a_back_analysis_are_refused(pair: PunchesSolution) -> None:
    with pytest.raises(ValueError, match=r"^check: the finite-element check is of one"):
        sections(pair, check={"scene_key": "x"})
    with pytest.raises(ValueError, match=r"^calibration: a back-analysis is of one punch"):
        report_html(pair, calibration=object())


def test_the_html_draws_the_surface_and_a_line_per_punch(pair: PunchesSolution) -> None:
    text = report_html(pair, time=30)
    assert text.startswith("<!DOCTYPE html>") and text.endswith("</html>")
    assert "contact pressure q(x, t), 2 punches (zones shaded)" in text
    assert "<td>zone</td><td>x = 0.9 to 2.1 m (shaded in q(x))</td>" in text
    j = int(np.argmin(np.abs(pair.times - 30)))
    assert f'"t = {days_text(pair.times[j])}"' in text  # the chosen time
    # the plots' titles (Bokeh's JSON escapes the Greek letters)
    titles = set(re.findall(r'"text":"(\w+) [^"]*\(t\)"', text))
    assert titles == {"settlement", "tilt", "moment"}  # both forces are given constants
    assert '"punches[0]"' in text and '"punches[1]"' in text  # the histories' legends
    assert "&quot;punches&quot;: [" in text  # the scene file, escaped


def test_the_pdf_has_text_plot_and_scene_pages(pair: PunchesSolution) -> None:
    data = report_pdf(pair)
    assert data.startswith(b"%PDF-")
    # two pages of text, one of plots (four), one of the scene file (measured)
    assert len(re.findall(rb"/Type\s*/Page\b", data)) == 4
