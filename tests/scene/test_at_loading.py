"""The scene at the instant of loading (``core.scene.elastic_at_loading``): its base
elastic at the modulus at loading, its answer at t = 0 the creeping scene's own up to the
coating model.

Measured (relative to each history's largest value at t = 0): the lift-off preset's
settlement 5.7e-8 and tilt 9.7e-8, its zone's end 6.8e-8 m apart, against estimates of
8.0e-7 (creep) and 1.6e-8 (elastic); the default scene with a crown of R = 25 km:
settlement 2.4e-8 against 1.0e-7, its zone's ends 6.3e-10 m apart; the two footings of
``new_footing_beside_old`` (MC2010 creep): the bound below holds with the same margin.
The bound is the sum of the two answers' estimates where both answers come from the
thin-layer model. An even coating in full contact on an elastic base is answered by the
exact layered kernel instead: the default scene's settlement at t = 0 then differs by
0.23 %, the thin layer's own error, within the 0.35 % its answer estimates.
"""

from __future__ import annotations

import copy

import numpy as np
import pytest

from core.presets import read_preset
from core.scene import creeps, elastic_at_loading, modulus_at_loading, scene_from_dict, solve


def _crowned(radius_m: float) -> dict:
    scene = read_preset("uniform_flat")
    scene["punch"]["shape"] = {"kind": "polynomial",
                               "coefficients": [0.0, 0.0, 1.0 / (2.0 * radius_m)]}
    return scene


def _estimate(*answers) -> float:
    return sum(float(a.info["error_estimate"]) for a in answers)


@pytest.mark.parametrize("scene", [read_preset("eccentric_footing_liftoff"),
                                   _crowned(25e3)], ids=["lift-off preset", "crown"])
def test_the_answer_at_loading_is_the_creeping_scenes_own(scene) -> None:
    creeping = solve(scene)
    elastic_scene = elastic_at_loading(scene)
    assert elastic_scene["base"]["creep"] == {
        "model": "elastic", "modulus": scene_from_dict(scene).modulus_at_loading()}
    assert not creeps(elastic_scene) and creeps(scene)
    elastic = solve(elastic_scene)
    assert creeping.times[0] == elastic.times[0] == 0.0
    bound = _estimate(creeping, elastic)
    for name in ("settlement", "tilt"):
        ours, theirs = getattr(elastic, name), getattr(creeping, name)
        assert abs(ours[0] - theirs[0]) <= bound * np.max(np.abs(creeping.settlement)) * (
            1.0 if name == "settlement" else 1.0 / scene["punch"]["half_width"]), name
    # both answer by lift-off at loading, with the same zone
    assert creeping.info["contact"] == elastic.info["contact"] == "unilateral"
    a = scene["punch"]["half_width"]
    ends = a * (float(creeping.info["zone_end_error"]) + float(elastic.info["zone_end_error"]))
    for (lo, hi), (lo_e, hi_e) in zip(creeping.contact_set[0], elastic.contact_set[0],
                                      strict=True):
        assert abs(lo - lo_e) <= ends and abs(hi - hi_e) <= ends
    # later the base creeps in one and not the other
    assert creeping.settlement[-1] > 1.1 * elastic.settlement[-1]


def test_an_even_coating_differs_at_loading_by_the_coating_models_error() -> None:
    scene = read_preset("uniform_flat")
    creeping = solve(scene)
    elastic = solve(elastic_at_loading(scene))
    assert creeping.info["coating_model"] != elastic.info["coating_model"] == "exact layered"
    bound = float(creeping.info["model_error_estimate"]) + _estimate(creeping, elastic)
    off = abs(elastic.settlement[0] - creeping.settlement[0]) / abs(creeping.settlement[0])
    assert 1e-3 < off <= bound, (off, bound)


def test_several_punches_and_the_input_left_as_it_was() -> None:
    scene = read_preset("new_footing_beside_old")
    given = copy.deepcopy(scene)
    elastic_scene = elastic_at_loading(scene)
    assert scene == given
    assert {k: v for k, v in elastic_scene.items() if k != "base"} == {
        k: v for k, v in scene.items() if k != "base"}
    assert elastic_scene["base"]["creep"]["model"] == "elastic"
    creeping, elastic = solve(scene), solve(elastic_scene)
    for ours, theirs in zip(elastic.punches, creeping.punches, strict=True):
        bound = _estimate(ours, theirs) * np.max(np.abs(theirs.settlement))
        assert abs(ours.settlement[0] - theirs.settlement[0]) <= bound


def test_an_elastic_base_comes_back_as_a_copy_and_bad_input_names_its_field() -> None:
    scene = read_preset("worn_coating")
    assert not creeps(scene)
    same = elastic_at_loading(scene)
    assert same == scene and same is not scene
    # only the fields it reads are checked here (the solve checks the rest)
    bad = read_preset("uniform_flat")
    bad["base"]["age_at_loading"] = -1.0
    with pytest.raises(ValueError, match=r"^base\.age_at_loading: must be > 0"):
        elastic_at_loading(bad)
    bad = read_preset("uniform_flat")
    bad["base"]["creep"] = {"model": "no such law"}
    with pytest.raises(ValueError, match=r"^base\.creep"):
        elastic_at_loading(bad)
    bad = read_preset("uniform_flat")
    del bad["base"]["age_at_loading"]
    with pytest.raises(ValueError, match=r"^base\.age_at_loading: missing"):
        elastic_at_loading(bad)
    # the modulus at loading as the validated scene has it, the design-code laws too
    for key in ("young_concrete_50_years", "eccentric_footing_liftoff", "uniform_flat"):
        scene = read_preset(key)
        assert modulus_at_loading(scene) == scene_from_dict(scene).modulus_at_loading()
    with pytest.raises(ValueError, match=r"^scene: must be a scene dict"):
        elastic_at_loading([1, 2])  # type: ignore[arg-type]
    assert not creeps({})
