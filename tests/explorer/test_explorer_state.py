"""The explorer's state and solve logic, without a server or a browser.

Widget values -> scene dicts the core accepts; presets in and out of the state; the
statement switch; bad values give a message naming the field and keep the last good
result; a change of the load re-solves without re-evaluating any geometric stage.
"""

from __future__ import annotations

import asyncio
import json
import math
import threading
import zlib
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np
import param
import pytest

from core import scene_from_dict, solve
from explorer.model import (
    CREEP_MODELS,
    QUANTITIES,
    STATEMENTS,
    ExplorerState,
    ProfileState,
    decode_scene,
    encode_scene,
    presets,
    validated_scene,
)
from explorer.model.results import negative_intervals
from explorer.solving import SolveController, describe_field, format_error
from explorer.solving.result_cache import RESULTS

PRESETS = presets()

# Stages of the pipeline that depend on the geometry and materials only: a change of the
# load must never evaluate them again.
GEOMETRIC_STAGES = ("grid", "bordered", "modal")


def canonical(scene: dict[str, Any]) -> dict[str, Any]:
    return validated_scene(scene).to_dict()  # one punch, or several


def assert_same(a: Any, b: Any, path: str = "scene") -> None:
    """Structural equality with floats compared to 1e-12 relative."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and set(a) == set(b), f"{path}: keys {set(a) ^ set(b)}"
        for key in a:
            assert_same(a[key], b[key], f"{path}.{key}")
    elif isinstance(a, (list, tuple)):
        assert isinstance(b, (list, tuple)) and len(a) == len(b), f"{path}: length"
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            assert_same(x, y, f"{path}[{i}]")
    elif isinstance(a, float) or isinstance(b, float):
        assert math.isclose(a, b, rel_tol=1e-12, abs_tol=1e-300), f"{path}: {a} != {b}"
    else:
        assert a == b, f"{path}: {a!r} != {b!r}"


def small(state: ExplorerState) -> ExplorerState:
    """Few output times keep the real solves of these tests quick."""
    state.param.update(time_count=8)
    return state


# ------------------------------------------------------------------ state -> scene dict


def test_default_state_is_a_valid_scene():
    scene = ExplorerState().to_scene()
    assert scene["schema_version"] == 1
    built = scene_from_dict(scene)
    assert set(built.loading) == {"force", "moment"}


@pytest.mark.parametrize("shape", ["flat", "parabolic", "wedge", "stepped", "land", "wavy"])
def test_every_punch_shape_gives_a_valid_scene(shape):
    state = ExplorerState()
    state.punch.shape = shape
    scene = state.to_scene()
    built = scene_from_dict(scene)
    x = np.linspace(-1, 1, 201)
    f = np.asarray(built.shape(x))
    # shapes are micrometre features, not millimetres
    assert np.all(np.abs(f) < 1e-3)


def test_punch_shape_units():
    state = ExplorerState()
    p = state.punch
    p.param.update(shape="parabolic", radius=20.0)          # km
    assert state.to_scene()["punch"]["shape"]["coefficients"][2] == pytest.approx(2.5e-5)
    p.param.update(shape="stepped", step_height=15.0, step_position=0.25)   # µm, m
    assert state.to_scene()["punch"]["shape"] == {"kind": "step",
                                                  "values": [0.0, pytest.approx(15e-6)],
                                                  "breaks": [0.25]}
    p.param.update(shape="wedge", slope=50.0)                # µrad
    table = scene_from_dict(state.to_scene()).shape
    assert float(table(np.array([1.0]))[0]) == pytest.approx(50e-6)


@pytest.mark.parametrize("kind", ["none", "linear", "step", "patch", "sine", "bump"])
def test_every_coating_variation_gives_a_valid_scene(kind):
    state = ExplorerState()
    layer = state.layers[0]
    layer.thickness.param.update(kind=kind, mean=10.0, amplitude=20.0, position=0.2,
                                 length=0.4)
    layer.modulus.param.update(kind=kind, mean=500.0, amplitude=50.0, position=-0.1,
                               length=0.3)
    built = scene_from_dict(state.to_scene())
    x = np.linspace(-1, 1, 401)
    h = np.asarray(built.coating[0].thickness(x))
    e = np.asarray(built.coating[0].modulus(x))
    # the thickness amplitude is absolute (µm), the modulus one relative (%)
    assert np.max(np.abs(h - 0.010)) <= 20e-6 * (1 + 1e-9)
    assert np.max(np.abs(e - 500e6)) <= 0.5 * 500e6 * (1 + 1e-9)
    if kind != "none":
        assert np.ptp(h) > 0 and np.ptp(e) > 0


@pytest.mark.parametrize("model", [m for m in CREEP_MODELS if m != "custom"])
def test_every_creep_model_gives_a_valid_scene(model):
    state = ExplorerState()
    state.base.creep_model = model
    built = scene_from_dict(state.to_scene())
    assert built.modulus_at_loading() > 0


@pytest.mark.parametrize("kind", ["constant", "ramp", "step", "sine"])
@pytest.mark.parametrize("statement", list(STATEMENTS))
def test_every_statement_and_history_gives_a_valid_scene(statement, kind):
    state = ExplorerState()
    state.loading.statement = statement
    for q in QUANTITIES:
        state.loading.histories[q].param.update(kind=kind, time=30.0)
    scene = state.to_scene()
    assert set(scene["loading"]) == set(STATEMENTS[statement])
    scene_from_dict(scene)


def test_layers_count():
    state = ExplorerState()
    state.n_layers = 3
    state.layers[2].modulus.mean = 3000.0
    scene = state.to_scene()
    assert len(scene["coating"]) == 3
    assert scene["coating"][2]["modulus"] == pytest.approx(3e9)
    assert len(scene_from_dict(scene).coating) == 3


def test_revision_counts_each_change_and_a_load_once():
    state = ExplorerState()
    start = state.revision
    state.loading.histories["force"].value = 700.0
    assert state.revision == start + 1
    state.load_scene(PRESETS["worn_coating"])
    assert state.revision == start + 2


# ------------------------------------------------------------------------- presets


def test_presets_are_there_and_described():
    expected = {"uniform_flat", "worn_coating", "patched_insert", "rounded_graded",
                "eccentric_creep", "stepped_punch"}
    assert expected <= set(PRESETS)
    for key, scene in PRESETS.items():
        assert scene.get("name"), key
        assert len(scene.get("description", "")) > 40, key
        # the selector shows ~286 px of a name (measured in Chromium, both widths): "A
        # new footing beside an old one on young concrete" (303 px, 50 characters) was
        # cut; the longest shown whole, 48 characters, took 251 px
        assert len(scene["name"]) <= 48, (key, scene["name"])


@pytest.mark.parametrize("key", sorted(PRESETS))
def test_each_preset_loads_into_the_state_and_back(key):
    preset = PRESETS[key]
    state = ExplorerState()
    state.load_scene(preset)
    assert_same(canonical(state.to_scene()), canonical(preset))


def test_presets_use_the_on_screen_controls():
    """The presets are meant to be edited: their profiles map onto widgets, not 'custom'."""
    state = ExplorerState()
    state.load_scene(PRESETS["worn_coating"])
    thickness = state.layers[0].thickness
    assert thickness.kind == "bump" and thickness.amplitude == pytest.approx(-20.0)  # µm
    state.load_scene(PRESETS["patched_insert"])
    assert state.layers[0].modulus.kind == "patch"
    assert state.layers[0].modulus.amplitude == pytest.approx(500.0)  # % of the level
    state.load_scene(PRESETS["stepped_punch"])
    assert state.punch.shape == "land" and state.punch.land_height == pytest.approx(15.0)
    state.load_scene(PRESETS["rounded_graded"])
    assert state.punch.shape == "parabolic" and state.punch.radius == pytest.approx(20.0)
    assert state.n_layers == 3


def test_unknown_profiles_travel_verbatim():
    spec = {"kind": "table", "points": [[-1.0, 0.01], [0.0, 0.012], [1.0, 0.01]],
            "interpolation": "pchip"}
    profile = ProfileState(scale=1e-3, amplitude_scale=1e-6)
    profile.load_spec(spec)
    assert profile.kind == "custom"
    assert profile.to_spec() == spec
    scene = ExplorerState().to_scene()
    scene["coating"][0]["modulus"] = {"expr": "1e9 * (1 + 0.1 * x^2)"}
    scene["times"] = [1.0, 10.0, 100.0]
    state = ExplorerState()
    state.load_scene(scene)
    assert_same(canonical(state.to_scene()), canonical(scene))
    state.time_end = 50.0  # a change of the time span replaces the explicit list
    assert state.to_scene()["times"]["end"] == 50.0


def test_a_scene_the_screen_cannot_show_leaves_the_state_unchanged():
    state = ExplorerState()
    before = state.to_scene()
    bad = json.loads(json.dumps(before))
    bad["loading"] = {"settlement": 0.0, "force": 1.0}
    with pytest.raises(ValueError, match="loading"):
        state.load_scene(bad)
    assert state.to_scene() == before


# -------------------------------------------------------------------- statements


def test_statement_switch_changes_the_given_pair_and_keeps_histories():
    state = ExplorerState()
    state.loading.histories["force"].value = 640.0
    state.loading.statement = "settlement + tilt given"
    assert set(state.to_scene()["loading"]) == {"settlement", "tilt"}
    assert state.loading.unknowns == ("force", "moment")
    state.loading.statement = "tilt + force given"
    loading = state.to_scene()["loading"]
    assert set(loading) == {"tilt", "force"}
    assert loading["force"] == pytest.approx(640e3)
    assert state.loading.unknowns == ("settlement", "moment")


def test_statement_switch_changes_which_quantities_the_result_computes():
    state = small(ExplorerState())
    controller = SolveController(state, executor=None)
    controller.request()
    first = controller.view
    assert first.given == ("force", "moment")
    settlement = first.values["settlement"][-1]
    state.loading.statement = "settlement + tilt given"
    view = controller.view
    assert view is not first and view.given == ("settlement", "tilt")
    assert set(view.unknowns) == {"force", "moment"}
    assert view.values["settlement"][-1] == pytest.approx(
        state.loading.histories["settlement"].value * 1e-3)
    assert view.values["force"][-1] > 0
    assert settlement > 0


# ----------------------------------------------------------- bad values and errors


def test_bad_value_gives_a_message_naming_the_field_and_keeps_the_last_result():
    state = small(ExplorerState())
    controller = SolveController(state, executor=None)
    controller.request()
    good = controller.view
    assert good is not None and controller.error == ""

    state.layers[0].thickness.mean = -5.0  # mm
    assert "coating[0].thickness" in controller.error
    assert "Coating layer 1" in controller.error
    assert controller.view is good  # the plots keep the last good result

    state.layers[0].thickness.mean = 12.0
    assert controller.error == ""
    fixed = controller.view
    assert fixed is not good
    state.base.poisson = 0.7
    assert "base.poisson" in controller.error
    assert controller.view is fixed

    # the session keeps working once the values are fixed
    state.base.poisson = 0.2
    assert controller.error == ""
    assert controller.view is not fixed
    assert controller.view.scene["coating"][0]["thickness"] == pytest.approx(0.012)


def test_solver_crash_is_a_message_not_an_exception():
    state = small(ExplorerState())

    def broken(scene):
        raise RuntimeError("boom")

    controller = SolveController(state, solve=broken, executor=None)
    controller.request()
    assert "boom" in controller.error and controller.view is None


def test_a_punch_too_wide_for_its_base_is_said_with_both_lengths_and_a_plain_ratio():
    """A half-width of 1e6 m read "Base, thickness (base.thickness): the ratio ... must be
    in [0.0001, 100], got 250000 m": the ratio with a unit, and the punch the user changed
    not said."""
    state = ExplorerState()
    state.punch.half_width = 1e6
    controller = SolveController(state, executor=None, auto=False)
    controller.solve_now()
    assert controller.error == (
        "Base, thickness (base.thickness): the ratio punch.half_width / base.thickness = "
        "1e+06 m / 2 m = 500000 must be in [0.0001, 100] (a thicker or thinner base, or a "
        "narrower or wider punch)")


def test_a_step_or_land_off_the_punch_is_said_in_the_sliders_words(explorer_app):
    """The step position's slider reached x = a (End) and the land width 2 m on a punch
    0.2 m wide: both were refused as "punch.shape.breaks[0]: must lie strictly inside the
    domain ...", naming no box on the page. The sliders now stay inside the punch, and a
    value typed past it is said in their words."""
    def error(**punch: float | str) -> str:
        state = ExplorerState()
        state.punch.param.update(**punch)
        controller = SolveController(state, executor=None, auto=False)
        controller.solve_now()
        return controller.error

    assert error(shape="stepped", step_position=1.0) == (
        "Punch, shape (punch.shape): the step position must lie strictly inside the punch "
        "(-1, 1) m, is 1 m")
    assert error(half_width=0.1, shape="land") == (
        "Punch, shape (punch.shape): the land width must be above 0 and below the punch's "
        "width 2a = 0.2 m, is 0.8 m")
    assert error(shape="stepped", step_position=0.99) == ""
    # the crown radius: 0 km read "Punch, shape, coefficients[2] (punch.shape.
    # coefficients[2]): must be a finite number, is inf", and -5 km drew a dished base
    # under "crowned"
    for radius in (0.0, -5.0):
        assert error(shape="parabolic", radius=radius) == (
            f"Punch, shape (punch.shape): the crown radius R must be > 0 km, is {radius:g} "
            "km (a dished base is a custom shape, a table of heights or a polynomial in a "
            "scene file)")
    assert error(shape="parabolic", radius=0.5) == ""
    app = explorer_app()
    app.state.punch.half_width = 0.5
    view = app.punch_tab
    view.refresh()
    spec = view.step_position._spec
    assert (spec["start"], spec["end"]) == (-0.49, 0.49)
    assert view.land_width._spec["end"] == pytest.approx(0.98)


def test_format_error_says_loads_and_stresses_in_the_page_units():
    # the sliders read kN/m and kN·m/m; the messages read "P = -200000 N/m"
    assert format_error("loading.force: the punch is pulled away (P = -200000 N/m at t = 0 "
                        "days after loading)") == (
        "Loading, force (loading.force): the punch is pulled away (P = -200 kN/m at t = 0 "
        "days after loading)")
    assert "M = 480 kN·m/m with no force (P = 0 kN/m)" in format_error(
        "loading.moment: M = 480000 N·m/m with no force (P = 0 N/m) at t = 1 days")
    assert format_error("coating[0].modulus: got -5e+06 Pa, 2.5e9 Pa, 300 Pa").endswith(
        "got -5 MPa, 2500 MPa, 0.3 kPa")
    assert format_error("base.thickness: must be > 0 m, got -1.5 m").endswith("got -1.5 m")
    # a coating layer's thickness box is in mm
    assert format_error("coating[0].thickness: must be > 0 m, got -0.005 m").endswith(
        "must be > 0 mm, got -5 mm")
    # the value in mm, the place on the punch in m as the punch's boxes (it read "is
    # -0.005 at x = -1000 mm")
    assert format_error("coating[0].thickness: must be > 0, is -0.005 m at x = -1 m").endswith(
        "must be > 0, is -5 mm at x = -1 m")
    assert format_error("punches[1].coating[0].thickness: must be > 0, is 0 m at x = 0.5 m"
                        ).endswith("is 0 mm at x = 0.5 m")


def test_format_error_says_a_refused_value_in_the_unit_of_its_box():
    # the coating's modulus box is in MPa and read "is 0 kPa"; the base's in GPa and its
    # thickness, age and the half-width read "got 0", "got -1" with no unit
    assert format_error("coating[0].modulus: must be > 0, is 0 Pa at x = -1 m").endswith(
        "must be > 0, is 0 MPa at x = -1 m")
    assert format_error("base.creep.modulus: must be > 0, got 0").endswith("got 0 GPa")
    assert format_error("base.creep.modulus_final: must be > 0, got -3e+10 (final)"
                        ).endswith("got -30 GPa (final)")
    assert format_error("base.thickness: must be > 0, got -1").endswith("got -1 m")
    # the bounds in the box's unit too, without the reminder that the file's are in Pa
    assert format_error("coating[0].modulus: must be >= 10000, is 800 Pa at x = -1 m (moduli "
                        "are in Pa: 800 MPa is 8e8, 33 GPa is 3.3e10)").endswith(
        "must be >= 0.01 MPa, is 0.0008 MPa at x = -1 m")
    assert format_error("base.creep.modulus: the base's modulus at loading E0 is 30 Pa, "
                        "outside [10000, 1e+13] Pa (moduli are in Pa: 800 MPa is 8e8)"
                        ).endswith("E0 is 3e-08 GPa, outside [1e-05, 10000] GPa")
    assert format_error("base.age_at_loading: must be > 0, got -3").endswith("got -3 days")
    assert format_error("punch.half_width: must be > 0, got 0").endswith("got 0 m")
    # C∞'s box is in 1/GPa (it read "got -1e-09" for a box showing -1); the time span's in
    # days, the wavelength's in m (they read "got 0", "is 0")
    assert format_error("base.creep.compliance: must be >= 0, got -1e-09: a negative value "
                        "makes the compliance decrease in time, which is not creep"
                        ).endswith("got -1 1/GPa: a negative value makes the compliance "
                                   "decrease in time, which is not creep")
    assert format_error("base.creep.compliance_final: must be >= 0, got -1e-09").endswith(
        "got -1 1/GPa")                             # (Arutyunyan's C∞, the same box)
    assert format_error("times.end: must be > 0, got 0").endswith("got 0 days")
    assert format_error("punch.shape.wavelength: must be > 0, is 0").endswith("is 0 m")


def test_format_error_names_the_field_in_words():
    assert describe_field("coating[1].thickness") == "Coating layer 2, thickness"
    assert describe_field("base.creep.rate") == "Base, creep, rate"
    assert format_error("coating[0].poisson: must be < 0.5, got 0.6") == (
        "Coating layer 1, poisson (coating[0].poisson): must be < 0.5, got 0.6")
    assert format_error("no field here") == "no field here"


# ----------------------------------------------------------------- caching of stages


def test_moving_a_load_reuses_every_geometric_stage(stage_evaluations):
    state = small(ExplorerState())
    state.load_scene(PRESETS["eccentric_creep"])
    state.time_count = 8
    controller = SolveController(state, executor=None)
    controller.request()
    first = controller.view
    before = dict(first.info["builds"])
    assert "grid" in before and "modal" in before

    for force in (700.0, 720.0, 740.0):
        state.loading.histories["force"].value = force
    view = controller.view
    assert view is not first and controller.error == ""
    assert view.values["force"][0] == pytest.approx(740e3)
    assert view.values["settlement"][-1] != pytest.approx(first.values["settlement"][-1])
    # counted on the prepared geometry the solves share: nothing geometric built again
    assert [view.info["builds"].get(k) for k in GEOMETRIC_STAGES] == [
        before.get(k) for k in GEOMETRIC_STAGES]
    for q in GEOMETRIC_STAGES:
        assert view.info["stages"].get(q, {"cached": True})["cached"], q

    # a change of geometry does build again (the counter is live)
    state.base.thickness = 5.0
    assert controller.view.info["stages"]["grid"]["cached"] is False


# ------------------------------------------------------------- threads and staleness


def test_older_results_never_replace_newer_ones():
    state = small(ExplorerState())
    gate = threading.Event()
    calls: list[float] = []

    def slow_first(scene):
        calls.append(scene["loading"]["force"])
        if len(calls) == 1:
            gate.wait(10)
        return solve(scene)

    with ThreadPoolExecutor(2) as pool:
        controller = SolveController(state, solve=slow_first, executor=pool)
        for force in (100.0, 200.0, 300.0, 400.0):
            state.loading.histories["force"].value = force
        assert controller.busy
        gate.set()
        assert controller.wait(60)
    # requests made while a solve ran collapse into the newest one
    assert calls == [100e3, 400e3]
    assert controller.view.values["force"][0] == pytest.approx(400e3)
    assert not controller.busy and controller.error == ""


def test_a_late_old_result_is_dropped():
    state = small(ExplorerState())
    controller = SolveController(state, executor=None, auto=False)
    old_scene = state.to_scene()
    controller.request()
    state.loading.histories["force"].value = 900.0
    controller.request()
    newest = controller.view
    controller._deliver(1, controller._compute(old_scene))  # a straggler arrives
    assert controller.view is newest


def test_results_arrive_through_the_dispatcher():
    """A result solved on a thread of the pool reaches the page through the dispatcher
    (the event loop's turn); one kept already is shown at once, by the caller, in the
    same call (and so in the same message to the page as the change that asked)."""
    RESULTS.clear()
    state = small(ExplorerState())
    delivered: list[Any] = []

    def dispatch(callback):
        delivered.append(threading.current_thread().name)
        callback()

    with ThreadPoolExecutor(1, thread_name_prefix="worker") as pool:
        controller = SolveController(state, executor=pool, dispatch=dispatch)
        controller.request()
        assert controller.wait(60)
        assert delivered and delivered[0].startswith("worker")
        assert controller.view is not None
        first = controller.view
        state.loading.histories["force"].value *= 1.5
        assert controller.wait(60)
        solved = len(delivered)
        state.loading.histories["force"].value /= 1.5   # back to a scene solved before
        assert controller.view is not first and controller.view.scene == first.scene
        assert controller.view.info["reused"] and not controller.busy
        assert len(delivered) == solved


# ------------------------------------------------------------------------- links


def test_link_round_trip_is_compact():
    for scene in PRESETS.values():
        text = encode_scene(scene)
        assert len(text) < 2000
        assert all(c.isalnum() or c in "-_." for c in text)
        assert decode_scene(text) == scene


@pytest.mark.parametrize("value, reason", [
    ("", "empty"),
    ("2.abc", "unknown format"),
    ("1.%%%", "base64"),
    ("1.AAAA", "damaged"),
    ("1." + "A" * 7000, "too long"),
])
def test_bad_links_are_refused_with_a_reason(value, reason):
    with pytest.raises(ValueError, match=reason):
        decode_scene(value)


def test_link_bombs_and_non_objects_are_refused():
    import base64

    def pack(data: bytes) -> str:
        return "1." + base64.urlsafe_b64encode(zlib.compress(data, 9)).decode().rstrip("=")

    with pytest.raises(ValueError, match="too large"):
        decode_scene(pack(b" " * 1_000_000))
    with pytest.raises(ValueError, match="not a JSON object"):
        decode_scene(pack(b"[1, 2]"))
    with pytest.raises(ValueError, match="not valid JSON"):
        decode_scene(pack(b"{nope"))


def test_app_uses_a_good_link_and_falls_back_on_a_bad_one(explorer_app):

    scene = json.loads(json.dumps(PRESETS["worn_coating"]))
    app = explorer_app(query={"scene": encode_scene(scene)})
    assert app.screen.notice == ""
    assert app.state.scene_name == scene["name"]
    assert app.controller.view is not None

    scene["coating"][0]["modulus"] = -1.0
    app = explorer_app(query={"scene": encode_scene(scene)})
    assert "coating[0].modulus" in app.screen.notice and "default" in app.screen.notice
    assert app.state.scene_name == PRESETS["uniform_flat"]["name"]
    assert app.controller.view is not None and app.controller.error == ""

    app = explorer_app(query={"scene": "1.garbage!"})
    assert "link" in app.screen.notice and app.controller.view is not None


def release(widget, value):
    """What a browser sends when a slider is let go at ``value``."""
    widget.value = value
    with param.edit_constant(widget):
        widget.value_throttled = value


def test_app_widgets_follow_and_drive_the_state(monkeypatch, explorer_app):
    from explorer import app as app_module

    # solves slower than the live threshold: geometry sliders apply on release only
    monkeypatch.setattr(app_module, "LIVE_SOLVE_S", 0.0)
    app = explorer_app()
    app.scene_tab.preset.value = "patched_insert"
    assert app.state.loading.statement == "settlement + tilt given"
    assert app.scene_tab.statement.value == "settlement + tilt given"
    assert app.controller.view.scene["name"] == PRESETS["patched_insert"]["name"]
    assert "Given settlement" in app.scene_tab.history_editors[0].title.object
    # a load slider writes while dragging (value), a geometry slider on release
    editor = app.scene_tab.history_editors[0]
    editor.value.value = 0.06
    assert app.state.loading.histories["settlement"].value == pytest.approx(0.06)
    app.base_tab.base_thickness.value = 3.5
    assert app.state.base.thickness != 3.5
    release(app.base_tab.base_thickness, 3.5)
    assert app.state.base.thickness == pytest.approx(3.5)
    # solves faster than the threshold (the last one measured): every drag step applies
    monkeypatch.setattr(app_module, "LIVE_SOLVE_S", float("inf"))
    app.base_tab.base_thickness.value = 3.6
    assert app.state.base.thickness == pytest.approx(3.6)
    # bad input: message in the alert, plots keep the last good result
    view = app.controller.view
    release(app.coating_tab.thickness_editor.mean, -1.0)
    assert app.results.alert.visible and "coating[0].thickness" in app.results.alert.object
    assert app.controller.view is view
    # downloads hold what is on screen
    assert app.files_tab._scene_file().getvalue().strip().startswith("{")
    assert json.loads(app.files_tab._scene_file().getvalue()) == view.scene
    csv = asyncio.run(app.files_tab._csv_file()).getvalue()
    assert csv.startswith("# coated-punch explorer") and "\ntime_day,settlement_mm," in csv


# ------------------------------------------------------------------ pressure shading


def test_negative_intervals():
    x = np.linspace(-1, 1, 5)                       # -1, -0.5, 0, 0.5, 1
    assert negative_intervals(x, np.array([1, 1, 1, 1, 1.0])) == []
    assert negative_intervals(x, np.array([-1, 1, 1, 1, -1.0])) == [(-1.0, -0.75),
                                                                   (0.75, 1.0)]
    assert negative_intervals(x, np.array([1, -1, -1, 1, 1.0])) == [(-0.75, 0.25)]


def test_time_is_quick_to_scrub():
    """Moving the time slider only slices arrays that already exist (no solve)."""
    state = small(ExplorerState())
    controller = SolveController(state, executor=None)
    controller.request()
    view = controller.view
    solves = controller.solves
    assert view.pressure.shape == (len(view.x), len(view.times))
    for i in range(len(view.times)):
        view.negative_intervals(i)
    assert controller.solves == solves


def test_scene_files_load_and_bad_files_explain_themselves(explorer_app):

    app = explorer_app()
    scene = PRESETS["rounded_graded"]
    app.files_tab.load_file.filename = "rounded.json"
    app.files_tab.load_file.value = json.dumps(scene).encode()
    assert app.screen.notice == ""
    assert app.state.n_layers == 3 and app.coating_tab.layer.options == ["1", "2", "3"]
    assert app.controller.view.scene["name"] == scene["name"]
    shown = app.controller.view

    app.files_tab.load_file.value = b"{not json"
    assert "not valid JSON" in app.screen.notice
    bad = json.loads(json.dumps(scene))
    bad["base"]["thickness"] = -1
    app.files_tab.load_file.value = json.dumps(bad).encode()
    assert "base.thickness" in app.screen.notice
    assert app.controller.view is shown and app.state.n_layers == 3

    app.punch_tab.shape_file.filename = "shape.csv"
    app.punch_tab.shape_file.value = b"x,f\n-0.5,0.00002\n0,0\n0.5,0.00001\n"
    assert app.state.punch.shape == "custom" and app.controller.error == ""
    assert "shape.csv" in app.punch_tab.shape_note.object
    app.punch_tab.shape_file.value = b"x,f\n-0.5,abc\n0,0\n"
    assert "punch.shape" in app.screen.notice and "line 2" in app.screen.notice


def test_a_value_refused_beside_an_earlier_refusal_is_named_first(explorer_app):
    """With a coating typed 0 mm thick (refused), a base thickness of -1 m typed next read
    again "coating thickness must be > 0", the value just typed not named; and a Poisson
    ratio of 0.7 then a coating of 0 mm named the coating alone. The newest value's fault
    comes first, then the others still in the way; a mended one is no longer named."""
    app = explorer_app()
    coating, base = app._view("coating"), app._view("base")
    thickness, poisson = coating.thickness_editor.mean._value_edit, base.base_poisson._value_edit
    coating_fault = "Coating layer 1, thickness (coating[0].thickness): must be > 0"
    base_fault = "Base, thickness (base.thickness): must be > 0 m, got -1 m"
    poisson_fault = "Base, poisson (base.poisson): must be in (-1, 0.5), got 0.7"
    thickness.value = 0.0
    assert app.controller.error.startswith(coating_fault), app.controller.error
    base.base_thickness._value_edit.value = -1.0
    error = app.controller.error
    assert error.startswith(base_fault + ". Also still not accepted: " + coating_fault), error
    base.base_thickness._value_edit.value = 4.0     # the base mended: the coating alone
    assert app.controller.error.startswith(coating_fault), app.controller.error
    assert "Also" not in app.controller.error
    thickness.value = 20.0
    assert app.controller.error == ""
    poisson.value = 0.7
    assert app.controller.error == poisson_fault
    thickness.value = 0.0
    error = app.controller.error
    assert error.startswith(coating_fault) and error.endswith(
        "Also still not accepted: " + poisson_fault), error
    thickness.value = 20.0                          # the coating mended: the ratio alone
    assert app.controller.error == poisson_fault
    # values typed since the result on screen and taken stay as typed: an end of the time
    # span typed, then a start past the old end, is not the start's fault (a review)
    app.state.time_end = 5000.0
    app.state.time_start = 1000.0
    assert app.controller.error == poisson_fault, app.controller.error
    poisson.value = 0.2
    assert app.controller.error == "" and app.controller.view is not None


def test_a_value_refused_on_a_scene_of_several_punches_is_named_first():
    # the scene of several punches was checked as one of one punch, and every refusal
    # read "Punches (punches): a scene of several punches is read by ..." (a review)
    import copy

    from core.scene import punches_from_dict
    from explorer.solving.controller import newest_fault

    good = presets()["new_footing_beside_old"]
    before = copy.deepcopy(good)
    before["base"]["poisson"] = 0.7
    now = copy.deepcopy(before)
    now["punches"][1]["half_width"] = -1.0
    with pytest.raises(ValueError) as refused:
        punches_from_dict(now)
    error = format_error(str(refused.value))
    assert newest_fault(error, good, before, now) == (
        "Punch 2, half width (punches[1].half_width): must be > 0 m, got -1 m. Also still "
        "not accepted: Base, poisson (base.poisson): must be in (-1, 0.5), got 0.7")


def test_a_refusal_on_screen_ends_when_a_value_is_taken(explorer_app):
    """"Value not accepted: force P [kN/m]: a number is needed (the box was empty); it
    stays 500" stayed above the plots after 600 was typed and solved (and after an undo
    or a reset)."""
    app = explorer_app()
    box = app.scene_tab.history_editors[0].value._value_edit
    box.value = None                  # the box emptied
    assert app.screen.notice.startswith("Value not accepted: ") and "stays" in \
        app.screen.notice
    app.scene_tab.history_editors[0].value.value = 600.0
    assert app.screen.notice == ""
    box.value = None
    assert app.screen.notice.startswith("Value not accepted: ")
    app.history.undo()                # an undo takes a scene too
    assert app.screen.notice == ""
    # a notice of another kind (a file, a link) is not a refusal: it stays
    app.screen.notice = "The file 'x.json' is not text in UTF-8 (a scene file is JSON)."
    app.scene_tab.history_editors[0].value.value = 650.0
    assert app.screen.notice.startswith("The file 'x.json'")


def test_every_emptied_number_box_says_so(explorer_app):
    """The force box emptied said "a number is needed (the box was empty)", the coating
    thickness's and the notional size's said nothing (the latter stayed empty while the
    scene kept 300 mm: a teacher's audit)."""
    app = explorer_app()
    coating = app._view("coating")
    coating.thickness_editor.mean._value_edit.value = None
    assert app.screen.notice == ("Value not accepted: thickness [mm]: a number is needed "
                                 "(the box was empty); it stays 20"), app.screen.notice
    app = explorer_app("young_concrete_50_years")
    size = app._view("base").code_creep.notional_size
    size.value = None
    assert app.screen.notice == ("Value not accepted: notional size h = 2A/u [mm]: a number "
                                 "is needed (the box was empty); it stays 300"), \
        app.screen.notice


def test_the_eccentricity_box_emptied_says_so_and_shows_the_value_kept(explorer_app):
    # it stayed blank, nothing said (an audit), where every other box says so
    app = explorer_app("eccentric_creep", solved=True)
    eccentricity = app.scene_tab.eccentric_load.slider
    eccentricity._value_edit.value = None
    assert app.screen.notice == ("Value not accepted: eccentricity e = M/P [m] (sets the "
                                 "moment): a number is needed (the box was empty); it stays "
                                 "0.15"), app.screen.notice
    assert eccentricity.value == 0.15
    assert app.state.loading.histories["moment"].value == 120.0


# (no NaN: the page sends an emptied box's NaN, which Panel reads as None)
@pytest.mark.parametrize("typed", [math.inf, -math.inf])
def test_a_number_that_is_not_finite_is_refused_in_every_kind_of_box(explorer_app, typed):
    """"1e400" typed in the force box (Infinity in the page) reached the scene state: the
    answer was "not solved", and the page's script widened the handle's range to it,
    where noUiSlider threw and cut the server's messages short (a user's audit: the
    preset selector, reset and undo then did nothing, and the page showed parts of two
    scenes). Refused as an emptied box is: said, the value kept in the box and the
    state, the answer on screen kept; in the Check tab too (a limit of infinity was taken
    unsaid: never checked)."""
    from explorer.views.widgets import FINITE_WIDEN_JS

    app = explorer_app("eccentric_creep", solved=True)
    shown = app.controller.view
    force = app.scene_tab.history_editors[0].value
    force._value_edit.value = typed
    assert app.screen.notice == ("Value not accepted: force P [kN/m]: must be a finite "
                                 f"number, got {typed}; it stays 800"), app.screen.notice
    assert force.value == 800.0 and app.state.loading.histories["force"].value == 800.0
    assert app.controller.view is shown and app.controller.error == ""
    eccentricity = app.scene_tab.eccentric_load.slider
    eccentricity._value_edit.value = typed
    assert app.screen.notice == ("Value not accepted: eccentricity e = M/P [m] (sets the "
                                 f"moment): must be a finite number, got {typed}; it stays "
                                 "0.15"), app.screen.notice
    assert eccentricity.value == 0.15
    assert app.state.loading.histories["moment"].value == 120.0
    check = app.check_tab
    check.allowable_pressure.value = 2000.0
    check.allowable_pressure.value = typed
    assert app.screen.notice.startswith("Value not accepted: allowable bearing pressure "
                                        "[kPa]: must be a finite number >= 0"), \
        app.screen.notice
    assert app.limits.allowable_pressure == 2000.0
    check.eccentricity.value = typed
    assert "must be a finite number" in app.screen.notice
    assert app.state.loading.histories["moment"].value == 120.0
    # the page's own script widens the handle's range to finite numbers only
    from panel.links import Callback

    scripts = [c.code["value"] for c in Callback.registry.get(force._value_edit, [])]
    assert scripts == [FINITE_WIDEN_JS]


def test_a_load_slider_returns_to_its_range_after_a_large_value(explorer_app):
    """1e6 kN/m typed into the force box left the slider at 0 to 2e6 for good (a pixel
    ~3,000 kN/m), through undo and reset."""
    app = explorer_app()
    slider = app.scene_tab.history_editors[0].value
    home = (slider.start, slider.end)
    assert home[0] <= 500.0 <= home[1]
    slider._value_edit.value = 1e6              # typed: the slider widens to show it
    assert app.state.loading.histories["force"].value == 1e6
    assert slider.end >= 1e6
    slider._value_edit.value = 500.0
    assert app.state.loading.histories["force"].value == 500.0
    assert (slider.start, slider.end) == home
    app.state.loading.histories["force"].value = 2e6   # a file's or a link's value
    assert slider.end >= 2e6 and slider.value == 2e6
    app.history.undo()
    assert (slider.start, slider.end) == home


def test_a_statement_chosen_on_the_page_starts_from_the_answer_on_screen(explorer_app) -> None:
    """Switching to "settlement + tilt given" set δ 0.05 mm and α 0 whatever the answer
    was (a teacher's audit): another scene. The newly given quantities start at the
    answer's values at the last output time; on an elastic base the answer is the same."""
    from core.presets import read_preset

    app = explorer_app(scene=read_preset("bare_layer"), solved=True)   # elastic
    before = app.controller.view
    assert before.given == ("force", "moment")
    app.scene_tab.statement.value = "settlement + tilt given"
    assert app.controller.wait(60) and app.controller.error == ""
    after = app.controller.view
    assert after.given == ("settlement", "tilt")
    for q in ("settlement", "tilt", "force", "moment"):
        np.testing.assert_allclose(after.display(q)[-1], before.display(q)[-1],
                                   rtol=1e-6, atol=1e-12)


def test_a_statement_chosen_says_where_its_given_values_came_from(explorer_app):
    """Switching the statement took the answer's values as the new given loads, silently:
    force and moment 800 and 120 came back as 740.27 and 110.99 after three switches on
    a creeping base (an audit). The page says what it took, until a given load changes."""
    app = explorer_app("eccentric_creep", solved=True)
    tab = app.scene_tab
    tab.statement.value = "settlement + tilt given"
    assert app.controller.wait(60)
    note = tab.unknowns_note.object
    assert "Now given, held at the answer's values at t = 1000 days" in note
    assert "settlement δ = 0.087475 mm" in note and "a switch back takes" in note
    app.state.loading.histories["settlement"].value = 0.09
    assert "Now given" not in tab.unknowns_note.object


def test_a_sine_chosen_after_a_step_starts_from_a_scene_that_solves(explorer_app):
    """An audit: history "step" then "sine" took the value after the step (1000 kN/m)
    as the sine's amplitude about 500 ("the punch is pulled away"); and on the 50-year
    preset the sine's 10-day period (1826 periods) ran 28 s into the time stepping's
    limit and was refused. A kind chosen on the page starts from its own values; a
    sine's period is at most the span over SINE_PERIODS."""
    from explorer.model.loading_state import SINE_PERIODS, SINE_SHARE, STEP_FACTOR

    app = explorer_app()
    force = app.state.loading.histories["force"]
    force.kind = "step"
    assert force.second == STEP_FACTOR * force.value == 1000.0
    force.kind = "sine"
    assert force.second == SINE_SHARE * force.value == 100.0 and force.time == 10.0
    app.controller.solve_now()
    assert app.controller.error == ""
    force.kind = "ramp"                       # a ramp from nothing up to the force
    assert force.second == 0.0
    # a sine chosen again after the force was typed lower starts from the new force (it
    # kept an amplitude of 100 about 50: refused, a review)
    force.kind = "constant"
    force.value = 50.0
    force.kind = "sine"
    assert force.second == SINE_SHARE * 50.0
    app.load_scene(json.loads(json.dumps(presets()["young_concrete_50_years"])))
    force = app.state.loading.histories["force"]
    force.kind = "sine"
    assert force.time == pytest.approx(18262.5 / SINE_PERIODS, rel=1e-3)
    app.controller.solve_now()
    assert app.controller.error == "", app.controller.error
    assert app.controller.view.scene["loading"]["force"]["kind"] == "sine"


def test_a_step_chosen_on_the_page_starts_from_a_scene_that_solves(explorer_app):
    """An engineer's audit: choosing the force history "step" on the lift-off preset set
    "after the step 0 kN/m at 10 days", refused at once ("M = 480 kN·m/m with no
    force"); the step now doubles the force, and the page solves it."""
    app = explorer_app()
    app.load_scene(json.loads(json.dumps(presets()["eccentric_footing_liftoff"])))
    app.controller.solve_now()
    force = app.state.loading.histories["force"]
    force.kind = "step"
    assert force.second == 2 * force.value == 1600.0
    app.controller.solve_now()
    assert app.controller.error == "" and app.controller.view.scene["loading"]["force"] == \
        {"kind": "step", "values": [8e5, 1.6e6], "breaks": [10.0]}
    # a file's step keeps its own values (read, not chosen)
    force.load_spec({"kind": "step", "values": [8e5, 0.0], "breaks": [5.0]})
    assert force.second == 0.0


def test_every_slider_of_the_base_and_the_coating_names_its_unit(explorer_app):
    # the base's "Poisson ratio" had no "[-]" where the coating's had (an audit)
    import panel as pn

    app = explorer_app()
    for tab in ("base", "coating"):
        sliders = app._view(tab).content().select(pn.widgets.EditableFloatSlider)
        assert sliders
        for widget in sliders:
            assert widget.name.endswith("]"), (tab, widget.name)
