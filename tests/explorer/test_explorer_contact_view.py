"""The contact zone on screen: the bar under the punch, the contact width over time, the
readout, and the inset of small features (state level, no browser)."""

from __future__ import annotations

import json
from functools import cache

import numpy as np
import pytest

from core.scene import days_text
from explorer.model import (
    ExplorerState,
    ResultView,
    contact_text,
    contact_widths,
    contact_zones,
    presets,
)
from explorer.plots import Figures
from explorer.solving import SolveController


@cache
def _solved(key: str) -> ResultView:
    state = ExplorerState()
    state.load_scene(json.loads(json.dumps(presets()[key])))
    controller = SolveController(state, executor=None, auto=False)
    controller.solve_now()
    assert controller.view is not None, controller.error
    return controller.view


def _drawn(key: str, index: int = -1) -> tuple[Figures, ResultView, int]:
    view = _solved(key)
    index = index % len(view.times)
    figures = Figures()
    figures.show(view, index, ())
    return figures, view, index


def test_the_bar_under_the_punch_is_the_contact_set_and_follows_the_time() -> None:
    figures, view, last = _drawn("eccentric_footing_liftoff")
    drawing = figures.contact
    (start, end), = view.contact_set[last]           # one zone, at the toe
    (xs,) = drawing.zone_src.data["xs"]
    assert (xs[0], xs[-1]) == (start, end)
    (lifted,) = drawing.lifted_src.data["xs"]
    assert (lifted[0], lifted[-1]) == (-1.0, start)  # the heel, drawn differently
    # the bar lies on the coating's top as drawn (exaggerated thickness)
    (ys,) = drawing.zone_src.data["ys"]
    x, top = drawing._surface
    assert np.allclose(ys, np.interp(xs, x, top))
    # under creep the zone moves: the time slider moves the bar with it
    figures.show_time(view, 0, ())
    (xs0,) = drawing.zone_src.data["xs"]
    assert xs0[0] == view.contact_set[0][0][0] != start
    assert "contact 1.306 m of 2 m at t = 0 days" == drawing.zone_label.text
    # written into the base just below its top, at the drawing's left: above the surface
    # it ran over the leftmost punch and its load's label at 1024 px (two footings)
    label = drawing.zone_label
    assert (label.y, label.text_baseline) == (0.0, "top") and label.y_offset < 0


def test_full_contact_draws_one_bar_over_the_whole_width() -> None:
    figures, view, last = _drawn("uniform_flat")
    data = figures.contact.zone_src.data
    assert [(xs[0], xs[-1]) for xs in data["xs"]] == [(-1.0, 1.0)]
    assert figures.contact.lifted_src.data["xs"] == []
    assert figures.contact.zone_label.text.startswith("full contact")
    # nothing lifts: the legend does not list the dashed part
    assert [item.visible for item in figures.contact.scene_legend.items
            if figures.contact.lifted_line in item.renderers] == [False]


def test_the_width_plot_gives_the_zone_lengths_and_the_lifted_length_in_metres() -> None:
    figures, view, _ = _drawn("eccentric_footing_liftoff")
    a = view.geometry.half_width
    expected = [sum(hi - lo for lo, hi in zones) for zones in view.contact_set]
    data = figures.contact.width_src.data
    # float32 on the page: 7 digits (relative 6e-8 of 2 m), far below a pixel
    assert np.allclose(data["width"], expected, rtol=1e-6)
    assert np.allclose(data["lifted"], 2 * a - np.asarray(expected), atol=1e-6)
    assert np.allclose(data["t"], view.times, rtol=1e-6)
    fig = figures.contact_fig
    assert fig.yaxis[0].axis_label == "length [m]"
    assert fig.xaxis[0].axis_label == "t [days after loading]"
    tooltips = dict(fig.tools[-1].tooltips)
    assert tooltips["contact width"].endswith(" m") and tooltips["t"].endswith(" days")
    assert fig.title.text == "Contact width [m]: lift-off"
    # under this creeping base the zone grows (the heel settles back) and then stays
    assert expected[-1] > expected[0]


def test_in_full_contact_the_width_plot_says_so() -> None:
    figures, view, _ = _drawn("uniform_flat")
    assert "full contact" in figures.contact_fig.title.text
    assert np.all(contact_widths(view) == 2 * view.geometry.half_width)


def test_the_readout_names_the_contact_zone() -> None:
    from explorer.views import readout_html

    view = _solved("eccentric_footing_liftoff")
    text = readout_html(view, 0, ())
    assert "contact 1.306 m of 2 m (65 %), lifted 0.694 m: x = -1 to -0.306 m" in text
    assert contact_zones(view, 0) == view.contact_set[0]
    assert "full contact" in contact_text(_solved("uniform_flat"), 0)


@pytest.mark.parametrize(("key", "feature_um"), [
    ("worn_coating", 20.0),      # a 20 µm wear bump in a 20 mm coating
    ("stepped_punch", 15.0),     # outer parts of the base raised 15 µm
    ("rounded_graded", 6.25),    # x^2 / 2R at the edge x = 0.5 m, 1/2R = 2.5e-5 / m
])
def test_small_features_show_in_the_inset_in_micrometres(key: str, feature_um: float) -> None:
    figures, view, _ = _drawn(key)
    inset = figures.inset_fig
    assert inset.visible
    data = figures.inset.src.data
    gap = np.asarray(data["punch"]) - np.asarray(data["surface"])
    # the 401-point drawing grid may miss the exact peak of a bump by 0.03 %
    assert gap.max() == pytest.approx(feature_um, rel=1e-3)
    assert gap.min() == pytest.approx(0.0, abs=1e-9)
    assert inset.yaxis[0].axis_label == "height [µm]"
    labels = [item.label["value"] for item in inset.legend[0].items
              if figures.inset.gap_area in item.renderers]
    assert labels == [f"initial gap (≤ {gap.max():.3g} µm)"]
    # short enough for the inset's 220 px (at 1024 px in presentation mode "gap before
    # loading (≤ 25 µm)" ran past the page's right edge)
    assert len(labels[0]) <= len("initial gap (≤ 25.5 µm)")


def test_no_inset_without_small_features() -> None:
    figures, _, _ = _drawn("uniform_flat")
    assert not figures.inset_fig.visible


def test_a_load_step_in_full_contact_resends_nothing_of_the_contact(explorer_app) -> None:

    app = explorer_app()
    sent = [0]
    contact = app.figures.contact
    for source in (contact.zone_src, contact.lifted_src, contact.width_src,
                   contact.width_point, app.figures.inset.src):
        source.on_change("data", lambda attr, old, new: sent.__setitem__(0, sent[0] + 1))
    force = app.state.loading.histories["force"]
    force.value = force.value * 1.1
    assert app.controller.wait(60) and app.controller.error == ""
    assert sent[0] == 0
    # a force step changes the histories: the width plot's point moves, its data stays
    assert app.figures.contact.width_point.data["t"] == [float(app.screen.shown().times[-1])]


def test_a_lift_off_is_badged_and_shaded_as_such_not_as_full_contact() -> None:
    from bokeh.core.properties import value

    from explorer.views import badges_html

    view = _solved("eccentric_footing_liftoff")
    badges = badges_html(view, "pressure")
    assert "lift-off" in badges and "full contact" not in badges
    assert "full contact" in badges_html(_solved("uniform_flat"), "pressure")
    figures, _, _ = _drawn("eccentric_footing_liftoff")
    labels = [item.label for item in figures.q_fig.legend[0].items
              if figures.neg_strip in item.renderers]
    assert labels == [value("lifted off (q = 0)")]
    labels = [item.label for item in figures.contact.scene_legend.items
              if figures.contact.lifted_line in item.renderers]
    assert labels == [value("lifted off (gap open)")]


def test_the_lift_off_badge_speaks_of_the_time_shown() -> None:
    """Just past the threshold (e = 0.41 m) the lift-off preset's heel lifts at loading
    and creep closes it within weeks: at a later time the badge read "part of the base
    carries no load (shaded)" beside a full contact, nothing shaded (a crowned default
    did the same). It now says when the base lifted, and that the time shown is in full
    contact."""
    from explorer.model import lifted_times
    from explorer.views import badges_html

    scene = json.loads(json.dumps(presets()["eccentric_footing_liftoff"]))
    scene["loading"]["moment"] = 0.41 * scene["loading"]["force"]
    state = ExplorerState()
    state.load_scene(scene)
    controller = SolveController(state, executor=None, auto=False)
    controller.solve_now()
    view = controller.view
    assert view is not None, controller.error
    lifted = lifted_times(view)
    assert lifted[0] and not lifted[-1], lifted
    at_loading = badges_html(view, "pressure", index=0)
    assert "part of the base carries no load (shaded)" in at_loading
    late = badges_html(view, "pressure", index=len(view.times) - 1)
    assert "carries no load" not in late, late
    last = float(np.asarray(view.times)[lifted][-1])
    assert (f"lift-off at t = 0 days to {days_text(last)}: full contact at the time "
            "shown") in late, late
    # lifted, in contact, lifted again: no span that takes in the time shown (a review)
    import dataclasses

    times = np.asarray(view.times)
    gap = int(np.argmax(~lifted))  # the first time in full contact
    sets = [list(zones) for zones in view.contact_set]
    sets[-1] = sets[0]  # the last time lifted as the first
    again = dataclasses.replace(view, contact_set=sets)
    relifted = lifted_times(again)
    assert relifted[0] and not relifted[gap] and relifted[-1]
    badge = badges_html(again, "pressure", index=gap)
    assert (f"lift-off at {int(relifted.sum())} of {times.size} output times, first 0 days, "
            f"last {days_text(float(times[-1]))}: full contact at the time shown") in badge, \
        badge


@pytest.mark.slow
def test_the_report_carries_the_contact_zone_and_its_history(explorer_app) -> None:
    """The downloaded report says the contact at the time on screen, as the readout does,
    and plots the contact width over time when the punch lifts off."""
    import asyncio

    app = explorer_app("eccentric_footing_liftoff", solved=True)
    app.screen.time_index = 0  # the time slider at its start
    text = asyncio.run(app.files_tab._report_file()).getvalue()
    said = contact_text(app.screen.shown(), 0)
    assert said.startswith("contact 1.306 m of 2 m (65 %), lifted 0.694 m")
    assert f"<td>contact at t = 0 days</td><td>{said}</td>" in text  # the readout's words
    assert "<td>lift-off</td><td>at 20 of 20 output times" in text
    assert "contact width and lifted length (2a = 2 m)" in text  # the plot's title
    app.screen.time_index = 11  # 46.42 d of the preset's log-spaced times
    text = asyncio.run(app.files_tab._report_file()).getvalue()
    said = contact_text(app.screen.shown(), 11)
    assert said.startswith("contact 1.339 m of 2 m (67 %)")  # the zone grows with creep
    assert f"<td>contact at t = 46.42 days</td><td>{said}</td>" in text
    flat = explorer_app("uniform_flat", solved=True)
    text = asyncio.run(flat.files_tab._report_file()).getvalue()
    assert "full contact: the whole width 2a = 2 m touches" in text
    assert "contact width and lifted length" not in text and "<td>lift-off</td>" not in text


def test_the_full_contact_model_marks_its_pull_zone_not_a_gap() -> None:
    from bokeh.core.properties import value

    scene = json.loads(json.dumps(presets()["eccentric_footing_liftoff"]))
    scene["solver"]["contact"] = "full"
    state = ExplorerState()
    state.load_scene(scene)
    controller = SolveController(state, executor=None, auto=False)
    controller.solve_now()
    view = controller.view
    assert "contact_lost" in view.flags
    figures = Figures()
    figures.show(view, 0, ())
    drawing = figures.contact
    (lifted,) = drawing.lifted_src.data["xs"]
    (lo, hi), = view.negative_intervals(0)   # where q < 0 beyond the error band
    assert (lifted[0], lifted[-1]) == (lo, hi) and lo == -1.0
    labels = [item.label for item in drawing.scene_legend.items
              if drawing.lifted_line in item.renderers]
    assert labels == [value("q < 0 (full-contact model)")]
    assert "q < 0 (contact lost)" in contact_text(view, 0)


def test_the_contact_figures_join_the_page_only_when_a_result_needs_them(explorer_app) -> None:

    app = explorer_app()          # the default scene: full contact, flat
    slots = app.results.contact_panes
    assert not slots.width_slot.visible and slots.width_slot.objects == []
    assert not slots.inset_slot.visible and slots.inset_slot.objects == []
    for key, width, inset in (("eccentric_footing_liftoff", True, False),
                              ("worn_coating", False, True), ("uniform_flat", False, False)):
        assert app.load_scene(json.loads(json.dumps(presets()[key])))
        assert app.controller.wait(120) and app.controller.error == ""
        assert (slots.width_slot.visible, slots.inset_slot.visible) == (width, inset), key
    # once sent, a figure stays on the page (hidden), ready for the next scene that needs it
    assert len(slots.width_slot.objects) == len(slots.inset_slot.objects) == 1


def test_the_drawing_goes_to_the_page_as_binary_arrays() -> None:
    """The coating's slabs and the zone's line are arrays, which Bokeh sends as binary
    buffers; as lists of numbers they were ~17 kB of JSON a geometry step, written by the
    server and parsed by the page. The zone's ends stay as computed (float64)."""
    from bokeh.core.serialization import Serializer

    figures, view, last = _drawn("eccentric_footing_liftoff")
    slabs = figures.layer_src.data
    assert slabs and all(isinstance(v, np.ndarray) for v in slabs.values())
    assert slabs["left"].size == 120 and set(slabs["layer"].tolist()) == {1}
    for source in (figures.contact.zone_src, figures.contact.lifted_src):
        assert all(isinstance(v, np.ndarray) and v.dtype == np.float64
                   for column in ("xs", "ys") for v in source.data[column])
    (xs,) = figures.contact.zone_src.data["xs"]
    assert xs[0] == view.contact_set[last][0][0]
    # serialized for the page: seven buffers and a short JSON text (as lists: ~8 kB)
    serializer = Serializer(deferred=True)
    encoded = serializer.encode(dict(figures.layer_src.data))
    text = json.dumps(encoded, default=lambda buffer: {"id": buffer.id})
    assert len(serializer.buffers) == 7 and len(text) < 1500


def test_the_pressure_plot_spans_the_punch_and_its_pins_set_by_the_server() -> None:
    """The x axis of q(x) is set with each result (the punch, the pins), not fitted in the
    page: an automatic range sent its new ends back to the server at every geometry step."""
    from explorer.model import Pin

    figures, view, last = _drawn("rounded_graded")
    a = view.geometry.half_width
    rng = figures.q_fig.x_range
    assert type(rng).__name__ == "Range1d"
    assert (rng.start, rng.end) == pytest.approx((-1.1 * a, 1.1 * a), rel=1e-12)
    assert (rng.reset_start, rng.reset_end) == (rng.start, rng.end)
    wider = _solved("uniform_flat")   # its punch is wider: a pin of it widens the axis
    b = wider.geometry.half_width
    assert b > a
    figures.show(view, last, (Pin(wider, "wider"),))
    assert (rng.start, rng.end) == pytest.approx((-1.1 * b, 1.1 * b), rel=1e-12)


def test_no_coating_badges_on_a_bare_layer_and_several_punches_show_their_worst() -> None:
    # the bare preset showed "✓ coating thin | ✓ coating softer than base | ✓ coating
    # model within solver.model_tol (estimated 0 %)"
    from explorer.model import model_evidence
    from explorer.views.results import badges_html

    bare = _solved("bare_layer")
    assert "coating" not in badges_html(bare, "scene", model_evidence(bare))
    # several punches: their worst punch's estimate, named (the page showed none while
    # every punch was within solver.model_tol)
    pair = _solved("new_footing_beside_old")
    assert ("coating model within solver.model_tol (estimated 1.31 % of the tilt α of "
            "punch 1)") in badges_html(pair, "scene", model_evidence(pair))
    coated = _solved("uniform_flat")
    assert "ok-model_error" in badges_html(coated, "scene", model_evidence(coated))


def test_the_status_line_does_not_vouch_for_an_extrapolated_estimate() -> None:
    # "within solver.model_tol 2 %" beside the badge "coating model error extrapolated"
    from explorer.model import model_evidence
    from explorer.views.status import status_html

    state = ExplorerState()
    scene = json.loads(json.dumps(presets()["uniform_flat"]))
    scene["coating"][0]["modulus"] = 2e5  # 0.2 MPa: beyond the measured map
    state.load_scene(scene)
    controller = SolveController(state, executor=None, auto=False)
    controller.solve_now()
    view = controller.view
    assert "beyond_model_map" in view.flags
    text = status_html(view, False, model_evidence(view))
    assert "extrapolated beyond the measured map" in text and "within solver" not in text
    # a number stays with its unit at a line's end ("135" ended a line, "%" began the next)
    assert " %" not in text and "&nbsp;%" in text, text


def test_the_drawing_s_axis_says_what_its_corner_note_says() -> None:
    """The bare layer read "drawn to scale" in the corner beside "y [m] (exaggerated)" on
    the axis."""
    for key, label, note in (("bare_layer", "y [m]", "drawn to scale"),
                             ("uniform_flat", "y [m] (exaggerated)", "drawn ×")):
        figures, _, _ = _drawn(key)
        drawing = figures.drawing
        assert drawing.fig.yaxis[0].axis_label == label, key
        assert note in drawing.scale_label.text, (key, drawing.scale_label.text)


def test_the_features_legend_hides_no_line() -> None:
    """Inside the inset's corner the legend hid the coating's top: heights are above the
    coating's highest point, so a uniform coating's top is the plot's lowest line."""
    figures, _, _ = _drawn("stepped_punch")
    fig = figures.inset.fig
    assert fig.visible
    assert fig.legend[0] in fig.below and fig.legend[0] not in fig.center


def test_the_design_check_says_when_q_max_is_the_thin_layer_s_at_an_edge() -> None:
    """The flat punch's q_max sits at x = a, where the thin coating model's springs bound
    q; the stepped punch's beside its step, inside, where they bound it too (an
    engineer's audit: the FE check's coating exceeds it within millimetres); the bare
    layer's corner is unbounded and says so in its own row."""
    from explorer.model import check_html, design_check

    html = check_html(design_check(_solved("uniform_flat")))
    assert "check-edge" in html and "q_max at the punch&#x27;s edge: the thin coating" in html
    stepped = check_html(design_check(_solved("stepped_punch")))
    assert "q_max beside a step of the punch: the thin coating" in stepped
    assert "check-edge" not in check_html(design_check(_solved("bare_layer")))


@pytest.mark.parametrize("key", ["new_footing_beside_old", "eccentric_footing_liftoff"])
def test_the_drawing_leaves_room_above_the_punches_for_the_load_labels(key: str) -> None:
    """The two footings' scene is drawn 3 m deep: 0.55 a above the punches was 13 % of
    its height, and the loads' labels ("1: P = 600 kN/m") ran out of its top in
    presentation mode at 1024x768 (a teacher's audit). The room is a quarter of the
    drawing below it at least; the one punch's (depth at most 1.2 a) keeps its 0.55 a."""
    figures, view, _ = _drawn(key)
    drawing = figures.drawing
    y = drawing.fig.y_range
    top = drawing._punch_top
    assert y.end - top >= 0.25 * (top - y.start) - 1e-12
    assert y.end - top >= 0.55 * max(p.half_width for p in view.punches) if view.punches \
        else y.end - top == pytest.approx(0.55 * view.geometry.half_width)


def test_a_preview_of_several_punches_says_so_in_the_readout() -> None:
    """The readout of several punches read "At t = ... after loading" over a preview's
    values without creep (a review): it says it is a preview, as one punch's does."""
    from explorer.views.results import readout_html

    view = _solved("new_footing_beside_old")
    assert view.several
    shown = readout_html(view, len(view.times) - 1, preview=True)
    assert "after loading (preview, without creep)</b>" in shown, shown
    assert "preview" not in readout_html(view, len(view.times) - 1)
