"""Lift-off on screen: the contact set of a unilateral solve becomes the shaded lifted
parts of q(x) and the contact width of the design check."""

from __future__ import annotations

import json

import pytest

from explorer.model import ExplorerState, design_check, presets
from explorer.model.results import lifted_intervals
from explorer.solving import SolveController


@pytest.mark.parametrize(("zones", "lifted"), [
    ([(-1.0, 1.0)], []),
    ([(-0.3, 1.0)], [(-1.0, -0.3)]),
    ([(-1.0, -0.5), (0.2, 0.6)], [(-0.5, 0.2), (0.6, 1.0)]),
    ([], [(-1.0, 1.0)]),
])
def test_lifted_parts_are_the_complement_of_the_contact_zones(zones, lifted) -> None:
    assert lifted_intervals(zones, 1.0) == lifted


def test_liftoff_preset_shows_its_contact_zone() -> None:
    state = ExplorerState()
    state.load_scene(json.loads(json.dumps(presets()["eccentric_footing_liftoff"])))
    controller = SolveController(state, executor=None, auto=False)
    controller.solve_now()
    view = controller.view
    assert view is not None, controller.error
    assert len(view.contact_set) == len(view.times)
    a = view.geometry.half_width
    last = len(view.times) - 1
    (lo, hi), = view.negative_intervals(last)   # one lifted part, at the heel
    assert lo == -a and -a < hi < a
    check = design_check(view)
    # the design check reads the narrowest contact width from the same contact set
    narrowest = min(2 * a - sum(h - lo_ for lo_, h in lifted_intervals(z, a))
                    for z in view.contact_set)
    assert check.contact_width == pytest.approx(narrowest, rel=1e-12)
    assert check.contact_width < 2 * a


def test_design_check_text_gives_the_lift_off_length() -> None:
    from explorer.model import check_html

    state = ExplorerState()
    state.load_scene(json.loads(json.dumps(presets()["eccentric_footing_liftoff"])))
    controller = SolveController(state, executor=None, auto=False)
    controller.solve_now()
    check = design_check(controller.view)
    text = check_html(check)
    assert f"lift-off length {check.full_width - check.contact_width:.4g} m" in text
    # the narrowest over the history, and when: it read "contact width 1.306 m" beside
    # the result's "contact 1.349 m" at 1000 days, with no word of which time
    assert "smallest contact width 1.306 m of 2 m (65 %) at t = 0 days" in text


def test_histories_csv_carries_the_contact_width_and_the_lifted_length() -> None:
    from explorer.files import histories_csv, parse_csv
    from explorer.model import contact_widths

    state = ExplorerState()
    state.load_scene(json.loads(json.dumps(presets()["eccentric_footing_liftoff"])))
    controller = SolveController(state, executor=None, auto=False)
    controller.solve_now()
    view = controller.view
    meta, names, table = parse_csv(histories_csv(view))
    assert names[-2:] == ["contact_width_m", "lifted_length_m"]
    assert meta["unit contact_width_m"].startswith("m, length of the base in contact")
    a = view.geometry.half_width
    # the plotted widths, to the 10 significant digits the file writes
    widths = contact_widths(view)
    assert widths.min() < 2 * a  # this preset lifts off
    assert table[:, -2] == pytest.approx(widths, rel=1e-9)
    assert table[:, -1] == pytest.approx(2 * a - widths, rel=1e-9, abs=1e-9 * a)


def test_design_check_says_the_pressure_is_unbounded_at_a_bare_corner() -> None:
    from explorer.model import DesignLimits, check_html

    state = ExplorerState()
    state.load_scene(json.loads(json.dumps(presets()["bare_layer"])))
    controller = SolveController(state, executor=None, auto=False)
    controller.solve_now()
    check = design_check(controller.view, DesignLimits(allowable_pressure=3000.0))
    assert check.q_max.verdict == "FAIL" and check.passed is False
    text = check_html(check)
    assert "unbounded at the corner" in text and "over the limit within ~0.8 mm" in text
    # a limit the pressure passes on the whole base is not extrapolated from the corner
    # (it read "within ~1.8e+02 mm" for 200 kPa, q >= 202.6 kPa everywhere)
    text = check_html(design_check(controller.view, DesignLimits(allowable_pressure=200.0)))
    assert "over the limit on the whole base" in text
    text = check_html(design_check(controller.view, DesignLimits(allowable_pressure=300.0)))
    assert "over the limit within ~100 mm of the corner" in text


def test_the_check_and_the_readout_write_realistic_values_without_an_exponent() -> None:
    # 20 MN/m on the default footing read "q_max [kPa] 2.075e+04"; the readout wrote any
    # value past 1e5 as "1.0000e+05"
    from explorer.model import check_html
    from explorer.model.design import Check, DesignCheck
    from explorer.views.results import _fmt

    line = Check("largest contact pressure", 20751.3, "kPa", "t = 0 days", 30000.0, True)
    check = DesignCheck(q_max=line, q_min=line, contact_width=2.0, full_width=2.0,
                        eccentricity=0.0, checks=[line])
    text = check_html(check)
    assert "20750" in text and "30000" in text and "e+0" not in text
    assert _fmt(123456.0) == "123460" and _fmt(0.040812) == "0.040812"


def test_the_check_of_a_flagged_answer_says_its_pass_is_not_to_be_relied_on() -> None:
    """The Check tab read "✓ all set limits hold" beside a model_error flag (a pad whose
    coating model was 70 % off); the downloads' design_check line likewise."""
    from explorer.files import histories_csv
    from explorer.model import DesignLimits, check_html

    state = ExplorerState()
    scene = json.loads(json.dumps(presets()["eccentric_footing_liftoff"]))
    scene["solver"]["contact"] = "full"     # the heel's tension kept: contact_lost
    state.load_scene(scene)
    controller = SolveController(state, executor=None, auto=False)
    controller.solve_now()
    assert "contact_lost" in controller.view.flags
    limits = DesignLimits(settlement_limit=1e3)
    text = check_html(design_check(controller.view, limits))
    assert "✓ all set limits hold" in text and "check-flagged" in text
    assert ("on an answer flagged contact_lost: the check is only as good as that answer, "
            "not to be relied on") in text
    assert "# design_check: pass (on an answer flagged contact_lost" in \
        histories_csv(controller.view, limits)


@pytest.mark.parametrize(("e", "align"), [(0.83, "right"), (-0.83, "left"), (0.0, "left")])
def test_the_load_label_runs_toward_the_middle_of_the_drawing(explorer_app, e, align):
    """At e = 0.83 m the load's label began at the arrow and ran off the drawing's right
    edge at 1024 px ("P = 800 kN/m, e = M/P =", the value cut): it now ends at an arrow
    right of the centre and begins at one left of it."""
    scene = presets()["eccentric_footing_liftoff"]
    scene["loading"] = {"force": 8e5, "moment": 8e5 * e}
    app = explorer_app(scene=scene, solved=True)
    label = app.figures.drawing.arrow_label
    assert label.text.endswith(f"e = M/P = {e:.3g} m")
    assert label.text_align == align and (label.x_offset < 0) == (align == "right")
