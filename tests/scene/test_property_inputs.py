"""Generated bad input at two entry points: scene dicts and the explorer's widget values.

Every example must end one of two ways: refused with a ``ValueError`` whose message starts
with the path of a scene field (``coating[0].thickness: ...``), or solved with finite
histories and pressure. Nothing may crash with another exception or hang. Hypothesis
draws at least 500 scenes and 500 widget combinations per run; the scenes keep few output
times and a loose tolerance so that the solved ones cost tens of milliseconds.
"""

from __future__ import annotations

import contextlib
import copy
import json
import math
import os
import re
import signal
import time
from collections import Counter
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from core.limits import MAX_SOLVE_CPU_SECONDS
from core.scene import scene_from_dict, solve
from core.scene.files import parse_scene_json
from explorer.model import QUANTITIES, STATEMENTS, ExplorerState
from explorer.solving import SolveController

pytestmark = pytest.mark.timeout(600)

#: Examples per test; PROPERTY_EXAMPLES=5000 digs deeper by hand (the suite keeps 500).
EXAMPLES = max(500, int(os.environ.get("PROPERTY_EXAMPLES", "500")))

#: A valid scene; every example changes a few of its fields.
BASE: dict[str, Any] = {
    "schema_version": 1,
    "name": "generated",
    "description": "",
    "punch": {"half_width": 1.0, "shape": 0.0},
    "coating": [{"thickness": 0.01, "modulus": 5.0e8, "poisson": 0.3}],
    "base": {"thickness": 4.0, "poisson": 0.2, "age_at_loading": 28.0,
             "creep": {"model": "exponential", "modulus": 3.0e10, "compliance": 3.0e-11,
                       "rate": 0.05}},
    "loading": {"force": 5.0e5, "moment": 0.0},
    "times": {"end": 100.0, "count": 3, "spacing": "linear"},
    "solver": {"tol": 1e-3},
}

#: A message names a field when it starts with a path of the scene schema (an unknown
#: key may end the path: ``base.creep.colour: unknown field for model 'elastic'``).
FIELD = re.compile(r"^(scene|schema_version|name|description|punch|coating|base|loading|"
                   r"times|solver)([.\[][^\n]*?)?: \S")

#: Per-example guard against hangs, not a speed test: the slowest of 10000 examples
#: measured 0.7 s (a cold solve of a generated geometry). Before the scene checks bounded
#: the work, generated scenes ran 6 to 14 s (extreme creep, a / H = 468); a wavy punch 28 m
#: wide (47 contact zones) ran over 12 minutes before the elastic zone solves checked the
#: solve's CPU bound. A solve may take up to that bound (then it is refused naming a
#: field), so the guard is the bound with room for a loaded machine's wall clock.
HANG_SECONDS = 2 * MAX_SOLVE_CPU_SECONDS


class Hang(Exception):
    """An example ran past :data:`HANG_SECONDS`."""


@contextlib.contextmanager
def hang_guard(seconds: float = HANG_SECONDS) -> Iterator[None]:
    """Raise :class:`Hang` in the block after ``seconds``; an outer alarm (pytest-timeout
    uses the same signal) is put back afterwards with the time it had left."""
    def alarm(signum: int, frame: Any) -> None:
        raise Hang(f"no answer after {seconds} s")

    start = time.monotonic()
    previous = signal.signal(signal.SIGALRM, alarm)
    outer, interval = signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
        if outer > 0:
            left = max(outer - (time.monotonic() - start), 1e-3)
            signal.setitimer(signal.ITIMER_REAL, left, interval)


def assert_names_a_field(message: str) -> None:
    assert "\n" not in message, message
    assert FIELD.match(message), f"message does not start with a field path: {message!r}"


def assert_finite(result: Any) -> None:
    for q in QUANTITIES:
        values = np.asarray(getattr(result, q), dtype=float)
        assert np.all(np.isfinite(values)), f"{q} is not finite: {values}"
    assert np.all(np.isfinite(result.pressure_on_grid)), "pressure is not finite"


# ------------------------------------------------------------------------- strategies

SPECIAL = [0, 0.0, -0.0, -1, -1.0, 1, 0.5, 0.4999999, -0.9999999, 1e-300, -1e-300, 5e-324,
           1e300, -1e300, 1.7e308, math.inf, -math.inf, math.nan, 10**400, -10**400, 2**63,
           True, False, None, "", "1", "nan", "<script>alert(1)</script>", [], {}, [1, 2],
           {"kind": "constant"}, {"kind": "no such kind"}, {"expr": "x"}]

junk = st.one_of(
    st.sampled_from(SPECIAL),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-10**6, max_value=10**6),
    st.text(max_size=12),
    st.lists(st.floats(allow_nan=False, allow_infinity=False, width=32), max_size=3),
)
#: Mostly plausible numbers, sometimes anything.
plausible = st.one_of(st.floats(min_value=-2.0, max_value=2.0, allow_nan=False),
                      st.floats(min_value=1e-3, max_value=1e10), junk)
positive = st.one_of(st.floats(min_value=1e-4, max_value=1e-1), st.floats(min_value=1e6,
                                                                           max_value=1e11),
                     junk)

FORMULA_PARTS = ["x", "t", "tau", "1", "0.01", "2", "1e-3", "pi", "+", "-", "*", "/", "**",
                 "(", ")", "sin(", "exp(", "abs(", "sign(", "min(x, ", "sqrt(", "log(",
                 "__import__('os')", "x.__class__", "lambda: 1", "[i for i in x]", ";", "9**9**9",
                 "<img src=x onerror=alert(1)>"]
formulas = st.one_of(
    st.lists(st.sampled_from(FORMULA_PARTS), min_size=1, max_size=8).map(" ".join),
    st.sampled_from(["0.01 + 0.001 * x", "0.01 * (1 + 0.2 * sin(3 * x))", "1e9 * exp(-x**2)",
                     "0.3 + 0.1 * x", "5e5 * (1 + t / 100)", "-0.05 * exp(-0.1 * (t - tau))",
                     "0.01 * exp(-(t - tau))", "1 / (t - tau)", "0.01 * heaviside(x)",
                     "(" * 30 + "x" + ")" * 30, "x" + " + x" * 300]),
)


def _pairs(values: st.SearchStrategy) -> st.SearchStrategy:
    return st.lists(st.one_of(st.tuples(values, values).map(list), junk), min_size=0,
                    max_size=6)


def _profile_kind(kind: str) -> st.SearchStrategy:
    fields = {
        "constant": {"value": plausible},
        "linear": {"start": plausible, "end": plausible},
        "step": {"values": st.lists(plausible, max_size=4),
                 "breaks": st.lists(st.floats(-1.5, 1.5), max_size=3)},
        "sine": {"mean": plausible, "amplitude": plausible, "wavelength": plausible,
                 "phase": plausible},
        "polynomial": {"coefficients": st.lists(plausible, max_size=18)},
        "bump": {"mean": plausible, "amplitude": plausible, "center": plausible,
                 "width": plausible},
        "ramp": {"start": plausible, "end": plausible, "duration": plausible},
        "table": {"points": _pairs(st.floats(-1.5, 1.5)),
                  "interpolation": st.sampled_from(["linear", "step", "pchip", "cubic", 3])},
        "expr": {"expr": st.one_of(formulas, junk)},
    }[kind]
    # every field may be missing, and an unknown one may appear
    return st.fixed_dictionaries(
        {"kind": st.just(kind)},
        optional={**fields, "colour": junk},
    )


profiles = st.one_of(
    plausible,
    st.sampled_from(["constant", "linear", "step", "sine", "polynomial", "bump", "ramp",
                     "table", "expr"]).flatmap(_profile_kind),
    st.fixed_dictionaries({"expr": st.one_of(formulas, junk)}),
)

creeps = st.one_of(
    junk,
    st.fixed_dictionaries({"model": st.just("elastic")}, optional={"modulus": positive}),
    st.fixed_dictionaries({"model": st.just("exponential"), "modulus": positive,
                           "compliance": plausible, "rate": plausible}),
    st.fixed_dictionaries({"model": st.just("arutyunyan"), "modulus_final": positive,
                           "beta": plausible, "alpha": plausible, "compliance_final": plausible,
                           "aging": plausible, "rate": plausible}),
    st.fixed_dictionaries({"model": st.just("prony"), "modulus": positive,
                           "terms": st.one_of(junk, st.lists(st.fixed_dictionaries(
                               {"compliance": plausible, "rate": plausible},
                               optional={"aging": plausible, "extra": junk}), max_size=3))}),
    st.fixed_dictionaries({"model": st.just("kernel"), "modulus": positive,
                           "expr": st.one_of(formulas, junk)}),
    st.fixed_dictionaries({"model": st.sampled_from(["viscous", "<b>x</b>", 1])}),
)

times_specs = st.one_of(
    junk,
    st.fixed_dictionaries({}, optional={"end": plausible,
                                        "count": st.one_of(st.integers(-2, 4),
                                                           st.sampled_from([0, 2001, 10**9,
                                                                            2.5, "3"])),
                                        "spacing": st.sampled_from(["linear", "log", "cubic",
                                                                    None]),
                                        "step": junk}),
    st.lists(st.one_of(st.floats(-10, 1e3), junk), max_size=5),
)

loadings = st.dictionaries(
    st.sampled_from([*QUANTITIES, "forse", "torque"]), profiles, max_size=3)

LEAF_PATHS: list[tuple[Any, ...]] = [
    ("schema_version",), ("name",), ("description",), ("punch", "half_width"),
    ("punch", "shape"), ("coating", 0, "thickness"), ("coating", 0, "modulus"),
    ("coating", 0, "poisson"), ("base", "thickness"), ("base", "poisson"),
    ("base", "age_at_loading"), ("base", "creep", "modulus"), ("base", "creep", "compliance"),
    ("base", "creep", "rate"), ("loading", "force"), ("loading", "moment"), ("times", "end"),
    ("times", "count"), ("times", "spacing"), ("solver", "tol"),
]
SCALABLE: list[tuple[Any, ...]] = [
    ("punch", "half_width"), ("coating", 0, "thickness"), ("coating", 0, "modulus"),
    ("base", "thickness"), ("base", "age_at_loading"), ("base", "creep", "modulus"),
    ("base", "creep", "compliance"), ("base", "creep", "rate"), ("loading", "force"),
    ("times", "end"),
]
OBJECT_PATHS: list[tuple[Any, ...]] = [(), ("punch",), ("coating", 0), ("base",),
                                       ("base", "creep"), ("loading",), ("times",),
                                       ("solver",)]

operations = st.one_of(
    st.tuples(st.just("set"), st.sampled_from(LEAF_PATHS), st.one_of(junk, profiles)),
    st.tuples(st.just("set"), st.sampled_from([("punch", "shape"), ("coating", 0, "thickness"),
                                               ("coating", 0, "modulus"),
                                               ("coating", 0, "poisson"), ("loading", "force"),
                                               ("loading", "moment")]), profiles),
    st.tuples(st.just("set"), st.just(("base", "creep")), creeps),
    st.tuples(st.just("set"), st.just(("times",)), times_specs),
    st.tuples(st.just("set"), st.just(("loading",)), loadings),
    st.tuples(st.just("set"), st.sampled_from(OBJECT_PATHS[1:]), junk),
    st.tuples(st.just("delete"), st.sampled_from(LEAF_PATHS + OBJECT_PATHS[1:]), st.none()),
    st.tuples(st.just("unknown"), st.sampled_from(OBJECT_PATHS),
              st.sampled_from(["hafl_width", "extra", "<img src=x onerror=alert(1)>", "__class__",
                               "kind"])),
    st.tuples(st.just("layers"), st.integers(0, 12), st.none()),
    # valid but extreme: a number of the base scene times 10**k
    st.tuples(st.just("scale"), st.sampled_from(SCALABLE), st.integers(-12, 12)),
)


def apply(scene: dict[str, Any], op: tuple[str, Any, Any]) -> None:
    """Apply one operation; one whose path an earlier operation removed is skipped."""
    action, path, value = op
    if action == "layers":
        # ``path`` is the number of layers: copies of the first one, whatever it holds
        layers = scene.get("coating")
        layer = layers[0] if isinstance(layers, list) and layers else BASE["coating"][0]
        scene["coating"] = [copy.deepcopy(layer) for _ in range(path)]
        return
    parents = path if action == "unknown" else path[:-1]
    target: Any = scene
    for key in parents:
        try:
            target = target[key]
        except (KeyError, IndexError, TypeError):
            return
    if action == "unknown":
        if isinstance(target, dict):
            target[value] = 1.0
        return
    key = path[-1]
    if action == "scale":
        if isinstance(target, dict) and isinstance(target.get(key), float):
            target[key] *= 10.0**value
        return
    if isinstance(target, list) and isinstance(key, int) and key < len(target):
        if action == "set":
            target[key] = copy.deepcopy(value)
    elif isinstance(target, dict):
        if action == "delete":
            target.pop(key, None)
        else:
            target[key] = copy.deepcopy(value)


def _build(ops: list[tuple[str, Any, Any]]) -> dict[str, Any]:
    scene = copy.deepcopy(BASE)
    for op in ops:
        apply(scene, op)
    return scene


bad_scenes = st.lists(operations, min_size=1, max_size=3).map(_build)


def _json_text(scene: dict[str, Any]) -> str | None:
    try:
        return json.dumps(scene)
    except (TypeError, ValueError, OverflowError):
        return None


# ------------------------------------------------------------------------- scene dicts


@pytest.mark.slow
def test_generated_bad_scenes_are_refused_or_solved() -> None:
    outcomes: Counter[str] = Counter()

    @settings(max_examples=EXAMPLES, deadline=None, database=None,
              suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much,
                                     HealthCheck.data_too_large])
    @given(scene=bad_scenes)
    def check(scene: dict[str, Any]) -> None:
        with hang_guard():
            try:
                built = scene_from_dict(scene)
            except ValueError as exc:
                assert_names_a_field(str(exc))
                outcome = "refused"
            else:
                try:
                    result = solve(built)
                except ValueError as exc:
                    assert_names_a_field(str(exc))
                    outcome = "refused by the solve"
                else:
                    assert_finite(result)
                    outcome = "solved"
            # the file path answers the same way as the dictionary
            text = _json_text(scene)
            if text is not None:
                try:
                    parse_scene_json(text, "generated.json")
                    as_file = "accepted"
                except ValueError as exc:
                    assert_names_a_field(str(exc))
                    as_file = "refused"
                assert (as_file == "refused") == (outcome == "refused"), (outcome, as_file)
        outcomes[outcome] += 1

    check()
    assert sum(outcomes.values()) >= EXAMPLES, outcomes
    # mostly bad input, and enough good input to exercise the solver
    assert outcomes["refused"] >= EXAMPLES // 2, outcomes
    assert outcomes["solved"] >= 20, outcomes


# ------------------------------------------------------------------------- widget values

#: Values a widget could hold: slider ranges, typed numbers, and garbage a crafted
#: websocket message could carry.
widget_numbers = st.one_of(
    st.floats(min_value=-5.0, max_value=500.0, allow_nan=False),
    st.sampled_from([0.0, -0.0, -1.0, 1e-300, 1e300, math.inf, -math.inf, math.nan, 0.5, 0.49,
                     True, 10**30]),
)

PUNCH_NUMBERS = ["half_width", "radius", "slope", "step_height", "step_position",
                 "land_height", "land_width", "wave_amplitude", "wave_length"]
BASE_NUMBERS = ["thickness", "poisson", "modulus", "age_at_loading", "compliance", "rate",
                "beta", "alpha", "aging"]
PROFILE_NUMBERS = ["mean", "amplitude", "position", "length"]
HISTORY_NUMBERS = ["value", "second", "time"]

widget_changes = st.one_of(
    st.tuples(st.just("punch"), st.sampled_from(PUNCH_NUMBERS), widget_numbers),
    st.tuples(st.just("punch"), st.just("shape"),
              st.sampled_from(["flat", "parabolic", "wedge", "stepped", "land", "wavy",
                               "custom", "oval"])),
    st.tuples(st.just("base"), st.sampled_from(BASE_NUMBERS), widget_numbers),
    st.tuples(st.just("base"), st.just("creep_model"),
              st.sampled_from(["elastic", "exponential", "arutyunyan", "custom", "glass"])),
    st.tuples(st.sampled_from(["layer0.thickness", "layer0.modulus", "layer0.poisson",
                               "layer1.thickness", "layer1.modulus"]),
              st.sampled_from(PROFILE_NUMBERS), widget_numbers),
    st.tuples(st.sampled_from(["layer0.thickness", "layer0.modulus", "layer1.thickness"]),
              st.just("kind"),
              st.sampled_from(["none", "linear", "step", "patch", "sine", "bump", "custom",
                               "spiral"])),
    st.tuples(st.sampled_from([f"history.{q}" for q in QUANTITIES]),
              st.sampled_from(HISTORY_NUMBERS), widget_numbers),
    st.tuples(st.sampled_from([f"history.{q}" for q in QUANTITIES]), st.just("kind"),
              st.sampled_from(["constant", "ramp", "step", "sine", "custom", "zigzag"])),
    st.tuples(st.just("loading"), st.just("statement"),
              st.sampled_from([*STATEMENTS, "force given"])),
    st.tuples(st.just("state"), st.just("n_layers"), st.sampled_from([1, 2, 3, 0, 11, 2.5])),
    st.tuples(st.just("state"), st.just("time_end"), widget_numbers),
    st.tuples(st.just("state"), st.just("time_count"),
              st.sampled_from([2, 3, 4, 0, 1, -1, 2001, 10**9, 2.5])),
    st.tuples(st.just("state"), st.just("time_spacing"), st.sampled_from(["linear", "log",
                                                                          "cubic"])),
    st.tuples(st.just("state"), st.just("tol"), st.sampled_from([1e-3, 1e-4, 0.5, 0.0])),
    st.tuples(st.just("state"), st.just("scene_name"),
              st.sampled_from(["", "<script>alert(1)</script>", "a" * 300, 7])),
)


def _target(state: ExplorerState, owner: str) -> Any:
    if owner == "state":
        return state
    if owner in ("punch", "base", "loading"):
        return getattr(state, owner)
    if owner.startswith("layer"):
        layer, profile = owner.split(".")
        return getattr(state.layers[int(layer[len("layer"):])], profile)
    return state.loading.histories[owner.split(".")[1]]


@pytest.mark.slow
def test_generated_widget_values_are_refused_or_solved() -> None:
    outcomes: Counter[str] = Counter()

    @settings(max_examples=EXAMPLES, deadline=None, database=None,
              suppress_health_check=[HealthCheck.too_slow])
    @given(changes=st.lists(widget_changes, min_size=1, max_size=6))
    def check(changes: list[tuple[str, str, Any]]) -> None:
        state = ExplorerState()
        state.param.update(time_count=3, tol=1e-3)
        with hang_guard():
            for owner, name, value in changes:
                try:
                    setattr(_target(state, owner), name, value)
                except ValueError as exc:
                    # the parameter refuses the value outright (a widget never holds it);
                    # the explorer shows this message as a notice
                    assert name in str(exc), str(exc)
                    outcomes["refused by a parameter"] += 1
            controller = SolveController(state, executor=None, auto=False)
            controller.solve_now()
        if controller.error:
            # the controller puts the field in words before the core's path:
            # "Coating layer 1, thickness (coating[0].thickness): must be > 0, ..."
            path = re.search(r"\(([^()]*)\):", controller.error)
            message = controller.error if path is None else \
                controller.error[path.start(1):].replace("):", ":", 1)
            assert not controller.error.startswith("The solver failed"), controller.error
            assert_names_a_field(message)
            outcomes["refused"] += 1
        else:
            view = controller.view
            assert view is not None
            for q in QUANTITIES:
                assert np.all(np.isfinite(view.values[q])), f"{q} is not finite"
            assert np.all(np.isfinite(view.pressure)) and np.all(np.isfinite(view.image))
            outcomes["solved"] += 1

    check()
    assert outcomes["refused"] + outcomes["solved"] >= EXAMPLES, outcomes
    assert outcomes["refused"] >= 50 and outcomes["solved"] >= 50, outcomes
