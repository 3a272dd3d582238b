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
    assert app.controller.view.geometry.thickness == []
    # one layer: its editors come back, the note goes
    app.state.n_layers = 1
    assert not tab.bare_note.visible
    assert all(part.visible for part in tab.layer_parts)
    assert tab.layer.options == ["1"]
    app.state.n_layers = 0
    assert tab.bare_note.visible and not tab.layer.visible
