"""The engine registry behind solve_dimensionless(method=...): one protocol, one result type,
one info schema, one acceptance rule, the fallback as a loop."""

from __future__ import annotations

import numpy as np
import pytest

from core import ContactSolution, solve_dimensionless
from core.engines import ENGINES, get_engine, register_engine
from core.problem import INFO_KEYS, UnresolvedOperator, accepts
from tests.conftest import scene_file

ELASTIC = dict(lam=1.0, m=0.1, g=lambda x: 0.02 * x**2, times=[1.0, 2.0], force=1.0,
               moment=0.1, tol=1e-6)
# the collocation's cross-check is O(N steps^2): coarse panels keep it at ~0.1 s
COARSE = {"collocation": dict(panels_per_unit=4, edge_width=1e-2)}


def _solve(method: str, **changes):
    args = {**ELASTIC, **COARSE.get(method, {}), **changes}
    return solve_dimensionless(args.pop("lam"), args.pop("m"), args.pop("g"),
                               args.pop("times"), method=method, contact="full", **args)


def test_the_three_dimensionless_engines_are_registered():
    assert {"nystrom", "projection", "collocation"} <= set(ENGINES)
    for name, engine in ENGINES.items():
        assert engine.name == name and engine.success_margin >= 1.0


@pytest.mark.parametrize("method", sorted(ENGINES))
@pytest.mark.parametrize("creep", [False, True])
def test_every_engine_answers_with_one_result_type_and_the_common_info(method, creep):
    changes = {}
    if creep:
        changes = dict(kernel=lambda t, tau: -0.5 * np.exp(-0.5 * (t - tau)),
                       tol=1e-4, times=[1.0, 1.5, 2.0])
    sol = _solve(method, **changes)
    assert isinstance(sol, ContactSolution)
    missing = set(INFO_KEYS) - set(sol.info)
    assert not missing, missing
    assert sol.info["method"] == method and sol.info["contact"] == "full"
    assert sol.info["statement"] == 4 and sol.info["given"] == ["force", "moment"]
    assert sol.pressure(np.linspace(-1.0, 1.0, 5)).shape == (5, len(sol.times))
    # one acceptance rule, with the engine's margin
    tol = changes.get("tol", ELASTIC["tol"])
    engine = get_engine(method)
    assert sol.success, sol.message
    assert accepts(sol.info["error_estimate"], tol, engine.success_margin)
    assert "tol_not_met" not in sol.flags


def test_the_layered_engine_answers_with_the_same_result_type_and_info():
    """The exact layered kernel stays a scene-level engine (it needs the stack, which the
    dimensionless problem has collapsed into m), but answers like the others."""
    from core.engines.layered import solve_scene_layered
    from core.scene import scene_from_dict

    d = scene_file("uniform_flat")
    d["base"]["creep"] = {"model": "elastic", "modulus": 3.0e10}
    d["times"] = {"end": 10.0, "count": 2, "spacing": "linear"}
    scene = scene_from_dict(d)
    sol = solve_scene_layered(scene, scene.dimensionless)
    assert isinstance(sol, ContactSolution)
    assert not set(INFO_KEYS) - set(sol.info)
    assert sol.info["method"] == "layered"
    assert sol.info["success"] == accepts(sol.info["error_estimate"], scene.dimensionless.tol)


def test_an_unknown_method_is_refused_naming_the_registered_ones():
    with pytest.raises(ValueError, match="method: must be one of 'nystrom', 'projection', "
                                         "'collocation'"):
        _solve("magic")


@pytest.mark.parametrize(("method", "option"), [
    ("projection", {"time_points": 8}),
    ("nystrom", {"n_modes": 8}),
    ("nystrom", {"basis": "piecewise"}),
    ("nystrom", {"panels_per_unit": 4}),
    ("collocation", {"n_modes": 8}),
])
def test_an_option_the_engine_does_not_take_is_refused_naming_it(method, option):
    name = next(iter(option))
    with pytest.raises(ValueError, match=f"^{name}: not an option of the '{method}' engine"):
        _solve(method, **option)


def test_the_common_keywords_at_their_defaults_pass_any_engine():
    """``basis="graded"``, ``n_modes=None``, ``time_breaks=()`` ask nothing of an engine
    that does not take them."""
    for method in ("nystrom", "projection", "collocation"):
        sol = _solve(method, basis="graded", n_modes=None, time_breaks=())
        assert sol.info["method"] == method


def test_engine_options_reach_the_engine():
    from core.engines.collocation import solve_collocation

    direct = solve_collocation(1.0, 0.1, ELASTIC["g"], [1.0, 2.0], force=1.0, moment=0.1,
                               panels_per_unit=3, edge_width=2e-2)
    via = _solve("collocation", panels_per_unit=3, edge_width=2e-2)
    assert via.info["n_nodes"] == direct.info["n_nodes"] != _solve("collocation").info["n_nodes"]
    assert np.array_equal(via.settlement, direct.settlement)
    x = np.linspace(-1.0, 1.0, 7)
    assert np.array_equal(via.pressure(x), direct.pressure(x))
    projection = _solve("projection", n_modes=8, basis="global")
    assert projection.info["n_modes"] == 8 and projection.info["basis"] == "global"


class _Declining:
    """An engine that declines every problem, as the Nystrom engine declines an operator it
    cannot step in modal form."""

    name = "nystrom"
    prepare_options = ()
    solve_options = ("time_breaks",)
    success_margin = 1.0

    def prepare(self, geometry):
        return geometry

    def solve(self, prepared, inputs, *, time_breaks=()):
        raise UnresolvedOperator("operator: cannot be stepped (a test engine)")


def test_a_declining_default_engine_hands_over_to_the_next_in_turn(monkeypatch):
    monkeypatch.setitem(ENGINES, "nystrom", _Declining())
    args = {k: v for k, v in ELASTIC.items() if k not in ("lam", "m", "g", "times")}
    sol = solve_dimensionless(1.0, 0.1, ELASTIC["g"], [1.0, 2.0], time_breaks=[1.5], **args)
    assert sol.info["method"] == "projection" and sol.success
    assert sol.info["fallback"] == ("default engine declined (operator: cannot be stepped "
                                    "(a test engine)); projection answered")
    with pytest.raises(UnresolvedOperator):  # asked for by name: no one else answers
        solve_dimensionless(1.0, 0.1, 0.0, [1.0], method="nystrom", force=1.0, moment=0.0)


def test_register_engine_refuses_a_taken_name_and_an_incomplete_engine(monkeypatch):
    monkeypatch.setattr("core.engines.registry.ENGINES", dict(ENGINES))
    with pytest.raises(ValueError, match="registered already"):
        register_engine(get_engine("projection"))

    class NoMargin(_Declining):
        name = "other"
        success_margin = 0.5

    with pytest.raises(ValueError, match="success_margin"):
        register_engine(NoMargin())
