"""Scenes with no coating layers (``"coating": []``): the punch on the bare base."""

from __future__ import annotations

import copy
import json
import re
from typing import Any

import numpy as np
import pytest

from core.engines.layered import NO_COATING
from core.presets import read_preset
from core.scene import load_json_schema, scene_from_dict, schema_errors, solve
from tests.support.creep_laws import CREEP, aging_growth, laws

#: pi theta delta / P of a flat punch on a layer with H = a, to the benchmark's 8 digits
#: (tests/engines/test_uncoated.py reproduces it on the kernel alone).
BENCHMARK = 0.66679549


def bare(**changes: Any) -> dict[str, Any]:
    """The preset ``bare_layer`` with ``changes`` (top-level fields replaced)."""
    d = read_preset("bare_layer")
    d.update(copy.deepcopy(changes))
    return d


def theta(d: dict[str, Any]) -> float:
    """``E / (2 (1 - nu^2))`` [Pa] of the scene's base."""
    nu = d["base"]["poisson"]
    return d["base"]["creep"]["modulus"] / (2 * (1 - nu * nu))


def test_no_coating_is_a_valid_scene_for_the_validator_and_the_schema():
    d = bare()
    assert d["coating"] == []
    scene = scene_from_dict(d)
    assert scene.coating == ()
    assert schema_errors(json.loads(json.dumps(d)), load_json_schema("scene")) == []
    assert scene.to_dict()["coating"] == []


def test_the_bare_preset_gives_the_benchmark_settlement_coefficient():
    d = bare(solver={"tol": 1e-10})
    result = solve(d)
    coefficient = np.pi * theta(d) * result.settlement[0] / result.force[0]
    # measured 0.66679548522 (estimate 1e-12): the benchmark's 8 digits
    assert coefficient == pytest.approx(BENCHMARK, abs=1e-8)
    assert result.info["coating_model"] == NO_COATING
    assert result.info["method"] == "layered" and result.info["contact"] == "full"


def test_a_bare_result_has_no_coating_model_error_and_says_so():
    result = solve(bare())
    assert result.model_error["estimate"] == 0.0
    assert result.info["model_error_estimate"] == 0.0
    assert result.flags == []
    text = repr(result)
    assert "0 coating model (no coating)" in text and "no coating" in text
    assert "thin layer" not in text
    # every output part works on zero layers
    assert np.all(np.isfinite(result.pressure_on_grid))
    assert json.loads(json.dumps(result.to_dict(), allow_nan=False))["scene"]["coating"] == []
    assert result.pressure_csv(header=False).count("\n") == 1 + result.x.size
    assert "no coating" in result._repr_html_()
    assert result.info["dimensional"]["coating_thickness_max_m"] == 0.0


def test_the_pressure_has_the_inverse_square_root_edges():
    result = solve(bare(solver={"tol": 1e-10}))
    a = result.scene.half_width
    force = result.force[0]
    # q sqrt(a^2 - x^2) tends to a finite, non-zero limit at the corner, linearly in
    # a - x: measured 0.7595, 0.7552, 0.7518 of P / pi at x = 0.99, 0.995, 0.999 a (slopes
    # 0.852 and 0.853 per unit of a - x; the half-space's limit would be 1)
    x = a * np.array([0.99, 0.995, 0.999])
    limit = result.pressure(x)[:, 0] * np.sqrt(a * a - x * x) / (force / np.pi)
    slopes = -np.diff(limit) / -np.diff(a - x)
    assert slopes[1] == pytest.approx(slopes[0], rel=0.01)
    assert 0.7 < limit[-1] < 0.8
    # held beyond a (1 - 1e-3) (core/engines/layered/answer.py BARE_CORNER)
    assert result.pressure(np.array([a]))[0, 0] == result.pressure(np.array([0.999 * a]))[0, 0]


def test_the_four_statements_agree_on_the_bare_layer():
    d = bare(solver={"tol": 1e-10}, loading={"force": 5e5, "moment": 1e5})
    four = solve(d)
    values = {q: float(getattr(four, q)[0]) for q in ("settlement", "tilt", "force", "moment")}
    # measured: no difference at all (the same cached unit responses answer all four;
    # estimates 1e-12), so rel=1e-11 only allows for rounding
    for given in (("settlement", "tilt"), ("settlement", "moment"), ("tilt", "force")):
        other = solve(bare(solver={"tol": 1e-10}, loading={q: values[q] for q in given}))
        for q, value in values.items():
            assert float(getattr(other, q)[0]) == pytest.approx(value, rel=1e-11), (given, q)


def test_the_bare_layer_agrees_with_the_fe_model():
    from core.scene import check_scene

    d = bare(loading={"force": 5e5, "moment": 5e4})
    check = check_scene(d, 0.0, level=0)
    # measured 9.6e-5 (settlement), 2.2e-4 (tilt): the FE model's own level-0 error on an
    # uncoated layer (1.0e-4 / 2.3e-4, core/coating/fem_check.py); 0.6 s of CPU
    assert abs(check["errors"]["settlement"]) < 3e-4
    assert abs(check["errors"]["tilt"]) < 3e-4
    assert check["estimate"] == 0.0 and check["coating_model"] == NO_COATING


# What the bare path does not solve yet: each refused naming the field and the reason.
REFUSED = [
    ("step", lambda d: d["punch"].update(shape={"kind": "step", "values": [1.5e-5, 0.0, 1.5e-5],
                                                "breaks": [-0.4, 0.4]}),
     "punch.shape: a scene with no coating layers"),
    ("kink", lambda d: d["punch"].update(shape={"expr": "1e-5 * abs(x)"}),
     "punch.shape: a scene with no coating layers"),
]


@pytest.mark.parametrize(("change", "message"), [c[1:] for c in REFUSED],
                         ids=[c[0] for c in REFUSED])
def test_what_the_bare_path_does_not_solve_is_refused_when_read(change, message):
    d = bare()
    change(d)
    with pytest.raises(ValueError) as refused:
        scene_from_dict(d)
    assert str(refused.value).startswith(message), str(refused.value)
    # with what a bare base is solved for
    assert "is solved under a punch shape without jumps or kinks; on a base that creeps" \
        in str(refused.value)


def test_a_lifting_punch_is_solved_under_auto_and_flagged_in_full_contact():
    lifting = {"force": 5e5, "moment": 4e5}  # e = 0.8 a: the far corner lifts off
    for contact in ("auto", "unilateral"):
        result = solve(bare(loading=lifting, solver={"tol": 1e-6, "contact": contact}))
        assert result.flags == [] and result.info["contact"] == "unilateral"
        (lo, hi), = result.contact_set[0]
        assert hi == 1.0 and 0.2 < lo < 0.3  # the heel lifts (tests/engines/test_bare_lift_off.py)
    result = solve(bare(loading=lifting, solver={"tol": 1e-6, "contact": "full"}))
    assert "contact_lost" in result.flags
    assert result.info["coating_model"] == NO_COATING


def test_a_crown_pressed_lightly_lifts_at_both_corners():
    # tests/engines/test_bare_lift_off.py: Hertz's contact on a thick layer
    crowned = bare(loading={"force": 5e4, "moment": 0.0})
    crowned["punch"]["shape"] = {"kind": "polynomial", "coefficients": [0.0, 0.0, 1e-4]}
    result = solve(crowned)
    assert result.flags == [] and result.info["contact"] == "unilateral"
    (lo, hi), = result.contact_set[0]
    assert -1.0 < lo < 0.0 < hi < 1.0 and lo == pytest.approx(-hi, abs=1e-12)


def test_a_smooth_crowned_punch_in_full_contact_is_solved():
    d = bare()
    d["punch"]["shape"] = {"kind": "polynomial", "coefficients": [0.0, 0.0, 2.5e-6]}
    result = solve(d)
    assert result.flags == [] and result.info["success"]
    assert result.info["coating_model"] == NO_COATING


def test_a_layer_of_zero_thickness_is_still_refused():
    d = bare(coating=[{"thickness": 0.0, "modulus": 1e9, "poisson": 0.3}])
    with pytest.raises(ValueError, match=r"^coating\[0\]\.thickness: must be > 0"):
        scene_from_dict(d)


# --------------------------------------------------------------- a creeping bare base



def creeping(loading: dict[str, float], creep: dict[str, Any] = CREEP) -> dict[str, Any]:
    d = bare(loading=loading, times={"end": 365.0, "count": 40, "spacing": "log"})
    d["base"]["creep"] = dict(creep)
    return d


@pytest.mark.parametrize("loading", [
    {"force": 5e5, "moment": 5e4}, {"settlement": 1e-5, "tilt": 1e-6},
    {"settlement": 1e-5, "moment": 0.0}, {"tilt": 0.0, "force": 5e5}],
    ids=lambda loading: "+".join(loading))
def test_a_creeping_bare_base_follows_the_creep_and_relaxation_functions(loading):
    # a bare homogeneous layer: constant forces give settlement and tilt growing like
    # J(t), constant kinematics forces relaxing like R(t) (the correspondence principle).
    # Measured: 6.4e-14 (creep: V of a constant force is exact), 2.0e-8 (relaxation, a
    # Volterra solve; estimate 1.4e-8, 32 steps) against tol 1e-6
    result = solve(creeping(loading))
    assert result.flags == [] and result.info["coating_model"] == NO_COATING
    assert result.info["n_steps"] > 0 and result.info["time_error_estimate"] > 0
    growth, relaxation = laws(result.times)
    for q in ("settlement", "tilt", "force", "moment"):
        if q in loading:
            continue
        values = getattr(result, q)
        if values[0] == 0:  # a centred load: no tilt, no moment
            assert np.all(values == 0), q
            continue
        law = growth if q in ("settlement", "tilt") else relaxation
        assert np.max(np.abs(values / values[0] / (law / law[0]) - 1)) < 1e-7, q


def test_an_aging_bare_base_settles_like_its_creep_function():
    # aging (Arutyunyan, the eccentric_creep preset's): under a constant force the
    # settlement is delta(0) E(tau0) J(t, tau0), J = 1 / E(tau0) + C(t, tau0). Measured
    # 1.1e-8 against an estimate of 1.5e-8 (tol 1e-6)
    creep = read_preset("eccentric_creep")["base"]["creep"]
    d = creeping({"force": 5e5, "moment": 5e4}, creep)
    d["times"] = read_preset("eccentric_creep")["times"]
    result = solve(d)
    law = aging_growth(result)
    for q in ("settlement", "tilt"):
        values = getattr(result, q)
        assert np.max(np.abs(values / values[0] / law - 1)) < 1e-7, q
    assert result.flags == []


def test_a_creeping_bare_result_reads_and_checks():
    result = solve(creeping({"force": 5e5, "moment": 5e4}))
    assert "0 coating model (no coating)" in repr(result)
    assert np.all(np.isfinite(result.pressure_on_grid))
    # the FE check compares the elastic copy at the time asked (the bare answer: no
    # coating model to measure; measured 9.6e-5 in the settlement at level 0, as above)
    from core.scene import check_scene

    check = check_scene(creeping({"force": 5e5, "moment": 5e4}), 10.0, level=0)
    assert check["coating_model"] == NO_COATING and abs(check["errors"]["settlement"]) < 3e-4


def test_the_report_of_a_bare_scene_says_there_is_no_coating():
    from core.report.content import accuracy_rows
    from core.report.inputs import input_rows

    result = solve(bare())
    assert ("coating", "none: the punch on the bare base") in input_rows(result.scene)
    rows = dict(accuracy_rows(result))
    assert rows["coating model error (estimated, relative)"].startswith("0: no coating")
    assert rows["solved by"].endswith("no coating")


@pytest.mark.parametrize("loading", [
    {"settlement": -1e-3, "tilt": 0.0},
    {"settlement": -1e-5, "moment": 0.0},
    {"settlement": -6e-4, "tilt": 5e-4},    # tilted, its toe still 1e-4 m above (a = 1 m)
])
def test_a_punch_held_clear_of_the_bare_base_has_no_contact(loading: dict) -> None:
    """As on a coated base: q = 0, P = M = 0, the flag ``no_contact``. It was refused as
    "no contact zone with two free ends was found ... (the crown's contact would reach a
    corner or vanish)" for a flat punch."""
    d = bare(loading=loading, times={"end": 100.0, "count": 3, "spacing": "linear"})
    d["punch"]["half_width"] = 1.0
    result = solve(d)
    assert result.flags == ["no_contact"] and result.info["success"]
    assert np.all(result.force == 0.0) and np.all(result.moment == 0.0)
    assert result.contact_set == [[], [], []] and np.all(result.contact_width == 0.0)
    assert np.all(result.pressure_on_grid == 0.0)
    np.testing.assert_array_equal(result.settlement, d["loading"]["settlement"])


def test_a_punch_that_reaches_the_bare_base_is_not_taken_for_clear() -> None:
    """Tilted so that its toe dips in (2e-4 + 5e-4 a > 0 at x = a): it touches there."""
    result = solve(bare(loading={"settlement": 2e-4, "tilt": 5e-4}))
    assert "no_contact" not in result.flags and result.force[0] > 0.0


def test_a_bare_base_too_thin_for_its_kernel_table_is_refused_with_the_thickness_answered():
    """a / H = 95 passes the kernel table's cost bound (5e7 cosines at a / H ~ 88). The
    refusal said what a bare base is solved for (shapes, creep, lift-off: nothing of
    this) and no number; it gives the thinnest base answered, rounded up, which is."""
    d = bare()
    d["base"].update(thickness=1.0 / 95)
    with pytest.raises(ValueError, match=r"^base\.thickness: without coating layers the base "
                       r"must be at least (0\.\d+) m thick under this punch \(a / H at most "
                       r"8\d\.\d\), got 0\.0105263 m \(a / H = 95\)") as refused:
        scene_from_dict(d)
    least = float(re.search(r"at least (\S+) m", str(refused.value))[1])
    d["base"].update(thickness=least)
    scene_from_dict(d)
    d["base"].update(thickness=least * 0.99)
    with pytest.raises(ValueError, match=r"^base\.thickness: without coating"):
        scene_from_dict(d)
