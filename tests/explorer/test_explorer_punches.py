"""Several punches in the explorer: the state of a ``punches`` scene, its result as drawn,
the page showing it, and the lesson built on the preset of a new footing beside an old one.

The numbers of the lesson's notes are the solver's (rounded as written), as for the other
lessons (tests/explorer/test_explorer_lessons.py): a test fails if they drift.
"""

from __future__ import annotations

import asyncio
import copy
import json
import pickle
from functools import cache

import numpy as np
import param
import pytest

import core
from core.presets import read_preset
from explorer.model import SCREEN_PUNCHES, ExplorerState, prepare_view, presets
from explorer.model.lessons import LESSONS, step_scene

KEY = "new_footing_beside_old"
LESSON = {lesson.key: lesson for lesson in LESSONS}["neighbour_footing"]
#: The new footing's load steps up one year after loading [day].
STEP_TIME = 365.25


@cache
def _solved(index: int):
    return core.solve(step_scene(LESSON, index))


@cache
def _preset_view():
    scene = presets()[KEY]
    return prepare_view(core.solve(scene), scene)


def _rounds_to(value: float, written: str) -> bool:
    decimals = len(written.split(".")[1]) if "." in written else 0
    return f"{value:.{decimals}f}" == written


# ------------------------------------------------------------------------------ state


def test_the_preset_goes_into_the_state_and_back_as_several_punches() -> None:
    state = ExplorerState()
    state.load_scene(presets()[KEY])
    assert state.n_punches == 2 and [e.center for e in state.punches] == [0.0, 3.0]
    scene = state.to_scene()
    assert "punch" not in scene and "loading" not in scene
    assert core.load_scene(f"preset:{KEY}").to_dict() == \
        core.scene.punches_from_dict(scene).to_dict()
    new = state.punches[1].loading.histories["force"]
    assert new.kind == "step" and (new.value, new.second, new.time) == (100.0, 600.0, STEP_TIME)
    # back to one punch: the single form again
    state.load_scene(presets()["uniform_flat"])
    assert state.n_punches == 0 and "punch" in state.to_scene()


def test_adding_and_removing_punches_is_one_change_each() -> None:
    state = ExplorerState()
    state.load_scene(presets()[KEY])
    start = state.revision
    assert state.add_punch() == 2
    assert state.revision == start + 1
    # a copy of the rightmost, one half-width clear of it
    assert [e.center for e in state.punches] == [0.0, 3.0, 6.0]
    assert state.scene_name.endswith("(modified)")
    state.add_punch()
    with pytest.raises(ValueError, match=f"1 to {SCREEN_PUNCHES} punches"):
        state.add_punch()
    state.remove_punch(0)
    assert state.revision == start + 3
    assert [e.center for e in state.punches] == [3.0, 6.0, 9.0]
    loads = state.to_scene()["punches"][0]["loading"]
    assert loads["force"]["kind"] == "step"  # the old second punch, now the first
    for _ in range(2):
        state.remove_punch(0)
    with pytest.raises(ValueError, match="one at least stays"):
        state.remove_punch(0)
    core.scene.punches_from_dict(state.to_scene())  # one punch in the punches form


def test_a_file_with_more_punches_than_the_screen_edits_is_refused_by_name() -> None:
    scene = presets()[KEY]
    scene["punches"] = [dict(scene["punches"][0], center=3.0 * k)
                        for k in range(SCREEN_PUNCHES + 1)]
    state = ExplorerState()
    with pytest.raises(ValueError, match="punches: the page edits 1 to 4 punches"):
        state.load_scene(scene)
    assert state.n_punches == 0  # left as it was


# ---------------------------------------------------------------------------- results


def test_the_result_of_several_punches_pickles_and_holds_each_punch() -> None:
    view = _preset_view()
    again = pickle.loads(pickle.dumps(view))  # made in a worker process
    assert again.several and len(again.punches) == 2
    solution = core.solve(presets()[KEY])
    for mine, theirs in zip(view.punches, solution.punches, strict=True):
        assert np.array_equal(mine.values["settlement"], theirs.settlement)
        assert np.array_equal(mine.values["tilt"], theirs.tilt)
        assert mine.x[0] == pytest.approx(theirs.center - 1.0)  # global x
    # q over the whole surface: each punch's grid, the free surface between left blank
    assert np.isnan(view.pressure).any() and view.span == (-1.0, 4.0)
    assert np.nanmin(view.pressure) > 0  # full contact
    # the contact: both zones, full
    assert view.contact_set[0] == [(-1.0, 1.0), (2.0, 4.0)]
    from explorer.model import contact_text, contact_widths, lifts_off
    assert not lifts_off(view) and np.all(contact_widths(view) == 4.0)
    assert contact_text(view, 0) == ("punch 1: full contact over 2 m; punch 2: full "
                                     "contact over 2 m")


def test_pins_refuse_results_of_several_punches() -> None:
    from explorer.model import PinBoard

    assert not PinBoard().add(_preset_view())


# ---------------------------------------------------------------------------- the page


def test_the_page_shows_each_punch_and_turns_off_what_is_for_one(explorer_app) -> None:
    app = explorer_app(KEY, solved=True)
    view = app.controller.view
    assert view.several
    figures = app.figures
    lines = figures.punch_history_src["settlement"]
    assert lines.data["label"] == ["punch 1", "punch 2"]
    # (200 output times, and a break where the new footing's load steps: test_explorer_load_jumps)
    assert [len(v) for v in lines.data["ys"]] == [201, 201]
    legend = figures.history_fig["settlement"].legend[0]
    assert legend.visible and [i.visible for i in legend.items] == [True, True, False, False]
    # the time axis spans the punches' lines (their times are in "xs")
    span = float(view.times[-1] - view.times[0])
    assert (figures.time_range.start, figures.time_range.end) == pytest.approx(
        (float(view.times[0]) - 0.05 * span, float(view.times[-1]) + 0.05 * span))
    assert not figures.history_line["settlement"].visible
    assert figures.drawing.punches_src.data["name"] == ["punch 1", "punch 2"]
    # named as the files name it too (an engineer's audit: punches[1] read as punch 1)
    assert "punch 2 (punches[1], x = 3 m)" in app.results.readout.object
    assert "several-punches-note" in app.results.readout.object
    # off for several punches, with a note in their place
    assert app.pins.pin_button.disabled and app.results.classical.disabled
    assert app.scene_tab.loading.note.visible and not app.scene_tab.loading.body.visible
    assert app.punch_tab.punches.panel.visible and not app.punch_tab.single.visible
    # the JSON of the result is the core's, every punch in it
    saved = json.loads(app.controller.download(view, "to_json"))
    assert [p["center"] for p in saved["punches"]] == [0.0, 3.0]
    # so are the CSV files and the reports: a column, a zone, a section per punch
    files = app.files_tab
    text = asyncio.run(files._csv_file()).getvalue()
    # the lines of the command line's CSV first: version, scene, settings, flags
    assert "\n# flags: " in text and "\n# scene_json: " in text
    histories = [line for line in text.splitlines() if not line.startswith("#")]
    assert histories[0].startswith("time_day,punches[0].settlement_m,")
    assert "punches[1].settlement_m" in histories[0] and len(histories) == 201
    pressure = [line for line in asyncio.run(files._pressure_file()).getvalue().splitlines()
                if not line.startswith("#")]
    assert pressure[0] == "time_day,x_m,pressure_Pa"
    xs = {float(line.split(",")[1]) for line in pressure[1:2000]}
    assert min(xs) == -1.0 and max(xs) == 4.0  # both zones, in the global x
    report = asyncio.run(files._report_file()).getvalue()
    assert "punches[1]" in report and "<h2>Results" in report
    assert asyncio.run(files._pdf_report_file()).getvalue().startswith(b"%PDF")
    # a study varies a punch's centre (the spacing) and shows each punch's outputs
    study = app.study_tab
    assert "punches[1].center" in study.study_first.field.options.values()
    assert study.study_output.value == "punches[0].settlement"
    assert "punch 2: tilt [mrad]" in study.study_output.options
    # back to one punch: the single-punch page as it was
    assert app.load_scene(presets()["uniform_flat"])
    assert app.controller.wait(120) and app.controller.error == ""
    assert not app.controller.view.several
    assert lines.data["ys"] == [] and not legend.visible
    assert figures.history_line["settlement"].visible
    assert not app.pins.pin_button.disabled and not app.scene_tab.loading.note.visible
    assert not app.punch_tab.punches.panel.visible and app.punch_tab.single.visible
    assert app.study_tab.study_output.value == "settlement"


def test_the_punches_section_edits_the_chosen_punch(explorer_app) -> None:
    app = explorer_app(KEY, solved=True)
    section = app.punch_tab.punches
    assert section.select.options == ["1", "2"] and section.remove_button.disabled is False
    section.select.value = "2"
    assert section.center.value == 3.0

    def release(value: float) -> None:  # as the browser sets it at the end of a drag
        with param.edit_constant(section.center):
            section.center.value_throttled = value

    assert section.history_editors[0].value.value == 100.0  # force before the step
    before = app.controller.view.punches[0].values["tilt"][-1]
    release(4.0)  # one solve
    assert app.controller.wait(120) and app.controller.error == ""
    assert app.controller.view.punches[1].center == 4.0
    after = app.controller.view.punches[0].values["tilt"][-1]
    assert 0 < after < before  # farther: the old footing tilts less toward it
    # overlapping punches: the core's message, naming both; the last good result stays
    shown = app.controller.view
    release(1.5)
    assert app.controller.wait(120)
    assert "punches[0] and punches[1] overlap or touch" in app.controller.error
    assert app.controller.view is shown and app.results.alert.visible
    release(3.0)
    assert app.controller.wait(120) and app.controller.error == ""
    section.add_button.clicks += 1
    assert app.controller.wait(120) and app.controller.error == ""
    assert len(app.controller.view.punches) == 3 and section.select.value == "3"


# ---------------------------------------------------------------------------- lesson


@pytest.mark.slow
def test_the_neighbour_footing_lesson_says_what_the_solver_finds() -> None:
    one, unloaded, farther = (_solved(k) for k in range(3))
    times = one.times
    after = int(np.searchsorted(times, STEP_TIME))  # the first output after the step
    before = after - 1

    def mm(solution, k: int, punch: int = 0) -> float:
        return float(solution.punches[punch].settlement[k]) * 1e3

    def mrad(solution, k: int, punch: int = 0) -> float:
        return float(solution.punches[punch].tilt[k]) * 1e3

    # step 1: 0.026 mm at once, 0.065 by one year, 0.067 just after the new load, 0.085
    # at 50 years; tilted toward the new footing 0.0012, 0.0031, 0.0058 mrad, the right
    # edge 12 µm lower (2a = 2 m); the new one tilts toward the old one
    assert times[-1] == pytest.approx(50 * 365.25)
    assert [_rounds_to(mm(one, k), w) for k, w in
            ((0, "0.026"), (before, "0.065"), (after, "0.067"), (-1, "0.085"))] == [True] * 4
    assert [_rounds_to(mrad(one, k), w) for k, w in
            ((before, "0.0012"), (after, "0.0031"), (-1, "0.0058"))] == [True] * 3
    assert f"{mrad(one, -1) * 2.0 * 1e3:.0f}" == "12"
    assert np.all(one.punches[1].tilt < 0)
    # step 2: never loaded, 0.080 mm and 0.0015 mrad; the load added 0.0022 mm at once
    # and 0.0050 mm (6 %) at 50 years, more than twice as much
    assert _rounds_to(mm(unloaded, -1), "0.080") and _rounds_to(mrad(unloaded, -1), "0.0015")
    at_once = mm(one, after) - mm(unloaded, after)
    at_50 = mm(one, -1) - mm(unloaded, -1)
    assert _rounds_to(at_once, "0.0022") and _rounds_to(at_50, "0.0050")
    assert f"{100 * at_50 / mm(unloaded, -1):.0f}" == "6" and at_50 > 2 * at_once
    # step 3: 3 m farther, 0.078 mm as alone (0.079 mm: the young-concrete preset is the
    # old footing alone), 15 times less tilt, 0.0004 mrad
    alone = core.solve(read_preset("young_concrete_50_years"))
    assert _rounds_to(float(alone.settlement[-1]) * 1e3, "0.079")
    assert _rounds_to(mm(farther, -1), "0.078") and _rounds_to(mrad(farther, -1), "0.0004")
    assert f"{mrad(one, -1) / mrad(farther, -1):.0f}" == "15"
    assert step_scene(LESSON, 2)["punches"][1]["center"] == 6.0


def test_the_lesson_goes_through_its_steps_on_the_page(explorer_app) -> None:
    app = explorer_app()
    view = app.lessons_tab
    view.lesson_select.value = "neighbour_footing"
    assert app.controller.wait(120) and app.controller.error == ""
    assert app.controller.view.several and app.results.log_time.value
    for _ in range(2):
        view.next_button.clicks += 1
        assert app.controller.wait(120) and app.controller.error == ""
    assert "Step 3 of 3" in view.lesson_note.object and len(app.pins.board) == 0
    assert app.controller.view.punches[1].center == 6.0
    assert copy.deepcopy(app.state.to_scene())["punches"][1]["center"] == 6.0


def test_the_punches_legends_sit_above_their_histories(explorer_app) -> None:
    """Inside at the top left, the punches' legend hid the old footing's step at one year
    (new_footing_beside_old), where every history starts."""
    from bokeh.models import Legend

    app = explorer_app()
    for fig in app.figures.history_fig.values():
        legends = [m for m in fig.above if isinstance(m, Legend)]
        assert len(legends) == 1 and legends[0].orientation == "horizontal"
        assert not [m for m in fig.center if isinstance(m, Legend)]
