"""Times after loading on the page: written out, never in e+04 notation."""

from __future__ import annotations

import copy

import pytest

from core.scene import days_text, number_text


@pytest.mark.parametrize(("days", "text"), [
    (0.0, "0 days"), (14.7, "14.7 days"), (28.0, "28 days"), (365.0, "365 days"),
    (1000.0, "1000 days (2.7 years)"), (18262.5, "18262.5 days (50.0 years)"),
    (0.0004, "0.0004 days"), (1.0, "1 day"), (1.00001, "1 day"), (1.5, "1.5 days"),
])
def test_days_are_written_out(days: float, text: str) -> None:
    assert days_text(days) == text


def test_plain_numbers_keep_the_exponent_only_beyond_a_million() -> None:
    assert number_text(123456.7) == "123500"
    assert number_text(0.30000000000000004) == "0.3"
    assert number_text(2.5e7) == "2.5e+07"


def test_a_fifty_year_history_reads_in_days_and_years(explorer_app) -> None:
    from explorer.model import presets

    scene = copy.deepcopy(presets()["eccentric_footing_liftoff"])
    scene["times"]["end"] = 18262.5       # 50 years
    app = explorer_app(scene=scene, solved=True)
    view = app.screen.shown()
    last = len(view.times) - 1
    app.results.show_time_texts(view, last)
    assert "t = 18262.5 days (50.0 years)" in app.results.time_label.object
    assert "At t = 18262.5 days (50.0 years) after loading" in app.results.readout.object
    assert "e+" not in app.results.time_label.object + app.results.readout.object
    app.figures.show_time(view, last)
    assert app.figures.q_fig.title.text == "Pressure q(x), t = 18262.5 days (50.0 years)"
    # in presentation mode without its years (beside the player), where at 1024 px it
    # was cut ("Pressure q(x), t = 1000 days (2.7"); back again after
    app.figures.set_presentation(True)
    assert app.figures.q_fig.title.text == "q(x) at t = 18262.5 days"
    app.figures.set_presentation(False)
    assert app.figures.q_fig.title.text == "Pressure q(x), t = 18262.5 days (50.0 years)"
    assert "e+" not in app.figures.contact.zone_label.text


def test_the_first_log_time_is_set_on_the_time_tab_and_kept_in_the_scene(explorer_app) -> None:
    """The young-concrete preset starts its log spacing at 0.1 day (its default, the last
    three decades of 50 years, began at 18 days); the box shows only with log spacing, an
    emptied box is the default again, and a value <= 0 is refused saying so."""
    app = explorer_app("young_concrete_50_years", solved=True)
    assert app.screen.shown().times[1] == 0.1
    box = app.times_tab.time_start
    assert box.visible and box.value == 0.1
    box.value = 1.0
    assert app.state.time_start == 1.0 and app.state.to_scene()["times"]["start"] == 1.0
    box.value = -2.0
    assert app.state.time_start == 1.0
    assert "first time after 0: must be a number of days > 0" in app.screen.notice
    box.value = None
    assert app.state.time_start is None and "start" not in app.state.to_scene()["times"]
    box.value = 0.5
    app.state.time_spacing = "linear"
    assert not box.visible and "start" not in app.state.to_scene()["times"]


def test_presentation_mode_gives_short_plots_few_ticks_and_short_titles(explorer_app) -> None:
    """At 1024x768 in presentation mode the histories of two punches were titled
    "Settlement δ: computed, per p" (cut) and their y ticks of 18 px ran into each other
    ("0.08 0.06 0.04 0.02 0"), as did the contact width's on the lift-off preset."""
    app = explorer_app("new_footing_beside_old", solved=True)
    figures = app.figures
    short = [*figures.history_fig.values(), figures.contact_fig]
    assert figures.history_fig["settlement"].title.text == \
        "Settlement δ [mm]: computed, per punch"
    figures.set_presentation(True)
    assert figures.history_fig["settlement"].title.text == "Settlement δ: per punch"
    assert figures.history_fig["force"].title.text == "Force P: per punch"
    assert {fig.yaxis[0].ticker.desired_num_ticks for fig in short} == {3}
    assert figures.q_fig.yaxis[0].ticker.desired_num_ticks == 4     # tall: as before
    # the colour bars' ticks and titles larger too (a teacher's audit found them at 11 px)
    from bokeh.models import ColorBar

    bars = [bar for fig in figures.all_figures() for bar in fig.select({"type": ColorBar})]
    assert len(bars) >= 2  # the drawing's modulus, the q(x, t) map's pressure
    assert {(b.major_label_text_font_size, b.title_text_font_size) for b in bars} == {
        ("14px", "14px")}
    figures.set_presentation(False)
    assert figures.history_fig["settlement"].title.text == \
        "Settlement δ [mm]: computed, per punch"
    assert {fig.yaxis[0].ticker.desired_num_ticks for fig in short} == {6}
    assert {(b.major_label_text_font_size, b.title_text_font_size) for b in bars} == {
        ("11px", "13px")}


def test_a_changed_scene_keeps_its_modified_in_the_drawing_s_title(explorer_app) -> None:
    """The drawing's title is cut to fit 1024 px, and the cut took " (modified)":
    "Scene: Eccentric footing: from full contact to…" did not say it had changed."""
    from core.presets import read_preset

    app = explorer_app(scene=read_preset("eccentric_footing_liftoff"), solved=True)
    app.state.loading.histories["force"].value *= 1.01
    assert app.controller.wait(120) and app.controller.error == "", app.controller.error
    title = app.figures.scene_fig.title.text
    assert title == "Scene: Eccentric footing: from full\ncontact to lift-off (modified)", title


def test_a_long_scene_name_takes_two_lines_that_fit_in_presentation_mode() -> None:
    """In presentation mode (18 px) the drawing's title beside the inset at 1024 px was
    cut at "Scene: What a coating…, step 2 of 3 (modifi" (a teacher's audit); a long
    name now takes two lines, a lesson's step and "(modified)" on the second, each line
    within what fits, split where the lines balance."""
    from explorer.model import presets
    from explorer.plots.figures import PRESENTING_TITLE_CHARS, TITLE_CHARS, scene_title

    assert scene_title("What a coating does to the edge pressure, step 2 of 3 (modified)",
                       presenting=True) == ("Scene: What a coating does to the…\n"
                                            "step 2 of 3 (modified)")
    assert scene_title("Footing on young concrete, 50 years", presenting=True) == (
        "Scene: Footing on young\nconcrete, 50 years")
    assert scene_title("Uniform coating, flat punch") == "Scene: Uniform coating, flat punch"
    assert scene_title("x" * 80) == "Scene: " + "x" * (TITLE_CHARS - 1) + "…"
    for presenting, limit in ((False, len("Scene: ") + TITLE_CHARS),
                              (True, PRESENTING_TITLE_CHARS)):
        for scene in presets().values():
            for name in (scene["name"], scene["name"] + " (modified)"):
                lines = scene_title(name, presenting).split("\n")
                assert len(lines) <= 2 and max(map(len, lines)) <= limit, lines


def test_a_lessons_step_keeps_its_number_in_the_drawing_s_title() -> None:
    """A lesson step's name was cut before its number ("Force, eccentricity and tilt,
    step 4 of…", at 1024 and 1366 px alike), and words mid-way ("ti…")."""
    from explorer.plots.figures import short

    assert short("Force, eccentricity and tilt, step 4 of 4") == (
        "Force, eccentricity and…, step 4 of 4")
    assert short("What a coating does to the edge pressure, step 3 of 3") == (
        "What a coating does to the…, step 3 of 3")
    assert short("Uniform coating, flat punch") == "Uniform coating, flat punch"
