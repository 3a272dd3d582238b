"""The exact layered answer is prepared once per geometry: a load change builds nothing."""

from __future__ import annotations

import copy

import numpy as np

from core import solve
from core.cache import clear_caches
from core.engines.layered.cache import (
    GAP_MOMENTS,
    LAYERED_OPERATOR,
    LAYERED_RESPONSE,
    LAYERED_TABLE,
)
from tests.conftest import scene_file

STAGES = {"layered_table": LAYERED_TABLE, "layered_operator": LAYERED_OPERATOR,
          "layered_response": LAYERED_RESPONSE}
QUANTITIES = ("settlement", "tilt", "force", "moment")


def rounded_graded(loading: dict) -> dict:
    """The crowned punch on three smooth layers over an elastic base, one output time."""
    d = scene_file("rounded_graded")
    d["base"]["creep"] = {"model": "elastic", "modulus": 3.4e10}
    d["times"] = {"end": 1.0, "count": 1}
    d["loading"] = loading
    return d


def builds() -> dict[str, int]:
    """Evaluations (builds) of each cache of the layered solve so far."""
    return {name: cache.evaluations for name, cache in STAGES.items()}


def test_load_changes_reuse_the_geometry_and_a_geometry_change_builds_again() -> None:
    clear_caches()
    scene = rounded_graded({"tilt": 0.0, "force": 8e5})
    start = builds()
    first = solve(scene)
    assert first.info["coating_model"] == "exact layered"
    after_first = builds()
    assert all(after_first[name] > start[name] for name in STAGES)

    # load-only changes, and another statement of the same geometry: nothing is built
    changed = []
    for loading in ({"tilt": 0.0, "force": 6e5}, {"tilt": 1e-5, "force": 9e5},
                    {"settlement": 3e-5, "moment": 2e3}):
        d = copy.deepcopy(scene)
        d["loading"] = loading
        result = solve(d)
        assert result.info["coating_model"] == "exact layered"
        assert builds() == after_first, loading
        changed.append((d, result))

    # the cached answer is the one a cold solve gives: the same arithmetic on the same
    # unit responses (measured: equal to the last bit; 1e-12 leaves room for BLAS order)
    clear_caches()
    for d, result in changed:
        cold = solve(d)
        for q in QUANTITIES:
            np.testing.assert_allclose(getattr(result, q), getattr(cold, q), rtol=1e-12,
                                       atol=0.0, err_msg=q)
    after_cold = builds()

    # another punch shape on the same stack: new unit responses, the same operator
    d = copy.deepcopy(scene)
    d["punch"]["shape"]["coefficients"] = [0.0, 0.0, 5e-5]
    solve(d)
    now = builds()
    assert now["layered_response"] > after_cold["layered_response"]
    assert now["layered_operator"] == after_cold["layered_operator"]
    assert now["layered_table"] == after_cold["layered_table"]

    # another coating: the stack's table and operator are built again
    d = copy.deepcopy(scene)
    d["coating"][0]["modulus"] = 5e8
    solve(d)
    again = builds()
    assert again["layered_table"] > now["layered_table"]
    assert again["layered_operator"] > now["layered_operator"]


def test_the_stage_report_says_what_a_load_change_redid() -> None:
    clear_caches()
    scene = rounded_graded({"tilt": 0.0, "force": 8e5})
    stages = solve(scene).info["stages"]
    assert not stages["operator"]["cached"] and not stages["galerkin"]["cached"]
    scene["loading"]["force"] = 7e5
    stages = solve(scene).info["stages"]
    assert stages["operator"]["cached"] and stages["galerkin"]["cached"]
    assert not stages["solve"]["cached"]


def test_a_worker_s_budget_bounds_the_layered_caches_too() -> None:
    from core.budget import STAGE_CACHE_BYTES, set_stage_cache_budget
    from core.engines.layered.cache import LAYERED_BYTES

    try:
        set_stage_cache_budget(STAGE_CACHE_BYTES // 4)
        for name, cache in STAGES.items():
            assert cache.max_bytes == LAYERED_BYTES[name] // 4, name
    finally:
        set_stage_cache_budget(STAGE_CACHE_BYTES)
    assert all(cache.max_bytes == LAYERED_BYTES[name] for name, cache in STAGES.items())


def test_kept_chebyshev_rows_are_the_computed_ones_and_bounded():
    from core.engines.layered import solve as ls
    from core.engines.layered.cache import CHEBYSHEV_ROWS

    t = np.cos(np.linspace(0.0, np.pi, 91))
    direct = np.cos(np.outer(np.arccos(np.clip(t, -1, 1)), np.arange(40)))
    first = ls._chebyshev_rows(t, 40)
    assert ls._chebyshev_rows(t.copy(), 40) is first  # equal points: the kept rows
    np.testing.assert_array_equal(first, direct)  # bit for bit
    assert not first.flags.writeable
    kept = CHEBYSHEV_ROWS
    for k in range(2 * kept.max_items):
        ls._chebyshev_rows(t, 41 + k)
    assert len(kept._kept) == kept.max_items
    big = np.linspace(-1.0, 1.0, ls._CHEBYSHEV_MOST_VALUES // 40 + 1)
    ls._chebyshev_rows(big, 40)
    assert all(key[0] != big.tobytes() for key in kept._kept)


def test_a_new_coating_under_the_same_punch_reuses_the_gap_moments():
    clear_caches()
    scene = rounded_graded({"tilt": 0.0, "force": 8e5})
    solve(scene)
    before = dict(GAP_MOMENTS._kept)
    d = copy.deepcopy(scene)
    d["coating"][0]["modulus"] = 4e8
    solve(d)
    assert GAP_MOMENTS._kept.keys() == before.keys()
    assert all(GAP_MOMENTS._kept[key] is before[key] for key in before)
