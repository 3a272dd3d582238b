"""The status line and its details say what the solver reported, and nothing it did not:
no "everything computed afresh" without stage timings, no "? modes"."""

from __future__ import annotations

import types

import numpy as np
import pytest

from explorer.views.status import details_text, plain_status


def _view(info: dict) -> types.SimpleNamespace:
    # the two fields the status reads: the solve report and the result's flags
    return types.SimpleNamespace(info=info, flags=[], scene={"solver": {"tol": 1e-4}})


def test_without_stage_timings_no_claim_of_what_was_recomputed() -> None:
    # the lift-off engine reports no stages (eccentric_footing_liftoff: info has none)
    text = plain_status(_view({"seconds": 0.0012, "error_estimate": 7e-7}))
    assert text.startswith("Solved in 1 ms;"), text
    assert "afresh" not in text and "recomputed" not in text


def test_stage_timings_all_fresh_say_so() -> None:
    stages = {"grid": {"seconds": 0.007, "cached": False},
              "solve": {"seconds": 0.017, "cached": False}}
    # info["seconds"] is the solve's own (as the Nystrom engine reports it); the grid of
    # a new geometry is timed apart and counts too: worn_coating read "Solved in under
    # 1 ms" beside "grid 2.2 ms"
    text = plain_status(_view({"seconds": 0.017, "stages": stages, "error_estimate": 1e-7}))
    assert text.startswith("Solved in 24 ms, everything computed afresh;"), text


def test_times_below_a_millisecond_and_unknown_times() -> None:
    stages = {"grid": {"seconds": 0.007, "cached": True},
              "solve": {"seconds": 0.0004, "cached": False}}
    # reused from an earlier solve, not said to be unchanged (a preset switched to, its
    # geometry solved before in the background, read "were unchanged")
    assert plain_status(_view({"seconds": 0.0004, "stages": stages})).startswith(
        "Solved in under 1 ms: only the response to the loads was recomputed (the "
        "geometry and materials were solved before and reused);")
    assert plain_status(_view({})).startswith("Solved; no accuracy estimate")


def test_details_leave_out_what_the_solver_did_not_report() -> None:
    text = details_text(_view({"n_steps": 124, "message": "unilateral contact"}))
    assert "?" not in text and "modes" not in text
    assert text == "124 time steps · solver: unilateral contact"
    full = details_text(_view({"n_modes": np.int64(128), "n_steps": 32, "message": "ok",
                               "stages": {"solve": {"seconds": 0.0004, "cached": False}}}))
    assert full == "stages: solve 0.4 ms · 128 modes, 32 time steps · solver: ok"
    assert details_text(_view({})) == "the solver reported no details"


def test_the_files_accuracy_line_leaves_out_what_the_solver_did_not_report():
    from explorer.files.exports import accuracy_statement

    view = types.SimpleNamespace(info={"error_estimate": 2e-7, "n_steps": 12}, flags=[],
                           scene={"solver": {"tol": 1e-6}})
    assert accuracy_statement(view) == ("estimated relative error 2.0e-07, target 1e-06 "
                                        "(met); 12 time steps")
    view.info = {}
    assert "?" not in accuracy_statement(view)


def test_a_missed_target_says_by_how_much_and_why() -> None:
    # the lift-off preset at tol 1e-8 (core's own message): the estimate 1.17e-8 read
    # "estimated error 1e-08, target 1e-08, NOT met", a contradiction on its face
    message = ("unilateral contact under creep: 640 steps, estimated error 1.2e-08; not "
               "within tol: 3 x the estimated error = 3.5e-08 is over tol 1.0e-08 (these "
               "estimates have read up to 3x low)")
    view = types.SimpleNamespace(info={"seconds": 3.5, "error_estimate": 1.1735e-8,
                                       "message": message},
                                 flags=["tol_not_met"], scene={"solver": {"tol": 1e-8}})
    text = plain_status(view)
    assert text.endswith("accuracy target NOT met: estimated error 1.2e-08, target 1e-08; "
                         "3 x the estimated error = 3.5e-08 is over tol 1.0e-08 (these "
                         "estimates have read up to 3x low)."), text
    # without a reason in the message, the two numbers alone, with the digits that tell
    # them apart (1.04e-8 read "1e-08" at two digits)
    view.info["message"] = "converged"
    view.info["error_estimate"] = 1.04e-8
    assert plain_status(view).endswith(
        "accuracy target NOT met: estimated error 1.04e-08, target 1e-08."), plain_status(view)
    # the other engines' words: the projection's margin and the Nystrom engine's reasons
    view.info["error_estimate"] = 5e-9
    view.info["message"] = ("tol 1.0e-08 not met (success needs the estimate below tol/3): "
                            "time stepping: estimated error 5.0e-09")
    assert plain_status(view).endswith("target 1e-08; success needs the estimate below "
                                       "tol/3: time stepping: estimated error 5.0e-09."), \
        plain_status(view)
    view.info["message"] = "tol 1.0e-08 not met (success needs the estimate below tol/3)"
    assert plain_status(view).endswith("target 1e-08; success needs the estimate below "
                                       "tol/3."), plain_status(view)


def test_every_engine_s_reason_for_a_missed_target_is_said() -> None:
    """The verdicts that miss for their zone ends, their contact set or a band their ends
    left, and the collocation engine, have no "not met" in their message: the status said
    the numbers alone, an estimate below its target NOT met."""
    from explorer.views.status import missed_reason

    assert missed_reason("unilateral contact (elastic): estimated error 1.0e-09, zone ends "
                         "to 3.0e-07 half-widths; the zone ends did not converge") == \
        "the zone ends did not converge"
    assert missed_reason("unilateral contact under creep: 140 steps, estimated error "
                         "1.0e-07 (...), zone ends to 1e-07 half-widths; a zone end left "
                         "the finely paneled band around the ends at 2 time(s), its "
                         "estimate does not hold there; not within tol: 3 x the estimated "
                         "error = 3.0e-07 is over tol 1.0e-07") == (
        "a zone end left the finely paneled band around the ends at 2 time(s), its "
        "estimate does not hold there; 3 x the estimated error = 3.0e-07 is over tol "
        "1.0e-07")
    assert missed_reason("estimated relative error 2.0e-06 is above tol = 1.0e-06: space: "
                         "the distance from the rule one level coarser gives 2.0e-06; "
                         "refine panels_per_unit or edge_width") == (
        "space: the distance from the rule one level coarser gives 2.0e-06; refine "
        "panels_per_unit or edge_width")
    assert missed_reason("tol 1.0e-08 not met: the grid reached 64 panels with estimated "
                         "error 2.0e-08 in q; time stepping: done") == (
        "the grid reached 64 panels with estimated error 2.0e-08 in q; time stepping: done")
    assert missed_reason("converged") == ""


def test_the_model_error_says_whose_error_it_is(explorer_app) -> None:
    """A tilt of 0.0002 mrad (0.3 % of the settlement) took the patched insert's estimate
    from 0.587 % to 2.08 % and its badge to "above solver.model_tol": the moment's own
    error counts once the tilt is not negligible (core.coating.NEGLIGIBLE_SHARE), and the
    page said only "2.08 %", which read as the whole answer's. It says whose it is."""
    import core
    from core.presets import read_preset

    scene = read_preset("patched_insert")
    level = core.solve(scene)
    assert level.model_error["part"] == "force"
    assert level.model_error["estimate"] == pytest.approx(0.00587, abs=1e-5)
    scene["loading"]["tilt"] = 2e-7
    tilted = core.solve(scene)
    assert tilted.model_error["part"] == "moment"
    assert tilted.model_error["estimate"] == pytest.approx(0.0208, abs=1e-4)
    # the force's part of it is as small as before
    assert abs(tilted.model_error["force"]) < 0.006

    app = explorer_app(scene=scene, solved=True)
    status = app.results.status.object.replace("&nbsp;", " ")  # (a percentage kept whole)
    assert "Coating model error 2.08 % of the moment M (estimated), above solver.model_tol" \
        in status, status
    assert "(estimated 2.08 % of the moment M)" in app.results.scene_badges.object
    # where the moment is given, the tilt is the unknown
    app = explorer_app(scene=read_preset("eccentric_creep"), solved=True)
    assert " of the tilt α (estimated)" in app.results.status.object


def test_several_punches_state_their_worst_punch_s_model_error(explorer_app) -> None:
    """new_footing_beside_old said only "Solved; accurate to about 5e-05" while every
    single punch's page states its coating model's error."""
    import core
    from core.presets import read_preset
    from core.scene import percent_text

    scene = read_preset("new_footing_beside_old")
    errors = [p.model_error for p in core.solve(scene).punches]
    worst = max(range(len(errors)), key=lambda k: errors[k]["estimate"])
    assert errors[worst]["part"] == "moment"  # the tilt is the unknown: force and moment given
    app = explorer_app(scene=scene, solved=True)
    assert (f"Coating model error {percent_text(errors[worst]['estimate'])} of the tilt α of "
            f"punch {worst + 1} (estimated), within solver.model_tol 2 %."
            ) in app.results.status.object.replace("&nbsp;", " ")


def test_the_status_line_repeats_a_flag_the_model_does_not_hold_under() -> None:
    """A force of 1e9 kN/m settled the uniform preset's slab 81 m with green badges at the
    top and the one warning below the design check (a teacher's audit): the status line,
    at the top, says it too; an answer without such a flag says nothing more."""
    from core import solve
    from core.presets import read_preset
    from explorer.model import prepare_view
    from explorer.views.status import status_html

    scene = read_preset("uniform_flat")
    scene["loading"]["force"] = 1e12
    flagged = prepare_view(solve(scene), scene)
    assert "large_settlement" in flagged.flags
    text = status_html(flagged, False)
    assert ("status-warnings'>⚠ Flagged: settlement beyond small strains (the badges "
            "below say why).</span>") in text
    plain = read_preset("uniform_flat")
    assert "Flagged" not in status_html(prepare_view(solve(plain), plain), False)
