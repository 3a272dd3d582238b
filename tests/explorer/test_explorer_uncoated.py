"""The explorer with no coating layer: the state, the Coating tab and the drawing."""

from __future__ import annotations

import numpy as np
import pytest

from core import scene_from_dict
from explorer.model import ExplorerState, presets
from explorer.model.results import prepare_view

PRESETS = presets()


def test_the_bare_preset_is_offered_and_round_trips_through_the_state():
    assert "bare_layer" in PRESETS
    state = ExplorerState()
    state.load_scene(PRESETS["bare_layer"])
    assert state.n_layers == 0
    scene = state.to_scene()
    assert scene["coating"] == []
    assert scene_from_dict(scene).to_dict() == scene_from_dict(PRESETS["bare_layer"]).to_dict()


def test_zero_layers_on_the_state_give_a_bare_scene_and_back():
    state = ExplorerState()
    state.load_scene(PRESETS["rounded_graded"])  # elastic base, three layers
    kept = state.layers[0].to_dict()
    state.n_layers = 0
    assert state.to_scene()["coating"] == []
    assert scene_from_dict(state.to_scene()).coating == ()
    # the layers' values are kept: one layer back is the first layer as it was
    state.n_layers = 1
    assert state.to_scene()["coating"] == [kept]
    with pytest.raises(ValueError):
        state.n_layers = -1


def test_a_bare_solution_is_drawn():
    scene = PRESETS["bare_layer"]
    from core import solve

    view = prepare_view(solve(scene), scene)
    assert view.geometry.thickness == [] and view.geometry.modulus == []
    assert np.all(np.isfinite(view.pressure))
    # the inverse square-root edges: the grid's edge values far above the middle's
    middle = view.pressure[view.pressure.shape[0] // 2, 0]
    assert view.pressure[0, 0] > 5 * middle and view.pressure[-1, 0] > 5 * middle


def test_the_coating_tab_hides_the_layer_widgets_with_no_layer(explorer_app):
    app = explorer_app("bare_layer", solved=True)
    tab = app.coating_tab
    assert tab.n_layers.start == 0 and tab.n_layers.value == 0
    assert tab.bare_note.visible
    assert not any(part.visible for part in tab.layer_parts)
    # (the tab's first line read "Layer 1 touches the punch" above "no coating")
    assert "Layer 1" not in tab.top_note.object
    assert app.controller.view.geometry.thickness == []
    # one layer: its editors come back, the note goes
    app.state.n_layers = 1
    assert not tab.bare_note.visible and "Layer 1 touches the punch" in tab.top_note.object
    assert all(part.visible for part in tab.layer_parts)
    assert tab.layer.options == ["1"]
    app.state.n_layers = 0
    assert tab.bare_note.visible and not tab.layer.visible


def test_the_heel_lifting_off_the_bare_layer_is_drawn_and_said(explorer_app):
    # e = 0.6 a on the bare layer (H = a): the heel lifts off, the zone [-0.39996 a, a]
    # (tests/engines/test_bare_lift_off.py); the page says it in words
    from explorer.model.contact_zone import contact_text, contact_widths

    app = explorer_app("bare_layer", solved=True)
    app.state.loading.histories["moment"].value = 300.0  # kN m/m with P = 500 kN/m
    assert app.controller.wait(60) and app.controller.error == "", app.controller.error
    view = app.controller.view
    assert view.contact_set[0] == [(pytest.approx(-0.3999646, abs=1e-6), 1.0)]
    assert contact_widths(view)[0] == pytest.approx(1.3999646, abs=1e-6)
    assert contact_text(view, 0) == ("contact 1.4 m of 2 m (70 %), lifted 0.6 m: x = -1 to "
                                     "-0.4 m (unilateral contact)")
    assert np.all(view.pressure[view.x < -0.4, 0] == 0)
    assert np.all(view.pressure[view.x > -0.399, 0] > 0)


@pytest.mark.slow
def test_a_crown_lifting_off_the_creeping_bare_layer_is_drawn_as_its_zone_grows(explorer_app):
    # a crown (R = 20 km) on the bare layer that creeps (a standard linear solid): it lifts
    # at both corners and its zone grows as the base creeps
    # (core/engines/layered/bare_growing_zone.py), which the page draws and says; at tol
    # 1e-3, met (estimate 1.1e-4; the solve 2.2 s of CPU, 4.0 s at 1e-4 for the same
    # zones to the digits drawn; at 1e-6 its time grids stop at an estimate of 2.2e-5,
    # tol_not_met)
    import copy

    from explorer.model.contact_zone import contact_text, contact_widths
    from tests.support.creep_laws import CREEP

    scene = copy.deepcopy(PRESETS["bare_layer"])
    scene["base"]["creep"] = dict(CREEP)
    scene["punch"]["shape"] = {"kind": "polynomial", "coefficients": [0.0, 0.0, 2.5e-5]}
    scene["times"] = {"end": 365.0, "count": 8, "spacing": "log"}
    scene["solver"] = {"tol": 1e-3}
    app = explorer_app(scene=scene, solved=True)
    assert app.controller.wait(120) and app.controller.error == "", app.controller.error
    view = app.controller.view
    assert view.info["success"] and view.info["flags"] == [], view.info["message"]
    widths = contact_widths(view)
    assert 0.0 < widths[0] < widths[-1] < 2.0 and np.all(np.diff(widths) > 0), widths
    assert contact_text(view, 0).startswith("contact ") and "lifted" in contact_text(view, 0)
    outside = np.abs(view.x) > 0.5 * widths[-1] + 1e-3
    assert np.all(view.pressure[outside, :] == 0) and np.all(np.isfinite(view.pressure))


def test_the_status_of_a_bare_layer_states_no_coating_model_error(explorer_app):
    """The bare layer has no coating model: the status line said "Coating model error 0 %
    (estimated), within solver.model_tol 2 %"; the time "t = 1 days"."""
    app = explorer_app("bare_layer", solved=True)
    view = app.controller.view
    app.results.draw(view, 0, True)
    assert "Coating model error" not in app.results.status.object
    assert app.results.evidence(view) is None
    # one layer: the estimate is stated again
    app.state.n_layers = 1
    assert app.controller.wait(120) and app.controller.error == ""
    coated = app.controller.view
    app.results.draw(coated, 0, True)
    assert "Coating model error" in app.results.status.object


def test_the_pressure_csv_says_the_corner_rows_are_held():
    """The bare layer's q CSV gave a finite 2.676 MPa at x = -1 m with nothing saying
    that q grows without bound there and the row holds its value 1 mm away (only the
    JSON's info.corner_pressure said so)."""
    from core import solve
    from explorer.files.exports import parse_csv, pressure_csv

    scene = PRESETS["bare_layer"]
    view = prepare_view(solve(scene), scene)
    meta, names, table = parse_csv(pressure_csv(view))
    assert meta["corner"] == ("q grows without bound toward the rigid corner at x = -1 m "
                              "and x = 1 m; within 0.001 m of it the rows hold its value at "
                              "that distance, and so leave out up to 1.1 % of the force P "
                              "(integrated, the rows fall short; the histories' force and "
                              "moment are the answer's)")
    # the command line's and the API's table says the same
    assert meta["corner"] in solve(scene).pressure_csv()
    # a coated answer of the thin layer's springs has no corner line
    coated = PRESETS["uniform_flat"]
    assert "corner" not in parse_csv(pressure_csv(prepare_view(solve(coated), coated)))[0]


def test_a_corner_where_q_is_unbounded_is_marked_with_the_width_held(explorer_app):
    """The exact layered answer (and the bare base's) holds q within a few mm of a rigid
    corner in contact, where it rises without bound: the flat end of the line read as a
    bounded maximum (an audit of rounded_graded). The corners are marked, and the legend
    says how wide the band held is; a coating of the thin-layer model has none."""
    app = explorer_app("rounded_graded", solved=True)
    figures = app.figures
    held = app.controller.view.info["corner_pressure"]
    assert figures.corner_src.data["x"] == [-0.5, 0.5]
    line = figures.q_src.data["q"]
    assert figures.corner_src.data["q"] == pytest.approx([line[0], line[-1]], rel=1e-6)
    [item] = [i for i in figures.q_fig.legend[0].items if figures.corner_marks in i.renderers]
    assert item.visible and item.label.value == (
        f"q → ∞ at the corner (held within {1e3 * held['held_within_m']:.3g} mm)")
    app.load_scene(presets()["uniform_flat"])
    assert app.controller.wait(60)
    assert figures.corner_src.data["x"] == [] and not item.visible
