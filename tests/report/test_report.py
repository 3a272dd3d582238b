"""The printable report: what it says (validity, design check, results with units,
accuracy, the inputs in engineering units, the contact at a chosen time, the scene), its
real plots (Bokeh in the HTML, Matplotlib in the PDF: q(x, t), settlement, tilt, the
contact width when the punch lifts off, the geometry where it varies), the command line's
``report``, and the message when the report's packages are missing."""

from __future__ import annotations

import re
import sys

import holoviews  # noqa: F401  (installed by the test set-up)
import pytest

import core
from core.optional import MissingDependency
from core.presets import read_preset
from core.report import output_index, report_html, report_pdf, sections
from core.scene import scene_from_dict
from tests.cli_runs import run_cli


@pytest.fixture(scope="module")
def checked() -> core.SceneSolution:
    """A lift-off preset with limits, one of them exceeded (the pressure peaks at
    1.97 MPa, measured)."""
    scene = read_preset("eccentric_footing_liftoff")
    scene["limits"] = {"allowable_pressure": 1.5e6, "settlement_limit": 0.01}
    return core.solve(scene)


def rows(result: core.SceneSolution, title: str, time: float | None = None) -> dict:
    """The rows of the section ``title`` of the report of ``result``."""
    return next(dict(s.rows) for s in sections(result, time) if s.title == title)


def test_the_sections_say_validity_check_results_and_accuracy(checked):
    titles = [s.title for s in sections(checked)]
    assert titles == ["About", "Validity", "Design check", "Results", "Accuracy", "Inputs"]
    design = dict(sections(checked)[2].rows)
    assert sections(checked)[2].tone == "bad"
    assert design["largest contact pressure q_max"].endswith("FAIL")
    assert design["largest settlement δ (punch centre)"].endswith(": pass")
    # in the units of the results: the limits of the fixture, 1.5e6 Pa and 0.01 m
    assert "; limit 1500 kPa, utilisation 1.31: FAIL" in design["largest contact pressure q_max"]
    assert "; limit 10 mm, utilisation" in design["largest settlement δ (punch centre)"]
    about = dict(sections(checked)[0].rows)
    assert about["made by"].startswith(f"coated-punch {core.__version__}, ")
    assert about["statement"] == "4: force and moment given"
    results = dict(sections(checked)[3].rows)
    assert "smallest contact width" in results  # the punch lifts off
    # at the toe, the thin coating model's value, said so (core.scene.thin_edge_note)
    assert re.fullmatch(r"[0-9.]+ kPa at x = 1 m, t = [0-9.]+ days( \([0-9.]+ years\))?"
                        r"( and after)? \(at the edge: the thin coating model's springs "
                        r"bound it there\)",
                        results["largest contact pressure q"])
    assert results["eccentricity e = M/P at the last time"] == "0.6 m"  # 480 / 800 kN
    accuracy = rows(checked, "Accuracy")
    assert re.fullmatch(r"\d+ nodes, \d+ time steps", accuracy["discretization"])


def test_the_inputs_are_listed_in_engineering_units(checked):
    inputs = rows(checked, "Inputs")
    assert inputs["punch"] == "half-width a = 1 m (width 2a = 2 m); base flat"
    assert inputs["coating layer 1"] == "h = 15 mm, E = 400 MPa, ν = 0.35, smooth interface"
    assert inputs["base"] == ("H = 6 m, ν = 0.2, age at loading τ0 = 28 days, modulus at "
                              "loading E(τ0) = 23.52 GPa")
    assert inputs["base creep"] == ("aging creep (Arutyunyan): E∞ = 30 GPa; β = 0.5; α = "
                                    "0.03 1/day; C∞ = 0.009 1/GPa; A = 0.48 day/GPa; γ = "
                                    "0.03 1/day")
    assert inputs["force P (given)"] == "800 kN/m"
    assert inputs["moment M (given)"] == "480 kN·m/m"
    assert inputs["output times"] == ("20 output times, 0 to 1000 days (2.7 years) after loading "
                                     "(log spacing)")
    assert inputs["solver settings"] == "tol 0.0001, model_tol 0.02, contact auto"


@pytest.mark.parametrize(("preset", "label", "text"), [
    ("stepped_punch", "punch", "base f(x) = 0 to 0.015 mm (step profile) above its lowest "
                               "point"),
    ("patched_insert", "coating layer 1", "E = 500 to 3000 MPa (step profile)"),
    ("worn_coating", "coating layer 1", "h = 19.98 to 20 mm (bump profile)"),
    ("rounded_graded", "coating layer 1 (under the punch)", "h = 4 mm, E = 300 MPa"),
    ("young_concrete_50_years", "base creep", "fib Model Code 2010: strength class C30/37; "
                                              "cement N; RH = 60 %; h0 = 300 mm; T = 20 °C"),
    ("patched_insert", "base creep", "Prony series: E = 32 GPa; term 1: C = 0.01 1/GPa, "
                                     "A = 0 day/GPa, γ = 0.1 1/day; term 2:"),
    ("stepped_punch", "settlement δ (given)", "0.08 mm"),
    ("rounded_graded", "output times", "1 output time, 1 day after loading"),
])
def test_profiles_and_creep_models_are_said_in_their_units(preset, label, text):
    from core.report.inputs import input_rows

    listed = dict(input_rows(scene_from_dict(read_preset(preset))))
    assert text in listed[label]


def test_a_varying_load_is_given_by_its_range_and_kind():
    from core.report.inputs import input_rows

    scene = read_preset("uniform_flat")
    scene["loading"]["force"] = {"kind": "ramp", "start": 0.0, "end": 5e5, "duration": 10.0}
    listed = dict(input_rows(scene_from_dict(scene)))
    assert listed["force P (given)"] == ("0 to 500 kN/m (ramp profile); it steps or kinks "
                                         "at t = 10 days")


def test_the_contact_at_a_chosen_time_and_when_the_punch_lifts_off(checked):
    results = rows(checked, "Results", time=0.0)
    # the preset's description: at e = 0.6 m only 1.31 m of the 2 m carry the load
    assert results["contact at t = 0 days"] == ("contact 1.306 m of 2 m (65 %), lifted 0.694 m: "
                                             "x = -1 to -0.306 m (unilateral contact)")
    assert results["lift-off"].startswith("at 20 of 20 output times, first at t = 0 days")
    # the nearest output time: 46.42 d for 50 d (log spacing to 1000 d)
    assert ("contact at t = 46.42 days (the output time nearest the 50 days asked for)"
            in rows(checked, "Results", time=50))
    assert "contact at t = 1000 days (2.7 years)" in rows(checked, "Results")  # the last by default
    assert output_index(checked, 1000.4) == 19
    for bad, reason in ((-3.0, "outside the output times, 0 to 1000 days"),
                        (2000.0, "outside the output times"), (float("nan"), "not a finite"),
                        ("7", "not a finite")):
        with pytest.raises(ValueError, match=f"^time: .*{reason}"):
            sections(checked, time=bad)


def test_full_contact_is_said_and_a_lost_contact_named_not_physical():
    flat = rows(core.solve(read_preset("uniform_flat")), "Results")
    assert flat["contact at t = 365 days"] == "full contact: the whole width 2a = 2 m touches"
    assert "lift-off" not in flat and "smallest contact width" not in flat
    scene = read_preset("eccentric_footing_liftoff")
    scene["solver"]["contact"] = "full"
    lost = core.solve(scene)
    assert "contact_lost" in lost.flags
    text = rows(lost, "Results", time=0)["contact at t = 0 days"]
    # where the full-contact pressure is negative: 0.37 m of the heel (measured; the
    # unilateral answer lifts 0.69 m)
    assert text.startswith("contact 1.628 m of 2 m (81 %), q < 0 (contact lost, not "
                           "physical) 0.372 m: x = -1 to -0.628 m (full-contact model)")


def test_no_design_section_without_limits():
    result = core.solve(read_preset("uniform_flat"))
    assert "Design check" not in [s.title for s in sections(result)]


def test_the_html_report_embeds_bokeh_plots_and_the_scene(checked):
    text = report_html(checked, time=100)
    assert text.startswith("<!DOCTYPE html>") and text.endswith("</html>")
    assert "Bokeh.embed" in text or "embed_items" in text  # the plots are Bokeh's
    assert "https://" not in text.split("<body>")[0].split("<script")[0]
    assert "class='bad'>A limit is exceeded." in text
    assert "&quot;allowable_pressure&quot;: 1500000.0" in text  # the scene file, escaped
    # the plot of the contact over time, and the chosen time among the q(x) curves
    assert "contact width and lifted length (2a = 2 m)" in text
    assert '"t = 100 days"' in text and "<td>contact at t = 100 days</td>" in text
    assert "<h2>Inputs</h2>" in text and "punch base f(x)" not in text  # a flat punch


def test_the_html_report_loads_nothing_from_beside_it(checked):
    """Panel, once imported (the command line's report loads HoloViews, which loads it),
    adds its module shim to Bokeh's resources as ``static/extensions/panel/...``: a saved
    report asked for a file that does not exist beside it. Every script is inline, or
    from an absolute address."""
    import re

    import panel  # noqa: F401  (what a report made in the explorer's process has loaded)

    text = report_html(checked)
    sources = re.findall(r'<script[^>]*\ssrc="([^"]*)"', text)
    assert all(re.match(r"[a-z][a-z0-9+.-]*:|/", s) for s in sources), sources


def test_a_script_from_an_address_without_a_scheme_is_left_out_however_quoted():
    from core.report.html import _standalone

    head = ('<script src="static/a.js"></script>\n<script src=\'static/b.js\'></script>'
            '<script src=static/c.js></script><script type="module" src="/static/d.js">'
            '</script><script src="https://cdn.example/e.js"></script>'
            '<script src="//cdn.example/f.js"></script><script>var src = "x";</script>')
    assert _standalone(head) == ('<script src="https://cdn.example/e.js"></script>'
                                 '<script src="//cdn.example/f.js"></script>'
                                 '<script>var src = "x";</script>')


def test_the_geometry_is_drawn_where_it_varies_and_no_lift_off_plot_in_full_contact():
    text = report_html(core.solve(read_preset("stepped_punch")))
    assert "punch base f(x) above its lowest point [mm]" in text
    assert "coating thickness, all layers" not in text  # a uniform coating
    assert "contact width and lifted length" not in text  # in full contact


def test_the_html_report_escapes_the_scene_name():
    scene = read_preset("uniform_flat")
    scene["name"] = "<script>alert(1)</script>"
    text = report_html(core.solve(scene))
    assert "<script>alert(1)</script>" not in text
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in text


def test_the_pdf_report_has_text_plot_and_scene_pages(checked):
    data = report_pdf(checked, time=0)
    assert data.startswith(b"%PDF-")
    # text (with the inputs), plots (four, the contact width's among them), scene file:
    # three pages for this scene, whose text fills its page exactly (it ran onto a second
    # page, blank but for the blank line after the last section)
    assert len(re.findall(rb"/Type\s*/Page\b", data)) == 3


def test_the_pdf_plots_are_the_reports_in_its_colours():
    """The PDF draws the report's elements itself (not through HoloViews' Matplotlib
    backend, ~8 s of CPU a report): one plot per title, the q(x) curves in the time
    colours of the HTML report, the lifted part shaded, and a history of round-off only
    (the tilt of a centred load, ~1e-18 mrad) drawn flat at zero."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt
    from matplotlib.colors import to_hex

    from core.report.pdf import _plot_page
    from core.report.plots import report_layout
    from core.scene.plotting import time_colours

    for name, lifts in (("uniform_flat", False), ("eccentric_footing_liftoff", True)):
        result = core.solve(read_preset(name))
        layout, titles = report_layout(result, 0.0)
        figure = _plot_page(plt, layout, titles)
        try:
            axes = figure.axes
            assert [a.get_title() for a in axes] == titles
            q_lines = axes[0].get_lines()
            assert [to_hex(line.get_color()) for line in q_lines] == \
                [to_hex(c) for c in time_colours(len(q_lines))]
            assert all(a.get_xlabel() and a.get_ylabel() for a in axes)
            assert bool(axes[0].patches) == lifts  # the lifted part's shade
            if not lifts:
                assert max(abs(result.tilt)) < 1e-15 and axes[2].get_ylim() == (-1.0, 1.0)
        finally:
            plt.close(figure)


def test_the_command_line_writes_both_and_is_strict(tmp_path):
    html_path, pdf_path = tmp_path / "r.html", tmp_path / "r.pdf"
    done = run_cli("report", "preset:uniform_flat", "-o", html_path)
    # said as solve, preset and sweep say it (the report alone wrote its file unsaid: an
    # audit)
    assert done.returncode == 0 and done.stdout == f"written to {html_path}\n"
    assert "Coated punch: " in html_path.read_text()
    done = run_cli("report", "preset:uniform_flat", "-o", pdf_path)
    assert done.returncode == 0 and done.stdout == f"written to {pdf_path}\n"
    assert pdf_path.read_bytes().startswith(b"%PDF-")
    # on standard output, the report alone
    assert run_cli("report", "preset:uniform_flat", "-o", "-").stdout.rstrip().endswith(
        "</html>")
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
    # the exceeded limit itself, as solve says it (report said no word of it)
    assert "\nwarning: design_check: largest settlement" in "\n" + strict.stderr


def test_the_command_line_describes_the_contact_at_the_time_asked_for(tmp_path):
    path = tmp_path / "r.html"
    done = run_cli("report", "preset:eccentric_footing_liftoff", "-o", path, "--time", "0")
    assert done.returncode == 0, done.stderr
    assert "<td>contact at t = 0 days</td><td>contact 1.306 m of 2 m (65 %)" in path.read_text()
    # a time between the output times: the nearest, said so (365 read "at t = 316.2 days")
    done = run_cli("report", "preset:eccentric_footing_liftoff", "-o", path, "--time", "365")
    assert done.returncode == 0, done.stderr
    assert ("<td>contact at t = 316.2 days (the output time nearest the 365 days asked "
            "for)</td>") in path.read_text()
    late = run_cli("report", "preset:eccentric_footing_liftoff", "-o", path, "--time", "5000")
    assert late.returncode == 2
    assert "--time: 5000 days is outside the output times, 0 to 1000 days" in late.stderr


def test_a_missing_plotting_package_is_named_with_its_extra(monkeypatch, checked):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    with pytest.raises(MissingDependency, match=r"coated-punch\[report\]"):
        report_pdf(checked)
    # without both (the solver alone): the extra that brings both, not plot and then report
    monkeypatch.setitem(sys.modules, "holoviews", None)
    with pytest.raises(MissingDependency, match=r"coated-punch\[report\]"):
        report_pdf(checked)


def test_long_times_read_without_an_exponent_and_in_years():
    """The report wrote "t = 18260 d" where the page writes "18262.5 days (50.0 years)": an
    engineer filing a 50-year check reads years."""
    result = core.solve(read_preset("young_concrete_50_years"))
    assert result.times[-1] > 1e4  # 50 years of days
    text = "".join(f"{label} {value}" for s in sections(result) for label, value in s.rows)
    assert "e+04" not in text and "t = 18262.5 days (50.0 years)" in text
    assert ("200 output times, 0 to 18262.5 days (50.0 years) after loading (log spacing "
            "from 0.1 days)") in text
    assert " d," not in text and not text.rstrip().endswith(" d")


def test_the_plots_legends_read_long_times_without_an_exponent():
    """The report's (and the notebook's) q(x) curves were labelled "t = 1.826e+04 d" beside
    "t = 71.2 d"."""
    import holoviews as hv

    from core.report.plots import report_layout

    result = core.solve(read_preset("young_concrete_50_years"))
    layout, _ = report_layout(result, 0.0)
    labels = [curve.label for curve in layout.traverse(lambda x: x, [hv.Curve])
              if curve.label.startswith("t = ")]
    assert labels and "t = 18262.5 days (50.0 years)" in labels
    assert not any("e+" in label for label in labels), labels


def test_the_time_of_a_largest_value_is_the_design_checks():
    """A centred load's zero tilt read "largest tilt 0 mrad at t = 0 d" in the report and
    "at t = 365 days" on the page: one rule (core.scene.time_of_largest) for both, the
    first time that reaches it."""
    from core.report.content import key_numbers
    from core.scene import days_text, design_check

    result = core.solve(core.load_scene("preset:uniform_flat"))
    rows = dict(key_numbers(result))
    check = design_check(result)
    assert rows["largest tilt α"] == f"0 mrad at t = {check.check('tilt').time:g} days" \
        == "0 mrad at t = 0 days"
    assert rows["largest settlement δ"].endswith(
        f"at t = {days_text(check.check('settlement').time)}")


def test_no_text_page_of_the_pdf_is_blank_or_starts_blank():
    """The blank line after the last section made a blank second page when the text
    ended at a page's end (63 lines, 62 a page: the lift-off preset's report)."""
    from core.report.pdf import LINES_PER_PAGE, text_pages

    line, blank = ("text", "", False), ("", "", False)
    for count in (LINES_PER_PAGE - 1, LINES_PER_PAGE, LINES_PER_PAGE + 1, 2 * LINES_PER_PAGE):
        lines = [line] * count + [blank]
        pages = text_pages(lines)
        assert all(page and page[0][0] for page in pages), count
        assert sum(len(page) for page in pages) >= count
    # a blank that falls at a page's start is dropped, others kept
    pages = text_pages([line] * LINES_PER_PAGE + [blank, line, blank, line])
    assert [len(p) for p in pages] == [LINES_PER_PAGE, 3]


def test_a_moment_within_the_answers_accuracy_reads_zero():
    """A centred punch's moment is round-off: it read "-1.113e-15 kN·m/m" and its
    eccentricity "-1.391e-18 m"; a real moment is shown as it is."""
    centred = rows(core.solve(read_preset("rounded_graded")), "Results")
    assert centred["moment M at the last time"] == "0 kN·m/m"
    assert centred["eccentricity e = M/P at the last time"] == "0 m"
    eccentric = rows(core.solve(read_preset("eccentric_creep")), "Results")
    assert eccentric["moment M at the last time"] != "0 kN·m/m"
    # a given moment is the user's, however small (a flagged answer's accuracy, up to
    # 1e-3, zeroed an eccentricity of a millimetre a metre)
    small = read_preset("eccentric_creep")
    small["loading"]["moment"] = 1e-3 * small["loading"]["force"] * small["punch"]["half_width"]
    small["solver"] = {"tol": 1e-2}
    assert rows(core.solve(small), "Results")["moment M at the last time"] != "0 kN·m/m"


def test_the_inputs_say_when_a_given_load_steps():
    """An engineer's audit: a force stepping from 800 to 1600 kN/m at 200 days read
    "800 to 1600 kN/m (step profile)", its time only in the appended scene JSON."""
    scene = read_preset("uniform_flat")
    scene["loading"]["force"] = {"kind": "step", "values": [8e5, 1.6e6], "breaks": [200.0]}
    (inputs,) = [s for s in sections(core.solve(scene)) if s.title == "Inputs"]
    rows = dict(inputs.rows)
    assert rows["force P (given)"] == ("800 to 1600 kN/m (step profile); it steps or kinks "
                                       "at t = 200 days")
    assert rows["moment M (given)"] == "0 kN·m/m"


def test_the_pdf_plots_go_below_the_last_lines_of_text_where_they_fit():
    """An engineer's audit: a page of five lines, then a page of plots, read as a page
    left blank; the two punches' report took 5 pages, now 4 (its last 8 lines of text and
    its plots on one)."""
    import re

    from core.report.pdf import (
        LINES_PER_PAGE,
        PLOTS_GAP,
        _text_lines,
        plots_height,
        scene_lines,
        text_pages,
    )
    from core.report.plots import report_layout

    result = core.solve(read_preset("new_footing_beside_old"))
    pages = text_pages(_text_lines(result, None, None, None))
    used = 0.05 + len(pages[-1]) * 0.9 / LINES_PER_PAGE
    assert 0.95 - used - PLOTS_GAP - plots_height(report_layout(result, None)[0]) >= 0.04
    count = len(re.findall(rb"/Type\s*/Page[^s]", report_pdf(result)))
    # the scene file's text, on pages of its own
    scene_pages = len(text_pages(scene_lines(result)))
    assert count == len(pages) + scene_pages  # no page of its own for the plots


def test_the_html_plots_are_as_wide_as_the_pressures():
    """An engineer's audit: on a 1500 px page the tilt plot, below q(x) in the page's
    grid, was drawn ~120 px wide with its ticks overlapping: a plot narrower than q(x)'s
    (400 against 580 px, its legend beside it) in the same column of Bokeh's grid is
    squeezed. Every plot of the report is as wide as q(x)'s."""
    import holoviews as hv
    from bokeh.models import Plot

    from core.report.plots import report_layout

    layout, _ = report_layout(core.solve(read_preset("eccentric_footing_liftoff")))
    figure = hv.render(layout, backend="bokeh")
    widths = {plot.width for plot in figure.select({"type": Plot})}
    assert len(widths) == 1, widths
