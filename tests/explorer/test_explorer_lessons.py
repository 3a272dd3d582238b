"""The lessons: their steps load, and every number in their notes is the solver's."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest

import core
from core.presets import read_preset
from explorer.model import validated_scene
from explorer.model.lessons import LESSONS, lessons, step_scene
from explorer.views.style import is_shown

LESSON = {lesson.key: lesson for lesson in LESSONS}


@cache
def _solved(key: str, index: int):
    return core.solve(core.scene_from_dict(step_scene(LESSON[key], index)))


def _mm(solution, k: int) -> float:
    return float(np.asarray(solution.settlement)[k]) * 1e3


def _mrad(solution, k: int) -> float:
    return float(np.asarray(solution.tilt)[k]) * 1e3


def _at(solution, days: float) -> int:
    return int(np.argmin(np.abs(np.asarray(solution.times) - days)))


def _rounds_to(value: float, written: str) -> bool:
    """Whether ``value`` rounds to the number as the note writes it."""
    decimals = len(written.split(".")[1]) if "." in written else 0
    return f"{value:.{decimals}f}" == written


def test_every_lesson_step_is_a_valid_scene_with_its_note() -> None:
    assert len(lessons()) >= 2
    for lesson in LESSONS:
        for k, step in enumerate(lesson.steps):
            scene = step_scene(lesson, k)
            validated_scene(scene)  # raises on a bad step (one punch or several)
            assert scene["description"] == step.note
            for number in step.changes:
                assert "." in number  # a dotted field of the scene
    with pytest.raises(ValueError, match="step 9 does not exist"):
        step_scene(LESSONS[0], 8)


def test_the_load_and_tilt_lesson_says_what_the_solver_finds() -> None:
    steps = [_solved("load_and_tilt", k) for k in range(4)]
    end = -1
    s0 = steps[0]
    # step 1: 0.024 mm at loading, 0.041 mm after a year, no tilt
    assert _rounds_to(_mm(s0, 0), "0.024") and _rounds_to(_mm(s0, end), "0.041")
    assert abs(_mrad(s0, end)) < 1e-9
    x = np.linspace(-1.0, 1.0, 201)
    q = np.asarray(s0.pressure(x)).reshape(len(x), -1)[:, end]
    assert np.argmin(q) == 100 and q[0] == pytest.approx(q.max())  # centre low, edges high
    # step 2: twice the force, twice the settlement and pressure (linear to round-off:
    # measured relative difference 3e-16)
    s1 = steps[1]
    assert _mm(s1, end) == pytest.approx(2 * _mm(s0, end), rel=1e-9)
    q1 = np.asarray(s1.pressure(x)).reshape(len(x), -1)[:, end]
    assert np.allclose(q1, 2 * q, rtol=1e-9)
    assert _rounds_to(_mm(s1, 0), "0.049") and _rounds_to(_mm(s1, end), "0.082")
    # step 3: e = 0.2 m tilts it, the centre settles as before
    s2 = steps[2]
    assert _rounds_to(_mrad(s2, 0), "0.015") and _rounds_to(_mrad(s2, end), "0.023")
    assert _rounds_to(_mm(s2, end), "0.082")
    q2 = np.asarray(s2.pressure(x)).reshape(len(x), -1)[:, end]
    assert q2[-1] > q1[-1] and q2[0] < q1[0]
    # step 4: e = 0.3 m, 1.5 times the tilt, the left edge lower still
    s3 = steps[3]
    assert _mrad(s3, end) == pytest.approx(1.5 * _mrad(s2, end), rel=1e-6)
    assert _rounds_to(_mrad(s3, end), "0.035")
    q3 = np.asarray(s3.pressure(x)).reshape(len(x), -1)[:, end]
    assert q3[0] < q2[0]
    # "at about e = 0.4 m its pressure reaches zero at loading": at e = 0.4 m the least
    # pressure at loading is ~1 % of the mean (measured 5.6 of 500 kPa)
    scene = step_scene(LESSON["load_and_tilt"], 3)
    scene["loading"]["moment"] = 4.0e5
    near = core.solve(core.scene_from_dict(scene))
    q_load = np.asarray(near.pressure(np.linspace(-1, 1, 401))).reshape(401, -1)[:, 0]
    assert 0 < q_load.min() < 0.02 * 1.0e6 / 2.0


def test_the_creep_lesson_says_what_the_solver_finds() -> None:
    s0, s1, s2 = (_solved("creep", k) for k in range(3))
    assert _rounds_to(_mm(s0, 0), "0.059") and _rounds_to(_mm(s0, -1), "0.087")
    assert f"{_mm(s0, -1) / _mm(s0, 0):.2f}" == "1.47"
    k90, k250 = _at(s0, 90.0), _at(s0, 250.0)
    assert f"{_mm(s0, k90) / _mm(s0, 0):.2f}" == "1.44"
    # "no more after about 250 days": less than 0.1 % left to grow (measured 0.02 %)
    assert _mm(s0, -1) / _mm(s0, k250) - 1 < 1e-3
    assert _rounds_to(_mm(s1, 0), "0.049")
    assert f"{100 * (_mm(s1, -1) / _mm(s1, 0) - 1):.0f}" == "22"
    assert f"{100 * (_mm(s0, -1) / _mm(s0, 0) - 1):.0f}" == "47"
    settlement = np.asarray(s2.settlement) * 1e3
    assert _rounds_to(settlement[0], "0.049") and np.ptp(settlement) < 1e-12


def test_a_lesson_goes_step_by_step_and_pins_each_step(explorer_app) -> None:

    app = explorer_app()
    view = app.lessons_tab
    view.lesson_select.value = "load_and_tilt"
    assert app.controller.wait(60)
    assert "Step 1 of 4" in view.lesson_note.object and view.previous_button.disabled
    view.next_button.clicks += 1
    assert app.controller.wait(60) and app.controller.error == ""
    # the one pin is named by what differs from the step on screen (it read
    # "1: Force, eccentricity and tilt…", the lesson's title cut to fit)
    assert [pin.label for pin in app.pins.board] == ["P = 500 kN/m"]
    assert "P = 500 kN/m" in app.results.readout.object
    assert "✕ P = 500 kN/m" in [b.label for b in app.pins.pin_list.objects]
    for _ in range(2):
        view.next_button.clicks += 1
        assert app.controller.wait(60) and app.controller.error == ""
    assert view.next_button.disabled and "Step 4 of 4" in view.lesson_note.object
    assert [pin.label for pin in app.pins.board] == ["P = 500 kN/m, e = 0 m",
                                                      "P = 1000 kN/m, e = 0 m",
                                                      "P = 1000 kN/m, e = 0.2 m"]
    assert float(app.results.readout.object.split("readout-moment'>")[1].split("<")[0]) == 300
    view.previous_button.clicks += 1
    assert app.controller.wait(60)
    assert "Step 3 of 4" in view.lesson_note.object
    # the creep lesson switches the histories to a log time axis
    view.lesson_select.value = "creep"
    assert app.controller.wait(60)
    assert app.results.log_time.value and len(app.pins.board) == 0


def test_the_coating_edges_lesson_says_what_the_solver_finds() -> None:
    bare, thin, thick = (_solved("coating_edges", k) for k in range(3))
    assert bare.scene.coating == () and len(thin.scene.coating) == 1
    x = np.array([0.0, 0.9, 0.99])  # the middle, 10 cm and 1 cm from the edge (a = 1 m)

    def mpa(solution) -> np.ndarray:
        return np.asarray(solution.pressure(x))[:, 0] / 1e6

    q0, q1 = mpa(bare), mpa(thin)
    # step 1: 0.20 MPa in the middle, 0.31 and 0.86 MPa near the edge, 0.0068 mm
    assert [f"{v:.2f}" for v in q0] == ["0.20", "0.31", "0.86"]
    assert _rounds_to(_mm(bare, 0), "0.0068")
    # step 2: 1 cm from the edge 0.34 MPa, 0.23 MPa in the middle, 0.0127 mm
    assert f"{q1[2]:.2f}" == "0.34" and f"{q1[0]:.2f}" == "0.23"
    assert _rounds_to(_mm(thin, 0), "0.0127")
    # step 3: 0.24 to 0.25 MPa up to 25 mm from the edges (as drawn: the plotting grid,
    # which holds q within half the coating's thickness of a corner; the note said
    # "across the whole punch" beside the check's "unbounded at the corner"), 0.064 mm
    grid = np.asarray(thick.pressure_on_grid)[:, 0] / 1e6
    assert f"{grid.min():.2f}" == "0.24" and f"{grid.max():.2f}" == "0.25"
    corners = thick.info["corner_pressure"]
    assert corners["held_within_m"] == pytest.approx(0.025) and corners["corners_m"] == [
        -1.0, 1.0]
    assert _rounds_to(_mm(thick, 0), "0.064")


def test_a_one_time_scene_keeps_its_time_where_the_player_cannot_go(explorer_app) -> None:
    """An elastic scene has one output time, but the player's range is 0 to 1 (a range
    of one point is no slider): moved to its end, the time index went to 1, and pinning
    or the coating lesson's next step raised IndexError on the server."""
    app = explorer_app()
    view = app.lessons_tab
    view.lesson_select.value = "coating_edges"
    assert app.controller.wait(60) and app.controller.error == ""
    player = app.results.player
    assert player.disabled and player.end == 1
    assert not is_shown(app.results.player_box)  # a greyed player read as broken
    player.value = 1    # what a click at its end sends, disabled or not
    assert app.screen.time_index == 0
    view.next_button.clicks += 1    # pins step 1, solves step 2
    assert app.controller.wait(60) and app.controller.error == ""
    assert "Step 2 of 3" in view.lesson_note.object and len(app.pins.board) == 1
    app.pins.pin()
    assert len(app.pins.board) == 2


def test_a_lessons_steps_keep_one_unit_and_the_scene_tab_shows_the_step(explorer_app) -> None:
    """The coating lesson's bare slab reads q in MPa (its edge runs past 1 MPa), the
    coated steps in kPa: a class read the notes' MPa on an axis in kPa. Its steps now keep
    the first step's unit, as a dragged slider does. The Scene tab kept the preset's name
    and description ("... 500 kN per metre") beside a step's plots; it shows the step's."""
    app = explorer_app()
    view = app.lessons_tab
    view.lesson_select.value = "coating_edges"
    assert app.controller.wait(60) and app.controller.error == ""
    assert app.scales.pressure_unit(app.controller.view)[0] == "MPa"
    for step in (2, 3):
        view.next_button.clicks += 1
        assert app.controller.wait(60) and app.controller.error == ""
        assert app.scales.pressure_unit(app.controller.view)[0] == "MPa", step
        assert app.figures.q_fig.yaxis[0].axis_label.endswith("[MPa]")
        text = app.scene_tab.preset_description.object
        assert text.startswith(f"**What a coating does to the edge pressure, step {step} of "
                               "3**: "), text
        assert app.scene_tab.preset.value == ""
    # a lesson started again, or a preset, chooses its unit afresh
    view.lesson_select.value = "load_and_tilt"
    assert app.controller.wait(60)
    assert app.scales.pressure_unit(app.controller.view)[0] == "kPa"
    assert "Force, eccentricity and tilt, step 1 of 4" in app.scene_tab.preset_description.object


def test_an_answer_at_one_output_time_draws_no_history(explorer_app) -> None:
    """The bare slab is elastic: one output time, and the page drew a q(x, t) map of one
    row and four histories of one dot each on axes of 0.96 to 1.04 days. They are taken
    off with a line saying why; a pinned answer over time brings them back. Taken off by
    their style, never by ``visible``: Bokeh lays the whole page out again at each change
    of ``visible``, and the five toggles made a switch between an elastic preset and one
    over time 150-200 ms slower in Chromium."""
    app = explorer_app("bare_layer", solved=True)
    results = app.results
    toggled = (results.history_grid, app.figures.image_fig, results.once_note,
               results.player_box, results.log_time.__panel__())

    def shown() -> list[bool]:
        assert all(pane.visible for pane in toggled)
        return [is_shown(pane) for pane in toggled]

    assert shown() == [False, False, True, False, False]
    assert "One output time (1 day)" in results.once_note.object
    app.load_scene(read_preset("uniform_flat"))
    assert app.controller.wait(60) and app.controller.error == ""
    assert shown() == [True, True, False, True, True]
    app.pins.pin()
    app.load_scene(read_preset("bare_layer"))
    assert app.controller.wait(60) and app.controller.error == ""
    assert shown()[:2] == [True, True]  # the pin has 40 output times
    app.pins.unpin()
    assert shown() == [False, False, True, False, False]
    assert "answers at once (elastic)" in results.once_note.object


def test_one_output_time_on_a_creeping_base_says_its_values_include_creep(explorer_app):
    # the note read "the base answers at once (elastic) and holds that answer at every
    # later time" beside a settlement at 1000 days 1.5 times the one at loading
    app = explorer_app("eccentric_creep", solved=True)
    app.state.time_count = 1
    assert app.controller.wait(60) and app.controller.error == ""
    note = app.results.once_note
    assert is_shown(note) and "creep since loading included" in note.object
    assert "elastic" not in note.object


def test_an_undo_in_a_lesson_shows_the_step_it_brings_back(explorer_app) -> None:
    """The Scene tab read the last step loaded after an undo had brought the one before
    back (a review); and a preset loaded in the middle of a lesson starts its own unit."""
    app = explorer_app()
    view = app.lessons_tab
    view.lesson_select.value = "coating_edges"
    assert app.controller.wait(60)
    view.next_button.clicks += 1
    assert app.controller.wait(60)
    assert "step 2 of 3**" in app.scene_tab.preset_description.object
    app.scene_tab.undo_button.clicks += 1
    assert app.controller.wait(60)
    assert "step 1 of 3**" in app.scene_tab.preset_description.object
    app.load_scene(read_preset("eccentric_creep"))
    assert app.controller.wait(60)
    assert app.scales.pressure_unit(app.controller.view)[0] == "MPa"
    view.next_button.clicks += 1   # step 2 again, after the preset: its own unit
    assert app.controller.wait(60)
    assert app.scales.pressure_unit(app.controller.view)[0] == "kPa"


def test_a_files_name_and_description_are_shown_as_written(explorer_app) -> None:
    """The Scene tab shows a scene of its own by its name and description, HTML and the
    Markdown that formats inline escaped ("2*3*4" read "2<em>3</em>4")."""
    from markdown_it import MarkdownIt

    app = explorer_app()
    scene = read_preset("uniform_flat")
    scene["name"], scene["description"] = "Pad 2*3*4", "<b>bold</b> a_b `c` $5"
    assert app._load_file(scene)
    rendered = MarkdownIt().render(app.scene_tab.preset_description.object)
    assert "<strong>Pad 2*3*4</strong>: &lt;b&gt;bold&lt;/b&gt; a_b `c` $5" in rendered
    # quotes as written: their entity's "#", escaped as Markdown, read "coating&#x27;s"
    # (the coating lesson's last step)
    scene["name"], scene["description"] = "The pad's test", 'mostly the coating\'s, "so"'
    assert app._load_file(scene)
    rendered = MarkdownIt().render(app.scene_tab.preset_description.object)
    assert "<strong>The pad's test</strong>: mostly the coating's, &quot;so&quot;" in rendered, \
        rendered


def test_a_step_changed_on_the_page_says_what_the_note_and_next_speak_of(explorer_app) -> None:
    """A teacher set the force to 700 kN/m at the step of 1000: the note's numbers no longer
    matched the page, next pinned the 700 and the next step went back to 1000, unsaid. The
    tab says it while the step is changed, and not once a step is shown again."""
    from explorer.views.lessons import CHANGED_NOTE

    app = explorer_app()
    view = app.lessons_tab
    view.lesson_select.value = "load_and_tilt"
    assert app.controller.wait(60)
    view.next_button.clicks += 1
    assert app.controller.wait(60) and not view.changed_note.visible
    app.state.loading.histories["force"].value = 700.0
    assert app.controller.wait(60)
    assert view.changed_note.visible and view.changed_note.object == CHANGED_NOTE
    view.next_button.clicks += 1          # pins the 700, shows step 3 as given
    assert app.controller.wait(60) and not view.changed_note.visible
    assert "P = 700 kN/m" in [pin.label for pin in app.pins.board][-1]
