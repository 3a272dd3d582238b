"""A given load's jump is drawn as a break in the histories, not as a slope.

A teacher's audit: the new footing's force steps from 100 to 600 kN/m at one year, and the
old footing's settlement, drawn straight between the output times either side (two weeks
apart on the preset's log times), read as a slope. The lines now break there, and a dashed
mark at the jump says why.
"""

from __future__ import annotations

import numpy as np
import pytest

from core.presets import read_preset
from core.scene import scene_from_dict
from explorer.model import load_jumps
from explorer.plots.bokeh_data import broken_at

TIMES = np.array([0.0, 100.0, 200.0, 365.25, 400.0])


def _loading(force: dict, moment: object = 0.0) -> dict:
    scene = read_preset("uniform_flat")
    scene["loading"] = {"force": force, "moment": moment}
    scene["times"] = list(TIMES)
    return scene_from_dict(scene).loading


@pytest.mark.parametrize(("force", "jumps"), [
    ({"kind": "step", "values": [1e5, 6e5], "breaks": [150.0]}, (150.0,)),
    # at an output time: the value there is the new one, the one before the old
    ({"kind": "step", "values": [1e5, 6e5], "breaks": [365.25]}, (365.25,)),
    # a ramp's end is a kink, not a jump; a short one too (a 14-day ramp from 0 to 600
    # kN/m over 50 years was drawn as a jump, a review)
    ({"kind": "ramp", "start": 1e5, "end": 6e5, "duration": 150.0}, ()),
    ({"kind": "ramp", "start": 0.0, "end": 6e5, "duration": 0.05}, ()),
    ({"kind": "table", "points": [[0, 1e5], [150, 6e5], [400, 6e5]],
      "interpolation": "linear"}, ()),
    ({"kind": "table", "points": [[0, 1e5], [150, 6e5], [400, 6e5]],
      "interpolation": "step"}, (150.0,)),
    # past the last output time: nothing drawn jumps
    ({"kind": "step", "values": [1e5, 6e5], "breaks": [450.0]}, ()),
    (5e5, ()),
])
def test_the_jumps_of_a_given_load_are_found_and_its_kinks_are_not(force, jumps) -> None:
    assert load_jumps(_loading(force), TIMES) == pytest.approx(jumps)


def test_a_jump_of_any_given_load_counts_and_one_time_has_none() -> None:
    loading = _loading(5e5, {"kind": "step", "values": [0.0, 1e5], "breaks": [50.0]})
    assert load_jumps(loading, TIMES) == (50.0,)
    assert load_jumps(loading, TIMES[-1:]) == ()


def test_a_history_breaks_between_the_output_times_either_side_of_a_jump() -> None:
    values = np.arange(TIMES.size, dtype=float)
    t, v = broken_at(TIMES, values, (150.0, 365.25))
    # a NaN between 100 and 200, and between 200 and 365.25 (the jump at an output time)
    assert np.isnan(v).tolist() == [False, False, True, False, True, False, False]
    np.testing.assert_array_equal(t[~np.isnan(t)], TIMES.astype(np.float32))
    np.testing.assert_array_equal(v[~np.isnan(v)], values)
    t, v = broken_at(TIMES, values, ())
    assert t.dtype == np.float32 and not np.isnan(v).any()


def test_the_new_footings_step_breaks_every_punchs_history_on_the_page(explorer_app) -> None:
    app = explorer_app("new_footing_beside_old", solved=True)
    view = app.controller.view
    assert view.jumps == (365.25,)
    k = int(np.searchsorted(view.times, 365.25))  # the first output time past the step
    assert view.times[k - 1] < 365.25 < view.times[k]
    figures = app.figures
    for q in ("settlement", "tilt"):
        lines = figures.punch_history_src[q].data
        for xs, ys in zip(lines["xs"], lines["ys"], strict=True):
            assert len(xs) == len(view.times) + 1 and np.isnan(ys[k])
        assert list(figures.jump_src[q].data["t"]) == [365.25]
    # a pinned answer of one punch keeps its own (none here): a scene without jumps
    app.load_scene(read_preset("uniform_flat"))
    assert app.controller.wait(60) and app.controller.error == ""
    assert not len(figures.jump_src["settlement"].data["t"])
    assert not np.isnan(np.asarray(figures.history_src["settlement"].data["v"])).any()


def test_the_values_at_loading_are_marked_at_the_edge_of_a_log_time_axis(explorer_app) -> None:
    """A log time axis has no t = 0: the settlement "at once" a lesson speaks of (0.026 mm
    for the old footing) was not on the plot. Open markers at the left edge of the log
    range carry the values at t = 0 of every line, one per punch; the linear axis draws
    them on the lines, and the markers go."""
    app = explorer_app("new_footing_beside_old", solved=True)
    view = app.controller.view
    assert view.times[0] == 0.0
    results, figures = app.results, app.figures
    marks = dict(zip(("settlement", "tilt", "force", "moment", "contact width"),
                     results.time_axis.at_loading, strict=True))
    assert all(not len(m.data["y"]) for m in marks.values())  # linear: on the lines
    results.log_time.value = True
    start = results.time_axis.log_range.start
    settlement = marks["settlement"].data
    assert settlement["y"] == pytest.approx([p.display("settlement")[0] for p in view.punches])
    assert settlement["color"] == list(figures.punch_history_src["settlement"].data["color"])
    assert all(start < x < view.times[1] for x in settlement["x"])
    # one punch: the main line's value, in its colour; and back to linear
    app.load_scene(read_preset("eccentric_creep"))
    assert app.controller.wait(60) and app.controller.error == ""
    one = app.controller.view
    assert marks["settlement"].data["y"] == pytest.approx([one.display("settlement")[0]])
    assert marks["force"].data["color"] == [figures.history_line["force"].glyph.line_color]
    results.log_time.value = False
    assert not len(marks["settlement"].data["y"])


def test_the_contact_width_follows_a_log_time_axis(explorer_app) -> None:
    """"log time axis" turned the four histories to log time and left the contact width's
    linear, 0 to 1000 days, beside them (the lift-off preset, a teacher's audit); its
    value at loading is marked at the log axis' edge as theirs are."""
    from bokeh.models import LinearScale, LogScale

    app = explorer_app("eccentric_footing_liftoff", solved=True)
    view = app.controller.view
    results, figures = app.results, app.figures
    assert view.times[0] == 0.0 and isinstance(figures.contact_fig.x_scale, LinearScale)
    results.log_time.value = True
    assert isinstance(figures.contact_fig.x_scale, LogScale)
    assert figures.contact_fig.x_range is results.time_axis.log_range
    assert figures.contact_fig.xaxis[0].axis_label == \
        figures.history_fig["settlement"].xaxis[0].axis_label
    width_marks = results.time_axis.at_loading[-1].data
    widths = figures.contact.width_src.data
    assert width_marks["y"] == pytest.approx([widths["width"][0], widths["lifted"][0]])
    results.log_time.value = False
    assert isinstance(figures.contact_fig.x_scale, LinearScale)
    assert not len(results.time_axis.at_loading[-1].data["y"])
