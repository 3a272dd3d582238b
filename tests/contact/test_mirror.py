"""A problem even in x is solved on the half x > 0 (core.contact.systems.Mirror): the
same answers as the whole problem, exactly even, on a rule made symmetric about 0."""

from __future__ import annotations

import copy

import numpy as np
import pytest

import core
from core.cache import clear_caches
from core.contact.bands import band_rule, even_rule, mirrored_bands
from core.contact.march import rule_mirror
from core.contact.step import Space
from core.contact.systems import Mirror, StepSolver, bordered_change, bordered_solve
from core.contact.zones import Resolution
from core.discretize import base_panels
from core.presets import read_preset

CENTRED = [{"force": 1.0, "moment": 0.0}, {"settlement": 0.02, "moment": 0.0},
           {"settlement": 0.02, "tilt": 0.0}, {"tilt": 0.0, "force": 0.8}]


def _even_sets(n: int) -> list[np.ndarray]:
    """Symmetric contact sets: a zone shrinking and growing at both ends, and two zones."""
    inside = np.arange(n)
    two = np.concatenate([inside[5:n // 2 - 8], inside[n // 2 + 8:n - 5]])
    return [inside[10:n - 10], inside[12:n - 12], inside[9:n - 9], two, inside[:]]


@pytest.mark.parametrize("given", CENTRED, ids=lambda g: "+".join(g))
def test_the_half_solves_the_whole_system(rule, given):
    """Every centred statement on symmetric contact sets, c/s drifting as in a march: the
    answers on the half (with kept factors) are the whole direct solve's within what
    the refinement promises (a residual of 1e-13 of b; measured 2e-15 of the largest q),
    the tilt exactly 0 and q exactly even; a change (a kink correction's) likewise."""
    op, m, x, w, rhs = rule
    mirror = Mirror.of(x, w, op, m, -rhs)
    assert mirror is not None and mirror.op.shape == (x.size // 2, x.size // 2)
    solver = StepSolver(mirror)
    for k, idx in enumerate(_even_sets(x.size)):
        c = 1.0 + 1e-3 * k
        q, delta, alpha = bordered_solve(op, m, x, w, c, 1.0, given, rhs, idx, solver)
        q_all, delta_all, _ = bordered_solve(op, m, x, w, c, 1.0, given, rhs, idx)
        scale = np.abs(q_all).max()
        assert np.abs(q - q_all).max() <= 1e-12 * scale
        assert delta == pytest.approx(delta_all, rel=1e-12, abs=1e-15)
        assert alpha == 0.0
        assert np.array_equal(q, q[::-1])
        loads = {name: 0.01 for name in given if name in ("force", "settlement")}
        change = {**{name: 0.0 for name in given}, **loads}
        d_rhs = 1e-3 * np.cos(x)
        dq, d_delta, d_alpha = bordered_change(op, m, x, w, c, 1.0, change, d_rhs, idx,
                                               solver.snapshot())
        dq_all, d_delta_all, _ = bordered_solve(op, m, x, w, c, 1.0, change, d_rhs, idx)
        assert np.abs(dq - dq_all).max() <= 1e-9 * np.abs(dq_all).max()
        assert d_delta == pytest.approx(d_delta_all, rel=1e-9, abs=1e-15)
        assert d_alpha == 0.0


def test_only_symmetric_data_is_folded(rule):
    """The rule, F, m and g must be symmetric to rounding (MIRROR_TOL, 1e-14): a coating
    1e-11 stiffer on one side, a gap tilted by 1e-12 of its largest value, a node moved
    by 1e-9, an odd count, an entry of F changed by 1e-9 are each refused."""
    op, m, x, w, rhs = rule
    g = -rhs
    assert Mirror.of(x, w, op, m, g) is not None
    soft = m.copy()
    soft[: x.size // 2] *= 1.0 + 1e-11
    assert Mirror.of(x, w, op, soft, g) is None
    tilted = g + 1e-12 * np.abs(g).max() * x
    assert Mirror.of(x, w, op, m, tilted) is None
    moved = x.copy()
    moved[0] += 1e-9
    assert Mirror.of(moved, w, op, m, g) is None
    assert Mirror.of(x[:-1], w[:-1], op[:-1, :-1], m[:-1], g[:-1]) is None
    lopsided = op.copy()
    lopsided[0, 1] *= 1.0 + 1e-9
    assert Mirror.of(x, w, lopsided, m, g) is None


def test_a_mirrored_solver_takes_no_other_rule(rule):
    """Its kept systems are the half's: a call with another rule's nodes is refused, not
    answered from them."""
    op, m, x, w, rhs = rule
    solver = StepSolver(Mirror.of(x, w, op, m, -rhs))
    bordered_solve(op, m, x, w, 1.0, 1.0, CENTRED[0], rhs, np.arange(8, x.size - 8), solver)
    k = x.size - 16
    with pytest.raises(ValueError, match="another rule"):
        bordered_solve(op[:k, :k], m[:k], x[:k], w[:k], 1.0, 1.0, CENTRED[0], rhs[:k],
                       np.arange(8, k - 8), solver)


def test_the_mirror_of_a_rule_is_kept_for_its_own_operator(rule):
    """rule_mirror keeps the mirror of a rule with the operator it was made of: the same
    array gives it again, another (a caller's own, here F doubled) its own mirror."""
    op, m, x, w, rhs = rule
    panels = base_panels(1.0, (), edge_width=1e-2, max_width=0.05)
    first = rule_mirror(1.0, panels, op, m, -rhs)
    assert rule_mirror(1.0, panels, op, m, -rhs) is first
    doubled = 2.0 * op
    other = rule_mirror(1.0, panels, doubled, m, -rhs)
    assert other is not first and np.array_equal(other.op, 2.0 * first.op)


@pytest.mark.parametrize(("given", "loads", "centred"), [
    (("force", "moment"), {"force": [1.0, 2.0], "moment": [0.0, 0.0]}, True),
    (("force", "moment"), {"force": [1.0, 2.0], "moment": [0.0, 1e-300]}, False),
    (("settlement", "tilt"), {"settlement": [0.1], "tilt": [0.0]}, True),
    (("tilt", "moment"), {"tilt": [0.0], "moment": [0.0]}, False),
    (("settlement", "force"), {"settlement": [0.1], "force": [1.0]}, False),
])
def test_a_load_is_centred_with_a_moment_or_a_tilt_of_zero_throughout(given, loads,
                                                                      centred):
    arrays = {k: np.asarray(v) for k, v in loads.items()}
    assert Mirror.centred(given, arrays) is centred


def test_the_even_rule_is_symmetric_and_keeps_a_symmetric_rule():
    """band_rule merges close edges scanning from -1, so symmetric bands can give a rule
    whose edges differ from their mirror images (by up to a tenth of a band panel);
    even_rule mirrors the half x > 0 and leaves a symmetric rule as it is."""
    space = Space(1.0, lambda x: np.ones_like(x), lambda x: np.zeros_like(x), (-0.4, 0.4))
    res = Resolution(0.125, 0.01)
    bands = mirrored_bands([(0.383, 0.613)])
    assert bands == [(-0.613, -0.383), (0.383, 0.613)]
    rule = band_rule(space, res, bands, 0.02)
    even = even_rule(rule)
    assert np.array_equal(even.edges, -even.edges[::-1])
    assert even.edges[0] == -1.0 and even.edges[-1] == 1.0
    assert {-0.4, 0.4} <= set(even.edges.tolist())
    assert np.diff(even.edges).max() <= np.diff(rule.edges).max() * (1 + 1e-12)
    assert even_rule(even) is even
    # a panel across 0 as wide or narrower when mirrored: kept without an edge at 0
    plain = base_panels(1.0, (), edge_width=1e-2, max_width=0.05)
    assert even_rule(plain) is plain


def _scene(name: str) -> dict:
    return copy.deepcopy(read_preset(name))


def _solved(scene: dict, fold: bool, monkeypatch) -> core.SceneSolution:
    clear_caches()
    with monkeypatch.context() as patch:
        if not fold:
            patch.setattr(Mirror, "centred", staticmethod(lambda given, loads: False))
        return core.solve(core.scene_from_dict(scene))


def test_a_centred_crown_under_creep_is_even_and_as_before(monkeypatch):
    """A crowned punch on the creeping uniform coating, centred force: its rules were
    symmetric already, so the half gives the whole march's answers to rounding
    (measured 7e-15 of q), with the tilt exactly 0 and q(x) = q(-x)."""
    scene = _scene("uniform_flat")
    scene["punch"]["shape"] = {"kind": "polynomial", "coefficients": [0.0, 0.0, 2e-5]}
    folded = _solved(scene, True, monkeypatch)
    whole = _solved(scene, False, monkeypatch)
    assert folded.dimensionless.success and whole.dimensionless.success
    x = np.linspace(-0.999, 0.999, 301)
    q, q_whole = np.asarray(folded.pressure(x)), np.asarray(whole.pressure(x))
    assert np.abs(q - q_whole).max() <= 1e-12 * np.abs(q_whole).max()
    assert np.max(np.abs(np.asarray(folded.tilt))) == 0.0
    axis = list(q.shape).index(x.size)
    assert np.abs(q - np.flip(q, axis)).max() <= 1e-13 * np.abs(q).max()
    for zones in folded.contact_set:
        assert zones[0][0] == pytest.approx(-zones[-1][1], abs=1e-13)


def test_a_stepped_punch_under_a_falling_force_is_even(monkeypatch):
    """The stepped punch whose outer steps touch as a centred force rises and leave as it
    falls. Its band rule was not symmetric (an edge 7e-4 half-widths off its mirror
    image), which left q 1.2e-10 asymmetric and a moment of 7.3e-12 P a; on the even rule
    (even_rule) and the half it is even to rounding. The rule's change moves the answer
    by far less than its estimate (measured 1.3e-10 of q against 1.2e-6)."""
    scene = _scene("stepped_punch")
    scene["solver"]["tol"] = 1e-5
    p = 4e5
    scene["loading"] = {"force": {"kind": "table", "points": [[0, 0.3 * p], [182.5, p],
                                                              [365, 0.6 * p]]},
                        "tilt": 0.0}
    folded = _solved(scene, True, monkeypatch)
    assert folded.dimensionless.success
    x = np.linspace(-0.99, 0.99, 200)  # no point on a step at +-0.4
    q = np.asarray(folded.pressure(x))
    axis = list(q.shape).index(x.size)
    assert np.abs(q - np.flip(q, axis)).max() <= 1e-13 * np.abs(q).max()
    assert np.max(np.abs(np.asarray(folded.moment))) <= 1e-13 * np.max(folded.force)
