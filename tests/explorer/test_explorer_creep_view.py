"""The design-code creep inputs and the phi(t, t0) plot of the explorer
(explorer/model/code_creep_state.py, explorer/views/creep.py)."""

import math

import numpy as np
import pytest

from explorer.model import CodeCreepState, creep_coefficient_data
from explorer.views.creep import creep_coefficient_figure, update_creep_figure


def _ec2_phi(fcm: float, rh: float, h0: float, t0: float, d: float, temp: float = 20.0) -> float:
    """EN 1992-1-1 Annex B written out independently (normal cement, alpha = 0)."""
    a1, a2, a3 = (35 / fcm) ** 0.7, (35 / fcm) ** 0.2, (35 / fcm) ** 0.5
    phi_rh = (1 + (1 - rh / 100) / (0.1 * h0 ** (1 / 3)) * a1) * a2
    t0_adj = max(t0 * math.exp(13.65 - 4000 / (273 + temp)), 0.5)
    phi0 = phi_rh * 16.8 / math.sqrt(fcm) / (0.1 + t0_adj ** 0.2)
    beta_h = min(1.5 * (1 + (0.012 * rh) ** 18) * h0 + 250 * a3, 1500 * a3)
    return phi0 * (d / (beta_h + d)) ** 0.3


def test_eurocode2_curve_matches_annex_b_written_out():
    state = CodeCreepState(code_model="eurocode2", strength_class="C30/37", cement="N",
                           relative_humidity=50.0, notional_size=200.0)
    data = creep_coefficient_data(state.spec(), 28.0, np.array([1.0, 100.0, 18262.5]))
    expected = [_ec2_phi(38.0, 50.0, 200.0, 28.0, d) for d in (1.0, 100.0, 18262.5)]
    # measured relative difference 0 to 2.2e-16 (same formulas, rounding only)
    assert data["phi"] == pytest.approx(expected, rel=1e-12)
    # the order of magnitude of EN 1992-1-1 Figure 3.1 (C30/37, t0 = 28 d, h0 = 200 mm,
    # indoor): phi(infinity, 28) is read there as about 2.3 to 2.6
    assert 2.0 < data["phi"][-1] < 2.8


def test_spec_round_trips_and_names_fields_on_error():
    state = CodeCreepState()
    spec = state.spec()
    assert spec == {"model": "fib_mc2010", "strength_class": "C30/37", "cement": "N",
                    "relative_humidity": 60.0, "notional_size": 300.0, "temperature": 20.0}
    other = CodeCreepState()
    other.load({**spec, "model": "eurocode2", "strength_class": None, "fcm": 45.0})
    assert other.strength_class == "fcm" and other.fcm == 45.0
    assert other.spec()["fcm"] == 45.0
    with pytest.raises(ValueError, match="base.creep.relative_humidity"):
        CodeCreepState(relative_humidity=20.0).spec()
    with pytest.raises(ValueError, match="base.creep.notional_size"):
        CodeCreepState(notional_size=5000.0).spec()
    with pytest.raises(ValueError, match="base.creep.temperature"):
        CodeCreepState(temperature=35.0).spec()  # fib MC2010 covers 5 to 30 deg C
    with pytest.raises(ValueError, match="base.creep.model"):
        other.load({"model": "prony"})


def test_figure_shows_the_curve_or_empties_on_refusal():
    fig, source = creep_coefficient_figure()
    assert fig.x_scale.__class__.__name__ == "LogScale"
    state = CodeCreepState()
    assert update_creep_figure(fig, source, state, 7.0) == ""
    phi = np.asarray(source.data["phi"])
    assert len(phi) > 100 and np.all(np.diff(phi) > 0)  # creep only grows under load
    state.relative_humidity = 10.0
    message = update_creep_figure(fig, source, state, 7.0)
    assert "relative_humidity" in message and len(source.data["phi"]) == 0


def test_base_state_offers_the_code_models_and_round_trips_the_preset():
    import json
    from pathlib import Path

    from explorer.model import CREEP_MODELS, ExplorerState

    assert {"fib_mc2010", "eurocode2"} <= set(CREEP_MODELS)
    scene = json.loads((Path(__file__).resolve().parents[2]
                        / "core/presets/scenes/young_concrete_50_years.json").read_text())
    state = ExplorerState()
    state._load(scene)
    assert state.base.creep_model == "fib_mc2010"  # by name, not as "other model"
    assert state.to_scene()["base"]["creep"] == scene["base"]["creep"]
    before = state.revision
    state.base.code.relative_humidity = 80.0
    assert state.revision == before + 1  # a code input is a change of the scene
    state.base.creep_model = "eurocode2"
    assert state.to_scene()["base"]["creep"]["model"] == "eurocode2"
    state.base.code.relative_humidity = 20.0
    with pytest.raises(ValueError, match="base.creep.relative_humidity"):
        state.to_scene()


def test_the_page_reads_every_class_core_reads():
    """A scene's "c30/37" or C12/15 (taken by core) was refused on the page: its own
    list, case-sensitive, began at C20/25. One list now, core's table."""
    from core.creep import CUBE_STRENGTHS
    from explorer.model import STRENGTH_CLASSES

    assert STRENGTH_CLASSES == tuple(f"C{a}/{b}" for a, b in CUBE_STRENGTHS.items())
    state = CodeCreepState()
    base = {"model": "fib_mc2010", "relative_humidity": 60.0, "notional_size": 300.0}
    for written, shown in (("c30/37", "C30/37"), ("C12/15", "C12/15"),
                           ("C 120/140", "C120/140")):
        state.load({**base, "strength_class": written})
        assert state.strength_class == shown and state.spec()["strength_class"] == shown
    with pytest.raises(ValueError, match="base.creep.strength_class: 'C30/99' is not one "
                                         "of C12/15"):
        state.load({**base, "strength_class": "C30/99"})
