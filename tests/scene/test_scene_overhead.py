"""What a scene solve shares between scenes of the same geometry, and the batched
golden-section search of the gap minimum (same points as the one-at-a-time search)."""

from __future__ import annotations

import copy

import numpy as np
import pytest

from core.scene import scene_from_dict, solve
from core.scene.golden_section import golden_minimum, golden_minimum_batched
from tests.conftest import edited, scene_file


@pytest.mark.parametrize("depth", [1, 3, 5, 8])
def test_batched_golden_search_meets_the_same_points(depth):
    rng = np.random.default_rng(7)
    for _ in range(50):
        a, b, c = rng.normal(size=3)

        def fn(x, a=a, b=b, c=c):
            # smooth, several minima, and a jump: every branch of the search is taken
            return a * np.sin(3 * x + b) + c * x * x + (x > 0.1) * b

        lo, hi = sorted(rng.normal(size=2))
        one_at_a_time = golden_minimum(lambda s, fn=fn: float(fn(np.array([s]))[0]), lo, hi)
        # exactly equal: the same points, evaluated elementwise
        assert golden_minimum_batched(fn, lo, hi, depth=depth) == one_at_a_time


@pytest.mark.parametrize("name", ["worn_coating", "patched_insert", "uniform_flat"])
def test_a_load_change_gives_the_answer_of_a_fresh_scene(name):
    """Results of a scene whose geometry was solved before (shared samples, extremes,
    model error) equal those computed with nothing shared."""
    from core.cache import clear_caches

    d = scene_file(name)
    solve(d)
    other = copy.deepcopy(d)
    quantity = next(iter(other["loading"]))
    value = other["loading"][quantity]
    other["loading"][quantity] = 1.1 * value if value else 1e-9
    shared = solve(other)
    clear_caches()
    fresh = solve(scene_from_dict(other))
    for key in ("flags", "model_error_estimate", "model_error", "coating_model"):
        assert shared.info[key] == fresh.info[key]
    assert shared.info["dimensional"] == fresh.info["dimensional"]
    # identical inputs to the same engine: identical answers (nothing is tolerated)
    for field in ("settlement", "tilt", "force", "moment"):
        assert np.array_equal(getattr(shared, field), getattr(fresh, field))
    assert np.array_equal(shared.pressure_on_grid, fresh.pressure_on_grid)


@pytest.mark.parametrize("name", ["rounded_graded", "patched_insert", "worn_coating"])
def test_the_samples_are_the_union_of_every_profiles_samples(name):
    """Constant profiles are sampled once: the samples are still the union of all."""
    from core.scene.model import DENSE_SAMPLES

    scene = scene_from_dict(scene_file(name))
    a = scene.half_width
    profiles = [scene.shape] + [p for layer in scene.coating
                                for p in (layer.thickness, layer.modulus, layer.poisson)]
    union = np.unique(np.concatenate([np.linspace(-a, a, DENSE_SAMPLES)] + [
        p.sample_points((-a, a)) for p in profiles]))
    assert np.array_equal(scene.sample_x, union)


def test_a_scene_dict_with_new_loads_is_validated_as_a_load_change(stage_evaluations):
    """A scene dict equal to one validated before but for its load values (a load slider,
    a study over a load) is checked as a load change: its geometry, base and times are not
    validated again, and a geometry change is."""
    d = scene_file("uniform_flat")
    scene_from_dict(d)
    assert stage_evaluations().get("validated_scenes") == 1
    for factor in (1.1, 1.2, 0.5):
        scene_from_dict(edited("loading.force", factor * d["loading"]["force"], d))
    assert stage_evaluations().get("validated_scenes") == 1
    scene_from_dict(edited("punch.half_width", 1.01 * d["punch"]["half_width"], d))
    assert stage_evaluations().get("validated_scenes") == 2


@pytest.mark.parametrize(("path", "value"), [
    ("loading.force", -1e30),
    ("loading.force", "x * "),
    ("loading.force", [[0, 1], [0, 2]]),
    ("loading.force", None),
])
def test_a_bad_load_after_a_good_scene_is_refused_as_in_a_fresh_one(path, value):
    """The load-change path refuses a bad load with the words of a full validation."""
    from core.cache import clear_caches

    d = scene_file("uniform_flat")
    scene_from_dict(d)  # remembered: the bad dict below differs in a load only
    bad = edited(path, value, d)
    with pytest.raises(ValueError) as shared:
        solve(bad)
    clear_caches()
    with pytest.raises(ValueError) as fresh:
        solve(bad)
    assert str(shared.value) == str(fresh.value)
    assert str(shared.value).startswith(path)


def test_other_given_loads_are_validated_in_full():
    """Loads naming other quantities (another statement) take the full validation."""
    d = scene_file("uniform_flat")
    scene_from_dict(d)
    other = copy.deepcopy(d)
    other["loading"] = {"settlement": 0.001, "tilt": 0.0}
    scene = scene_from_dict(other)
    assert set(scene.loading) == {"settlement", "tilt"}
    other["loading"] = {"settlement": 0.001}
    with pytest.raises(ValueError, match="^loading: exactly two"):
        scene_from_dict(other)
