"""The explorer's contact widths are the core's (:func:`core.scene.contact_width`, the
length of the contact set): the Study tab's results, chart and CSV, the readout, the
design check, the width plot and the histories file all give what ``core.solve`` gives.
The lift-off preset (e = 0.6 m) touches on 1.349 m of its 2 m at 1000 days; under the
full-contact model it keeps the whole 2 m, flagged contact_lost, its pull zone named
apart."""

from __future__ import annotations

import copy
import csv

import numpy as np
import pytest

from core import solve
from explorer.files import histories_csv, parse_csv, study_csv
from explorer.model import (
    ExplorerState,
    contact_text,
    contact_widths,
    design_check,
    lift_off_lengths,
    lifts_off,
    lifts_or_pulls,
    presets,
)
from explorer.model.study import ECCENTRICITY, Axis, plan_study
from explorer.plots import Figures
from explorer.solving import SolveController, StudyRun

#: The same solver on the same scene, in this process or the study's: measured bitwise
#: equal; 1e-12 leaves room for stage caches prepared in another order.
SAME_SOLVE = 1e-12


def screen_scene(contact: str | None = None) -> dict:
    """The lift-off preset as the page holds it (P = 800 kN/m, e = 0.6 m)."""
    scene = copy.deepcopy(presets()["eccentric_footing_liftoff"])
    if contact is not None:
        scene["solver"]["contact"] = contact
    state = ExplorerState()
    state.load_scene(scene)
    return state.to_scene()


def solved_view(scene: dict):
    state = ExplorerState()
    state.load_scene(scene)
    controller = SolveController(state, executor=None, auto=False)
    controller.solve_now()
    return controller.view


@pytest.fixture(scope="module")
def lift_off():
    scene = screen_scene()
    return scene, solved_view(scene), solve(scene)


def test_the_study_tab_records_the_width_the_page_reads(lift_off) -> None:
    scene, view, result = lift_off
    runner = StudyRun()
    runner.start(plan_study(scene, [Axis(ECCENTRICITY, 0.6, 0.8, 2)]))
    assert runner.wait(300), "the study did not end"
    assert runner.status == "done", runner.message
    study = runner.result
    last = len(study.times) - 1
    widths = study.outputs["contact_width"][0]  # e = 0.6 m, the scene on screen
    np.testing.assert_allclose(widths, result.contact_width, rtol=SAME_SOLVE)
    assert study.shown("contact_width", last)[0] == pytest.approx(1.349, abs=5e-4)
    # the CSV holds that width (not the 2 m where q >= 0) ...
    rows = list(csv.reader(line for line in study_csv(study).splitlines()
                           if not line.startswith("#")))
    header, body = rows[0], rows[1:]
    assert header[0] == "loading_eccentricity_e_m"
    column = header.index("contact_width_m")
    at_06 = np.array([float(row[column]) for row in body if float(row[0]) == 0.6])
    # the file's 10 significant digits
    np.testing.assert_allclose(at_06, result.contact_width, rtol=1e-9)
    assert f"{at_06[-1]:.3f}" == "1.349"
    # ... and the page's readout at the last time says the same
    assert "contact 1.349 m of 2 m" in contact_text(view, len(view.times) - 1)


def test_every_width_of_the_page_is_the_cores(lift_off) -> None:
    _, view, result = lift_off
    a = view.geometry.half_width
    np.testing.assert_allclose(contact_widths(view), result.contact_width, rtol=SAME_SOLVE)
    np.testing.assert_allclose(lift_off_lengths(view), result.lift_off_length,
                               rtol=SAME_SOLVE)
    assert lifts_off(view) and lifts_or_pulls(view)
    check = design_check(view)
    assert check.contact_width == pytest.approx(float(np.min(result.contact_width)),
                                                rel=SAME_SOLVE)
    figures = Figures()
    figures.show(view, len(view.times) - 1, ())
    data = figures.contact.width_src.data
    # the plot's float32: 6e-8 relative
    np.testing.assert_allclose(data["width"], result.contact_width, rtol=1e-7)
    np.testing.assert_allclose(data["lifted"], 2 * a - result.contact_width, rtol=1e-6)
    _, names, table = parse_csv(histories_csv(view))
    np.testing.assert_allclose(table[:, names.index("contact_width_m")],
                               result.contact_width, rtol=1e-9)


def test_the_full_contact_model_keeps_the_whole_width_and_names_its_pull_zone() -> None:
    scene = screen_scene("full")
    view = solved_view(scene)
    result = solve(scene)
    a = view.geometry.half_width
    assert "contact_lost" in view.flags
    np.testing.assert_array_equal(result.contact_width, 2 * a)
    np.testing.assert_array_equal(contact_widths(view), 2 * a)
    np.testing.assert_array_equal(lift_off_lengths(view), 0.0)
    assert not lifts_off(view) and lifts_or_pulls(view)  # it pulls: drawn, not lifted
    assert design_check(view).contact_width == 2 * a
    text = contact_text(view, 0)
    (lo, hi), = view.negative_intervals(0)
    assert lo == -1.0 and text == (
        f"contact 2 m of 2 m, as the full-contact model assumes; q < 0 (contact lost) on "
        f"{hi - lo:.3f} m: x = -1 to {hi:.3f} m (not physical)")
    figures = Figures()
    figures.show(view, 0, ())
    assert figures.contact.width_fig.title.text == "Contact width [m]: full-contact model, q < 0"
    np.testing.assert_array_equal(figures.contact.width_src.data["lifted"], 0.0)
