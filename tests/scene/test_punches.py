"""Several punches on one foundation (core/scene/punches.py, core/engines/nystrom/multi.py):
the coupled answer against the single punch, reciprocity, symmetry, the thin-base limit,
convergence under refinement with its error estimate, and the refusals."""

from __future__ import annotations

import copy
from typing import Any

import numpy as np
import pytest

import core
from core.scene import SceneSolution, punches_from_dict
from tests.conftest import scene_file

CROWN = {"kind": "polynomial", "coefficients": [0.0, 0.0, 5e-6]}


def _base(tol: float = 1e-6, thickness: float = 4.0) -> dict[str, Any]:
    d = scene_file("uniform_flat")
    d["base"]["creep"] = {"model": "elastic", "modulus": 3.0e10}
    d["base"]["thickness"] = thickness
    d["times"] = {"end": 10.0, "count": 3}
    d["solver"] = {"tol": tol}
    del d["punch"], d["loading"]
    return d


def _pair(gap: float, *, tol: float = 1e-6, thickness: float = 4.0,
          loads: tuple[dict, dict] = ({"force": 5e5, "moment": 1e4},
                                      {"force": 3e5, "moment": -1e4}),
          widths: tuple[float, float] = (1.0, 0.6)) -> dict[str, Any]:
    """A crowned punch at 0 and a flat, narrower one ``gap`` [m] to its right."""
    d = _base(tol, thickness)
    loads = copy.deepcopy(loads)  # the default is shared between calls
    d["punches"] = [
        {"center": 0.0, "half_width": widths[0], "shape": CROWN, "loading": loads[0]},
        {"center": widths[0] + gap + widths[1], "half_width": widths[1],
         "loading": loads[1]}]
    return d


def _single(d: dict[str, Any], k: int) -> SceneSolution:
    """Punch ``k`` alone, by the same (thin-layer, Nystrom) model."""
    scene = punches_from_dict(d).scenes[k]
    return SceneSolution(scene, scene.dimensionless, scene.dimensionless.solve())


def _relative(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300))


QUANTITIES = ("settlement", "tilt", "force", "moment")


def test_far_apart_punches_answer_as_single_punches() -> None:
    d = _pair(60.0)  # 15 base thicknesses apart
    result = core.solve(d)
    assert len(result.punches) == 2 and not result.flags
    for k in range(2):
        alone, coupled = _single(d, k), result.punches[k]
        a = alone.scene.half_width
        x = np.linspace(-a, a, 41)
        # measured: 4e-15 (scalars) and 1.1e-15 (q); exp(-2.1 * 15) = 2e-14 is the coupling
        for q in QUANTITIES:
            assert _relative(getattr(coupled, q), getattr(alone, q)) < 1e-9, q
        assert _relative(coupled.pressure(x), alone.pressure(x)) < 1e-9


def test_the_contact_set_is_in_the_global_x() -> None:
    result = core.solve(_pair(0.5))
    assert result.punches[0].contact_set[0] == [(-1.0, 1.0)]
    assert result.punches[1].contact_set[0] == pytest.approx([(1.5, 2.7)])
    np.testing.assert_allclose(result.punches[1].pressure_at([2.1]),
                               result.punches[1].pressure([0.0]))


def test_a_pair_far_from_the_origin_answers_as_the_same_pair_at_it() -> None:
    """The engine takes the punches' distances from the first one's centre: taken as
    differences of the global centres, a pair at 1e9 m moved its tilts by 8.4e-9 (the
    estimate 2.5e-9, tol 1e-8), and at 1e15 m by 1 %."""
    # (centres 0 and 2 m: shifted by these origins they stay exact in binary)
    near = core.solve(_pair(0.5, tol=1e-8, widths=(1.0, 0.5)))
    for origin in (1e9, -1e15):
        d = _pair(0.5, tol=1e-8, widths=(1.0, 0.5))
        for punch in d["punches"]:
            punch["center"] += origin
        far = core.solve(d)
        for k in range(2):
            for q in QUANTITIES:  # the same arithmetic: the same bits
                np.testing.assert_array_equal(getattr(far.punches[k], q),
                                              getattr(near.punches[k], q), err_msg=q)
            assert far.punches[k].center == near.punches[k].center + origin


def test_elastic_reciprocity() -> None:
    """Maxwell-Betti: the flexibility of the pair (settlement and tilt of each punch per
    unit force and moment on each) is symmetric."""
    unit = {"force": 1e5, "moment": 1e5}
    columns = []
    for k in range(2):
        for name in ("force", "moment"):
            loads = [{"force": 0.0, "moment": 0.0}, {"force": 0.0, "moment": 0.0}]
            loads[k][name] = unit[name]
            d = _pair(0.3, loads=tuple(loads))
            for p in d["punches"]:
                p.pop("shape", None)  # no gap: the answer is linear in the loads
            d["solver"]["contact"] = "full"  # a moment alone lifts an edge: q < 0 is fine
            result = core.solve(d)
            columns.append([getattr(result.punches[j], q)[0] / unit[name]
                            for j in range(2) for q in ("settlement", "tilt")])
    flexibility = np.array(columns).T
    # measured: asymmetry 3.4e-10 of the largest entry at tol 1e-6
    assert np.max(np.abs(flexibility - flexibility.T)) < 1e-6 * np.max(np.abs(flexibility))
    # the coupling is not negligible at this gap (so the check means something)
    assert abs(flexibility[2, 0]) > 1e-3 * abs(flexibility[0, 0])


def test_a_symmetric_pair_settles_equally_and_tilts_oppositely() -> None:
    d = _base()
    load = {"force": 5e5, "moment": 0.0}
    d["punches"] = [{"center": -1.2, "half_width": 1.0, "loading": load},
                    {"center": 1.2, "half_width": 1.0, "loading": copy.deepcopy(load)}]
    left, right = core.solve(d).punches
    # measured: equal to rounding (both punches share one grid)
    np.testing.assert_allclose(left.settlement, right.settlement, rtol=1e-12)
    np.testing.assert_allclose(left.tilt, -right.tilt, rtol=1e-10)
    assert np.all(left.tilt > 0)  # each leans toward the other


def test_a_thin_base_decouples_the_punches() -> None:
    # measured coupling (settlement, relative) at a gap of 0.5 m: H = 1 m 1.7e-3,
    # 0.25 m 8.7e-5, 0.1 m 2.6e-8, 0.05 m 1.5e-13: it falls like exp(-2.1 gap / H)
    effects = []
    for thickness in (1.0, 0.25, 0.05):
        d = _pair(0.5, thickness=thickness)
        effects.append(_relative(core.solve(d).punches[0].settlement,
                                 _single(d, 0).settlement))
    assert effects[0] > 1e-4 and effects[0] > effects[1] > effects[2]
    assert effects[2] < 1e-9


def test_convergence_and_the_estimate_covers_every_zone_edges_included() -> None:
    gap = 0.05  # 1/80 of the base thickness: the near-field coupling rule at work
    reference = core.solve(_pair(gap, tol=1e-10))
    errors = []
    for tol in (1e-4, 1e-8):
        result = core.solve(_pair(gap, tol=tol))
        worst = 0.0
        for mine, best in zip(result.punches, reference.punches, strict=True):
            a = mine.scene.half_width
            x = a * np.concatenate([np.linspace(-1.0, 1.0, 401),
                                    [-1 + 1e-6, 1 - 1e-6, -1 + 1e-3, 1 - 1e-3]])
            error = _relative(mine.pressure(x), best.pressure(x))
            # measured: q errors 2.5e-8 and 1.1e-8 against estimates 1.0e-7 and 4.4e-8
            # at tol 1e-4; 1.7e-9 and 7.3e-10 against 4.9e-9 and 1.9e-9 at tol 1e-8
            assert error <= mine.info["error_estimate"]
            assert mine.info["error_estimate"] <= tol
            for q in ("settlement", "tilt"):
                assert _relative(getattr(mine, q), getattr(best, q)) <= tol
            worst = max(worst, error)
        errors.append(worst)
    assert errors[1] < 0.2 * errors[0]


@pytest.mark.parametrize("gap", [1e-3, 1e-4])
def test_a_very_close_pair_stays_within_its_estimate(gap: float) -> None:
    """Punches closer than their end panels are wide: the facing ends are graded down to
    the gap (without it the error of q was 1.1e-6 at a gap of 1e-3 m, 5e-5 at 1e-4 m,
    under an estimate of 1e-7)."""
    reference, result = core.solve(_pair(gap, tol=1e-10)), core.solve(_pair(gap, tol=1e-6))
    for mine, best in zip(result.punches, reference.punches, strict=True):
        a = mine.scene.half_width
        x = a * np.concatenate([np.linspace(-1.0, 1.0, 801),
                                [1 - 1e-4, 1 - 1e-5, 1 - 1e-6, -1 + 1e-6, -1 + 1e-5]])
        # measured: 2.6e-8 and 9.0e-9 against estimates 1.0e-7 and 4.4e-8 (both gaps)
        assert _relative(mine.pressure(x), best.pressure(x)) <= mine.info["error_estimate"]
        for q in ("settlement", "tilt"):
            assert _relative(getattr(mine, q), getattr(best, q)) <= 1e-6


def test_one_punch_is_the_single_punch_scene() -> None:
    d = _base()
    d["punches"] = [{"center": 3.0, "half_width": 1.0, "loading": {"force": 5e5,
                                                                  "moment": 1e4}}]
    single = _base()
    single["punch"] = {"half_width": 1.0}
    single["loading"] = {"force": 5e5, "moment": 1e4}
    one, alone = core.solve(d).punches[0], core.solve(single)
    for q in QUANTITIES:
        np.testing.assert_array_equal(getattr(one, q), getattr(alone, q))
    assert one.contact_set[0] == [(2.0, 4.0)]


def test_a_lost_contact_is_flagged_on_its_punch_in_full_contact() -> None:
    d = _pair(60.0, loads=({"force": 5e5, "moment": 2e5}, {"force": 3e5, "moment": 0.0}))
    d["solver"]["contact"] = "full"
    result = core.solve(d)
    assert result.punches[0].flags == ["contact_lost"] and not result.punches[1].flags
    assert result.flags == ["punches[0].contact_lost"]


def test_a_lost_contact_under_creep_lifts_off_in_the_automatic_mode() -> None:
    d = _creeping(_pair(60.0, loads=({"force": 5e5, "moment": 2e5},
                                     {"force": 3e5, "moment": 0.0})))
    d["times"]["count"] = 2
    result = core.solve(d)  # tests/scene/test_punches_creep_liftoff.py checks the answer
    assert not result.flags
    for punch in result.punches:
        assert punch.info["contact"] == "unilateral"
    assert "contact_lost" in result.punches[0].info["full_contact"]["flags"]
    assert result.punches[0].contact_set[0][0][0] > -1.0
    assert result.punches[1].contact_set[0] == [pytest.approx((61.0, 62.2))]


# --------------------------------------------------------- a coating varying along x


def test_the_coating_is_read_in_the_global_x() -> None:
    d = _pair(60.0)
    d["coating"][0]["thickness"] = {"expr": "0.02 + 0.0002*x"}
    d["coating"][0]["modulus"] = {"expr": "8e8*(1 + 0.002*x)"}
    result = core.solve(d)
    for k, punch in enumerate(d["punches"]):
        c = punch["center"]
        alone = _base()
        alone["punch"] = {"half_width": punch["half_width"], "shape": punch.get("shape", 0.0)}
        alone["loading"] = punch["loading"]
        alone["coating"][0]["thickness"] = {"expr": f"0.02 + 0.0002*(x + {c!r})"}
        alone["coating"][0]["modulus"] = {"expr": f"8e8*(1 + 0.002*(x + {c!r}))"}
        scene = core.scene_from_dict(alone)
        single = SceneSolution(scene, scene.dimensionless, scene.dimensionless.solve())
        x = np.linspace(-1.0, 1.0, 21) * punch["half_width"]
        # measured: 1.5e-15 (scalars), 2.5e-14 (q)
        for q in QUANTITIES:
            assert _relative(getattr(result.punches[k], q), getattr(single, q)) < 1e-9, q
        assert _relative(result.punches[k].pressure(x), single.pressure(x)) < 1e-9
    # the file keeps the profile of the global x
    assert result.scene.to_dict()["coating"][0]["thickness"] == {"kind": "expr",
                                                                 "expr": "0.02 + 2e-4 * x"}


def test_a_close_pair_on_a_varying_coating_converges_within_its_estimate() -> None:
    def pair(tol: float) -> Any:
        d = _pair(0.05, tol=tol)
        d["coating"][0]["thickness"] = {"kind": "linear", "start": 0.015, "end": 0.03}
        return core.solve(d)

    reference, result = pair(1e-10), pair(1e-4)
    for mine, best in zip(result.punches, reference.punches, strict=True):
        x = mine.scene.half_width * np.concatenate([np.linspace(-1.0, 1.0, 401),
                                                    [-1 + 1e-6, 1 - 1e-6]])
        # measured: 4.5e-8 and 8.0e-9 against estimates 1.6e-7 and 3.3e-8
        assert _relative(mine.pressure(x), best.pressure(x)) <= mine.info["error_estimate"]


# ---------------------------------------------------------------------------- creep

CREEP = {"model": "exponential", "modulus": 3.0e10, "compliance": 3.0e-11, "rate": 0.05}


def _creeping(d: dict[str, Any], creep: dict[str, Any] = CREEP) -> dict[str, Any]:
    d["base"]["creep"] = copy.deepcopy(creep)
    d["times"] = {"end": 365.0, "count": 10, "spacing": "log"}
    return d


def test_far_apart_punches_creep_as_single_punches() -> None:
    d = _creeping(_pair(60.0))
    result = core.solve(d)
    assert not result.flags
    for k in range(2):
        alone, coupled = _single(d, k), result.punches[k]
        x = np.linspace(-1.0, 1.0, 21) * alone.scene.half_width
        # measured: 3.5e-15 (scalars), the same steps (the exponential kernel is exact)
        for q in QUANTITIES:
            assert _relative(getattr(coupled, q), getattr(alone, q)) < 1e-9, q
        assert _relative(coupled.pressure(x), alone.pressure(x)) < 1e-9
        assert coupled.settlement[-1] > 1.5 * coupled.settlement[0]  # it creeps


@pytest.mark.parametrize("loads", [({"force": 5e5, "moment": 1e4}, {"force": 3e5, "moment": -1e4}),
                                   ({"settlement": 3e-5, "tilt": 1e-6},
                                    {"settlement": 2e-5, "moment": -1e4})])
def test_a_creeping_pairs_load_change_sums_the_kept_pressures(loads, monkeypatch) -> None:
    """Load changes of punches on a creeping base read q on the plotting grid as the sum
    of each kept response's q there: from the second change on no Nystrom formula runs,
    and the answer is the formula's on the summed answer."""
    from core.cache import clear_caches
    from core.engines.nystrom import CoupledPunches

    def scaled(factor: float) -> dict[str, Any]:
        e = _creeping(_pair(0.5, loads=loads))
        for punch in e["punches"]:
            punch["loading"] = {k: factor * v for k, v in punch["loading"].items()}
        return e

    clear_caches()
    for factor in (1.0, 1.01):  # the responses stepped, then their q on the grid kept
        core.solve(scaled(factor))
    formula = CoupledPunches._pressure
    calls = []

    def counted(self, *args, **kwargs):
        calls.append(args[0])
        return formula(self, *args, **kwargs)

    monkeypatch.setattr(CoupledPunches, "_pressure", counted)
    summed = core.solve(scaled(1.02))
    grids = [punch.pressure_on_grid for punch in summed.punches]
    assert calls == []
    clear_caches()  # a first answer takes the formula on the summed answer
    direct = core.solve(scaled(1.02))
    assert direct.punches[0].pressure_on_grid is not None and calls
    for grid, punch in zip(grids, direct.punches, strict=True):
        # measured: 3.8e-15 to 7.1e-15 of q's largest value in both statements; the
        # responses' load shapes are kept to 12 digits (SHAPE_DIGITS), hence the bound
        assert _relative(grid, punch.pressure_on_grid) < 1e-12


def _scaled_pair(factor: float, gap: float = 0.5) -> dict[str, Any]:
    e = _creeping(_pair(gap))
    for punch in e["punches"]:
        punch["loading"] = {k: factor * v for k, v in punch["loading"].items()}
    return e


def _count_formula(monkeypatch) -> list[int]:
    """The punches whose q the Nystrom formula is evaluated for, call by call."""
    from core.engines.nystrom import CoupledPunches

    formula = CoupledPunches._pressure
    calls: list[int] = []

    def counted(self, *args, **kwargs):
        calls.append(args[0])
        return formula(self, *args, **kwargs)

    monkeypatch.setattr(CoupledPunches, "_pressure", counted)
    return calls


def test_kept_pressures_survive_more_point_sets_than_punches(monkeypatch) -> None:
    """q asked at several other point sets of every punch between load changes does not
    push the plotting grid out of the kept values (least recently used first, room for
    all of them): the next load change still evaluates no formula."""
    from core.cache import clear_caches

    clear_caches()
    for factor in (1.0, 1.01):
        result = core.solve(_scaled_pair(factor))
    for punch in result.punches:  # six more sets a punch, each evaluated part by part
        for k in range(6):
            punch.pressure(punch.scene.half_width * np.linspace(-0.9, 0.9, 11 + k))
    calls = _count_formula(monkeypatch)
    core.solve(_scaled_pair(1.02)).punches[1].pressure_on_grid  # noqa: B018
    assert calls == []


def test_a_set_too_large_to_keep_takes_the_formula_once(monkeypatch) -> None:
    """Points times output times above the kept bound: q of a load change is the formula
    on the summed answer (one evaluation a punch, not one a part of the sum), the same
    answer as the sum of the kept parts' q."""
    from core.cache import clear_caches
    from core.engines.nystrom import multi

    def third_change(calls: list[int]) -> list[np.ndarray]:
        clear_caches()
        for factor in (1.0, 1.01):
            core.solve(_scaled_pair(factor))
        calls.clear()
        return [p.pressure_on_grid for p in core.solve(_scaled_pair(1.02)).punches]

    calls = _count_formula(monkeypatch)
    summed = third_change(calls)
    assert calls == []
    monkeypatch.setattr(multi, "PRESSURE_VALUES_KEPT", 10)
    direct = third_change(calls)
    assert sorted(calls) == [0, 1]
    for grid, other in zip(summed, direct, strict=True):
        # measured: 5.2e-15 and 8.5e-15 of q's largest value (shapes kept to 12 digits)
        assert _relative(grid, other) < 1e-12


def test_kept_responses_and_pressures_count_in_the_cache(monkeypatch) -> None:
    """What a coupled discretization keeps after it was cached (time-stepped responses,
    q at points) is measured again, so the cache's byte budget holds; its own bounds drop
    the least recently used responses first."""
    from core.cache import clear_caches
    from core.engines.nystrom import COUPLED

    clear_caches()
    core.solve(_scaled_pair(1.0))
    (coupled,) = COUPLED.values()
    held = coupled.nbytes
    assert COUPLED.size_bytes == held
    one_set = coupled._responses.nbytes
    monkeypatch.setattr(coupled._responses, "max_bytes", int(2.5 * one_set))
    for k in range(5):  # other load histories: other responses
        e = _scaled_pair(1.0)
        e["punches"][1]["loading"]["force"] = {"kind": "ramp", "start": 1e5, "end": 3e5,
                                                "duration": 10.0 + k}
        core.solve(e)
    assert len(coupled._responses) == 2
    assert COUPLED.size_bytes == coupled.nbytes > held


def test_far_apart_punches_age_as_single_punches() -> None:
    young = scene_file("young_concrete_50_years")
    d = _creeping(_pair(60.0, tol=1e-4), young["base"]["creep"])
    d["base"]["age_at_loading"] = young["base"]["age_at_loading"]
    result = core.solve(d)
    for k in range(2):
        alone, coupled = _single(d, k), result.punches[k]
        # measured: 3.6e-15 (a design code's aging creep, fitted by exponentials)
        for q in ("settlement", "tilt"):
            assert _relative(getattr(coupled, q), getattr(alone, q)) < 1e-9, q
        # the estimates of one march and of two apart: measured 1.0e-3 apart (relative)
        assert coupled.info["time_error_estimate"] == pytest.approx(
            alone.info["time_error_estimate"], rel=1e-2)


@pytest.mark.parametrize("first", [("settlement", "tilt"), ("settlement", "moment"),
                                   ("tilt", "force"), ("force", "moment")])
def test_the_modal_form_meets_the_bordered_solve_in_every_statement(first: tuple) -> None:
    """A creep too small to matter: the modal form (every pair of statements) gives the
    elastic answer of the bordered system."""
    values = {"settlement": 3e-5, "tilt": 1e-6, "force": 4e5, "moment": 1e4}
    for second in (("settlement", "tilt"), ("settlement", "moment"), ("tilt", "force"),
                   ("force", "moment")):
        loads = ({q: values[q] for q in first}, {q: 0.5 * values[q] for q in second})
        d = _pair(0.3, loads=loads)
        elastic = core.solve(d)
        d["base"]["creep"] = dict(CREEP, compliance=3.0e-20)  # creep coefficient 1e-9
        modal = core.solve(d)
        for e, m in zip(elastic.punches, modal.punches, strict=True):
            x = np.linspace(-1.0, 1.0, 11) * e.scene.half_width
            # measured: at most 6.6e-10 over the 16 pairs (the creep coefficient is 1e-9)
            for q in QUANTITIES:
                assert _relative(getattr(m, q), getattr(e, q)) < 1e-8, (second, q)
            assert _relative(m.pressure(x), e.pressure(x)) < 1e-8


def test_a_symmetric_pair_creeps_alike() -> None:
    d = _creeping(_base())
    load = {"force": 5e5, "moment": 0.0}
    d["punches"] = [{"center": -1.2, "half_width": 1.0, "loading": load},
                    {"center": 1.2, "half_width": 1.0, "loading": copy.deepcopy(load)}]
    left, right = core.solve(d).punches
    np.testing.assert_allclose(left.settlement, right.settlement, rtol=1e-10)
    np.testing.assert_allclose(left.tilt, -right.tilt, rtol=1e-8)
    assert left.settlement[-1] > 1.5 * left.settlement[0]


# ------------------------------------------------------------------------- refusals


def test_overlapping_punches_are_refused_naming_both() -> None:
    d = _pair(-0.1)
    with pytest.raises(ValueError, match=r"punches: punches\[0\] and punches\[1\] overlap"):
        core.solve(d)


@pytest.mark.parametrize(("change", "message"), [
    (lambda d: d["coating"][0].update(thickness={"kind": "linear", "start": 0.02,
                                                 "end": -0.03}),
     r"coating\[0\]\.thickness: must be > 0, is -[\d.e-]+ m at x = 0\.48\d* m"),
    (lambda d: d.update(punch={"half_width": 1.0}),
     r"punch: give either punch and loading \(one punch\) or punches"),
    (lambda d: d["punches"][1]["loading"].update(settlement=0.001),
     r"punches\[1\]\.loading: exactly two"),
    (lambda d: d["punches"][1].update(half_width=-1.0),
     r"punches\[1\]\.half_width: "),
    (lambda d: d["punches"][0].pop("center"), r"punches\[0\]\.center: required"),
])
def test_what_is_not_coupled_yet_is_refused(change: Any, message: str) -> None:
    d = _pair(0.5)
    change(d)
    with pytest.raises(ValueError, match=message):
        core.solve(d)


def test_the_json_schema_takes_either_form() -> None:
    from core.scene import load_json_schema, schema_errors

    schema = load_json_schema("scene")
    assert not schema_errors(_pair(0.5), schema)
    both = _pair(0.5)
    both["punch"] = {"half_width": 1.0}
    assert schema_errors(both, schema)


def test_three_punches_in_a_row() -> None:
    d = _base()
    load = {"force": 4e5, "moment": 0.0}
    d["punches"] = [{"center": c, "half_width": 0.5, "loading": dict(load)}
                    for c in (-1.3, 0.0, 1.3)]
    left, middle, right = core.solve(d).punches
    np.testing.assert_allclose(left.settlement, right.settlement, rtol=1e-12)
    np.testing.assert_allclose(left.tilt, -right.tilt, rtol=1e-10)
    # measured: 1.7e-20 rad against 8.4e-6 rad at the sides
    assert np.max(np.abs(middle.tilt)) < 1e-10 * np.max(np.abs(left.tilt))
    # the middle one has a neighbour on each side: it settles most
    assert np.all(middle.settlement > left.settlement)


def test_a_load_change_under_creep_reuses_the_stepped_responses() -> None:
    """Creep: the coupled answer is a sum of time-stepped responses to each load's shape
    (cached); a new force of either punch is a new amplitude, so no time stepping runs
    again (counted), and the answer is the one a fresh solve gives."""
    from core.cache import clear_caches

    d = _creeping(_pair(2.0))
    first = core.solve(d)
    built = first.punches[0].info["coupled_builds"]["time_response"]
    assert built >= 2  # a force shape of each punch (and the moments)
    moved = copy.deepcopy(d)
    moved["punches"][0]["loading"]["force"] *= 1.3
    moved["punches"][1]["loading"]["force"] *= 0.7
    again = core.solve(moved)
    assert again.punches[0].info["coupled_builds"]["time_response"] == built
    clear_caches()
    fresh = core.solve(moved)
    for k in range(2):
        for q in QUANTITIES:
            # measured: equal to rounding (the same parts, stepped the same way)
            assert _relative(getattr(again.punches[k], q),
                             getattr(fresh.punches[k], q)) < 1e-12, q


def test_the_time_steps_land_on_a_jump_of_any_punchs_loads(monkeypatch) -> None:
    # the preset's new footing is loaded a year after the old one: the steps of the
    # coupled creep must land on that jump of the second punch's force (with the first
    # punch's breaks only, the fixed grids could not resolve it and, refined to 993 steps,
    # gave way to adaptive stepping: 2.9 s of CPU instead of 0.8 s, the same answers to
    # 8e-8 at tol 1e-4)
    from core.engines.nystrom import multi_modal
    from core.presets import read_preset

    seen: list[tuple[float, ...]] = []
    stepping = multi_modal.solve_degenerate

    def spy(*args: Any, **kwargs: Any) -> Any:
        seen.append(tuple(kwargs.get("breaks", ())))
        return stepping(*args, **kwargs)

    monkeypatch.setattr(multi_modal, "solve_degenerate", spy)
    d = read_preset("new_footing_beside_old")
    jumps = {b for sub in punches_from_dict(d).scenes for b in sub.dimensionless.time_breaks}
    assert jumps  # the second punch's force steps up at 365.25 days
    core.solve(d)
    assert seen and all(set(breaks) == jumps for breaks in seen)


def test_a_scene_of_several_punches_saves_as_it_loads(tmp_path) -> None:
    """``save_scene`` refused what ``load_scene`` gave ("scene: must be a JSON object, got
    PunchesScene(...)", a 15 KB message); its dict was refused too."""
    scene = core.load_scene("preset:new_footing_beside_old")
    core.save_scene(scene, tmp_path / "object.json")
    core.save_scene(scene.to_dict(), tmp_path / "dict.json")
    assert (tmp_path / "object.json").read_text() == (tmp_path / "dict.json").read_text()
    again = core.load_scene(tmp_path / "object.json")
    assert type(again) is type(scene) and again.to_dict() == scene.to_dict()
