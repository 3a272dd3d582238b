"""The coating tab prompts the interface choice where it matters (a layer of Poisson ratio
near 0.5), and the figures the prompt quotes are the solver's."""

from __future__ import annotations

import pytest

from core.scene import solve
from explorer.model import ExplorerState
from explorer.views.fidelity import PROMPT_POISSON, FidelityView
from tests.support.epoxy_on_pad import epoxy_on_pad_scene


def test_a_nearly_incompressible_layer_prompts_its_interface():
    state = ExplorerState()
    view = FidelityView(state)
    layer = state.layers[0]
    layer.poisson.mean = 0.3
    view.bind_layer(layer)
    assert "It matters here" not in view.interface_label.object
    layer.poisson.mean = PROMPT_POISSON + 0.05
    assert "It matters here" in view.interface_label.object
    other = state.layers[1]
    other.poisson.mean = 0.2
    view.bind_layer(other)  # the note follows the layer being edited
    assert "It matters here" not in view.interface_label.object
    layer.poisson.mean = 0.3  # no longer watched: no error, no change
    assert "It matters here" not in view.interface_label.object


@pytest.mark.parametrize(("interface", "settlement_mm"), [("smooth", 0.15), ("bonded", 0.063)])
def test_the_prompts_example_is_what_the_solver_gives(interface, settlement_mm):
    scene = epoxy_on_pad_scene()
    scene["times"] = {"end": 18262.5, "count": 20, "spacing": "log"}  # 50 years
    scene["loading"] = {"force": 8.0e5, "moment": 0.0}
    scene["coating"][1]["interface"] = interface  # the pad on the concrete
    result = solve(scene)
    # the prompt quotes two significant digits (measured 0.1485 and 0.0630 mm)
    assert float(f"{1e3 * result.settlement[-1]:.2g}") == settlement_mm
