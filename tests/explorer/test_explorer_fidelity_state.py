"""The explorer state keeps the coating-fidelity and contact fields of a scene.

A scene's ``coating[k].interface``, ``solver.model_tol`` and ``solver.contact`` survive a
round trip through the state and through a link, and fields at their defaults stay
implicit, so that a scene without them is saved unchanged.
"""

from __future__ import annotations

import copy
import json
from pathlib import Path

import pytest

from core import scene_from_dict
from explorer.model import ExplorerState, decode_scene, encode_scene

LIFTOFF = Path(__file__).resolve().parents[2] / "core/presets/scenes/eccentric_footing_liftoff.json"


def _scene() -> dict:
    scene = json.loads(LIFTOFF.read_text())
    scene["coating"][0]["interface"] = "bonded"
    scene.setdefault("solver", {}).update(model_tol=0.05, contact="unilateral")
    return scene


def test_fields_survive_state_and_link_round_trip() -> None:
    scene = _scene()
    state = ExplorerState()
    state.load_scene(scene)
    saved = state.to_scene()
    assert saved["coating"][0]["interface"] == "bonded"
    assert saved["solver"]["model_tol"] == 0.05  # exact: the 12-digit rounding of 5 %
    assert saved["solver"]["contact"] == "unilateral"
    again = ExplorerState()
    again.load_scene(decode_scene(encode_scene(saved)))
    assert again.to_scene() == saved
    scene_from_dict(saved)  # still a valid scene


def test_defaults_stay_implicit() -> None:
    scene = json.loads(LIFTOFF.read_text())
    scene["solver"].pop("contact", None)
    scene["solver"].pop("model_tol", None)
    for layer in scene["coating"]:
        layer.pop("interface", None)
    state = ExplorerState()
    state.load_scene(copy.deepcopy(scene))
    saved = state.to_scene()
    assert set(saved["solver"]) == {"tol"}
    assert all("interface" not in layer for layer in saved["coating"])


@pytest.mark.parametrize("change", [
    lambda s: setattr(s.layers[0], "interface", "bonded"),
    lambda s: setattr(s, "contact", "full"),
    lambda s: setattr(s, "model_tol_percent", 10.0),
])
def test_a_change_of_a_fidelity_field_is_a_scene_change(change) -> None:
    state = ExplorerState()
    before = state.revision
    change(state)
    assert state.revision == before + 1
    scene_from_dict(state.to_scene())


def test_widgets_edit_and_show_the_fidelity_fields(explorer_app) -> None:

    app = explorer_app()
    view = app.fidelity
    view.interface.value = "bonded"
    assert app.state.layers[0].interface == "bonded"
    view.contact.value = "unilateral"
    view.model_tol.value = 5.0
    saved = app.state.to_scene()
    assert saved["solver"]["contact"] == "unilateral" and saved["solver"]["model_tol"] == 0.05
    scene = _scene()
    scene["coating"][0]["interface"] = "smooth"
    app.state.load_scene(scene)                      # a loaded scene shows its values
    assert view.interface.value == "smooth"
    assert view.contact.value == "unilateral" and view.model_tol.value == 5.0
