"""Caches hand out values that cannot be changed, under keys that cannot collide.

A cached value is shared by every later caller: a write into it (``+=``, a slice
assignment, an in-place LAPACK call) would change the next caller's answer, an
order-dependent wrong answer. So every cache returns read-only arrays. And a key must
name its inputs: one built from ``id()`` of an object that is gone matches the next
object given that address.
"""

from __future__ import annotations

import copy
import gc

import numpy as np
import pytest


def _written(array: np.ndarray) -> bool:
    """Whether an in-place write into ``array`` goes through."""
    try:
        array.flat[0] += 0.0
    except ValueError:
        return False
    return True


def test_stage_cache_values_are_read_only():
    from core.cache import StageCache

    cache = StageCache("test_read_only_values", max_items=4)
    value, _ = cache.get_or_compute("k", lambda: (np.ones(3), {"a": np.zeros(2)}))
    again, was_cached = cache.get_or_compute("k", lambda: None)
    assert was_cached and again is value
    assert not _written(value[0]) and not _written(value[1]["a"])


def test_pair_tables_are_read_only():
    from core.discretize import Panels, node_rows, pair_tables

    panels = Panels.from_edges(np.array([-1.0, -0.25, 0.0, 0.5, 1.0]))
    node_rows(1.0, panels, panels, np.arange(panels.n_panels))
    store = pair_tables.stored()
    assert store.index
    for name in ("near", "reference", "correction", "slope", "steepest"):
        assert not _written(getattr(store, name))


def test_module_tables_are_read_only():
    from core.kernel import log_moments, plane, values

    shared = [plane._EVEN, plane._TABLE, plane._SCALES, plane._POLES,
              values._even_chebyshev(), values._even_coefficients(1e-8),
              *log_moments._outer_rule(15)]
    assert not any(_written(a) for a in shared)


def test_prepared_rows_are_read_only():
    from core.engines.nystrom import prepare

    prepared = prepare(1.0, 0.05, 0.0, tol=1e-6)
    rows = prepared.rows(np.linspace(-0.9, 0.9, 5))
    assert not _written(rows)


def test_fitted_kernel_values_are_read_only():
    """The fit is cached (its arrays shared) and so are its amplitudes at the last ages
    asked for (every caller at those ages gets views of the same arrays)."""
    from core.creep.kernel_fit import fit_kernel
    from core.creep.models import ExponentialCreep

    law = ExponentialCreep(modulus=3e10, compliance=6e-11, rate=0.05).dimensionless_kernel(28.0)
    fitted = fit_kernel(lambda t, s: law(t, s), end=10.0)
    tau = np.array([1.0, 2.0, 5.0])
    assert not any(_written(a) for a in (fitted.thetas, fitted.coef, *fitted.amplitudes(tau)))


def test_fingerprint_separates_what_differs():
    from core.cache import fingerprint

    distinct = [1, 1.0, "1", "1.0", True, None, (1, 2), (12,), ("1", "2"), ("12",),
                np.arange(4.0), np.arange(4.0).reshape(2, 2), np.arange(4),
                0.1, float(np.nextafter(0.1, 1.0)), -0.0, 0.0]
    keys = [fingerprint(v) for v in distinct]
    assert len(set(keys)) == len(keys)
    # the same content gives the same key, whatever object holds it
    assert fingerprint(np.arange(4.0)) == fingerprint(np.arange(4.0).copy())


def test_same_object_key_holds_its_object():
    """The id of an object kept in a key is not given to another while the key lives."""
    from core.cache import SameObject

    keys = []
    for k in range(50):
        keys.append(SameObject(lambda t, s, k=k: k))
        # the young generation holds every object made since (a full collection walks
        # the whole test process: 0.23 s each, 11 s in all)
        gc.collect(0)
    assert len({id(key.obj) for key in keys}) == 50
    assert len(set(keys)) == 50
    assert keys[3] == SameObject(keys[3].obj)


def test_unkeyed_kernel_response_is_not_reused_for_another(monkeypatch):
    """Two plain-callable creep kernels solved one after the other on one prepared
    geometry: the second gets its own answer, even when it has the first one's id (as a
    kernel does that takes over the address of one freed before). Keyed by ``id()``, the
    second kernel was given the first one's response."""
    import core.engines.nystrom.prepared
    from core.engines.nystrom import prepare

    # tol 1e-10: no sum-of-exponentials fit is within the budget, so the kernels are
    # stepped as they are and known by identity only
    prepared = prepare(1.0, 0.05, 0.0, tol=1e-10)
    from core.creep.models import ExponentialCreep

    # two creep laws, each hidden in a plain callable (no key to tell them apart)
    laws = [ExponentialCreep(modulus=3e10, compliance=c, rate=0.05).dimensionless_kernel(28.0)
            for c in (3e-11, 6e-11)]
    kernels = [lambda t, s, law=law: law(t, s) for law in laws]

    def settlement(kernel) -> float:
        return float(prepared.solve([1.0, 2.0], kernel=kernel, force=1.0,
                                    moment=0.1).settlement[-1])

    alone = []
    for kernel in kernels:
        prepared._responses.clear()
        alone.append(settlement(kernel))
    prepared._responses.clear()
    # every object the module asks the id of has the same one: an address reused
    monkeypatch.setattr(core.engines.nystrom.prepared, "id", lambda obj: 1, raising=False)
    in_turn = [settlement(kernel) for kernel in kernels]
    assert alone[0] != pytest.approx(alone[1], rel=1e-3)
    # measured: equal to the last digit (the same time march)
    assert in_turn == pytest.approx(alone, rel=1e-12)


def test_pair_tables_emptied_when_full_still_answer_every_key(monkeypatch):
    """When a call's new keys would pass the store's limit, the store is emptied: the
    call's keys the old store held must then come into the new one too (else KeyError)."""
    from core.discretize import Panels, node_rows, pair_tables

    first = Panels.from_edges(np.array([-1.0, -0.5, 0.0, 0.5, 1.0]))
    second = Panels.from_edges(np.array([-1.0, -0.75, -0.5, 0.0, 0.25, 0.5, 1.0]))
    pair_tables.clear()
    alone = node_rows(1.0, second, second, np.arange(second.n_panels))
    pair_tables.clear()
    node_rows(1.0, first, first, np.arange(first.n_panels))
    held = len(pair_tables.stored().index)
    # room for what the first grid left and one more: the second grid's keys pass it
    monkeypatch.setattr(pair_tables, "MAX_KEYS", held + 1)
    again = node_rows(1.0, second, second, np.arange(second.n_panels))
    assert np.array_equal(alone, again)
    pair_tables.clear()


def test_a_grown_value_is_measured_again():
    """A value that grew in place after it was cached (answers kept with a prepared
    geometry) counts at its new size: the least recently used others are dropped to stay
    within the budget, and a value larger than the whole budget is no longer kept."""
    from core.cache import StageCache

    sizes = {"a": 30, "b": 30, "c": 30}
    cache = StageCache("test_grown_values", max_items=8, max_bytes=100,
                       sizeof=lambda value: sizes[value])
    for key in sizes:
        cache.get_or_compute(key, lambda key=key: key)
    assert cache.size_bytes == 90
    sizes["b"] = 60
    cache.resize("b")  # "a" is the least recently used: dropped
    assert cache.get("a") is None and cache.size_bytes == 90
    sizes["c"] = 120
    cache.resize("c")
    assert cache.get("c") is None and cache.get("b") == "b" and cache.size_bytes == 60
    cache.resize("z")  # not held: nothing happens
    assert cache.size_bytes == 60


def test_a_prepared_geometrys_kept_responses_count_in_its_size():
    """The time-stepped responses a prepared geometry keeps for load changes count in
    its size, and so in the cache's budget."""
    from core.cache import clear_caches
    from core.engines.nystrom import PREPARED, solve_with_prepared

    clear_caches()
    times = np.linspace(1.0, 10.0, 5)
    kernel = lambda t, s: 0.5 * np.exp(-(t - s))  # noqa: E731
    solve_with_prepared(2.0, 1.0, 0.0, times, kernel=kernel, force=1.0, moment=0.0,
                        tol=1e-6)
    (prepared,) = PREPARED.values()
    before = prepared.nbytes
    solve_with_prepared(2.0, 1.0, 0.0, times, kernel=kernel,
                        force=lambda t: 1.0 + 0.1 * t, moment=0.0, tol=1e-6)
    assert prepared.nbytes > before and PREPARED.size_bytes == prepared.nbytes


def test_kept_values_drop_the_least_recently_used_and_keep_the_newest():
    """An object's own kept values (responses of a prepared geometry): bounded in items
    and bytes, a read refreshes a value, the newest is kept even above the bound."""
    from core.cache import KeptValues

    kept = KeptValues(max_items=3, max_bytes=100, sizeof=len)
    for key in "abc":
        assert kept.put(key, key * 30) == []
    assert kept.get("a") == "a" * 30           # now the most recently used
    assert kept.put("d", "d" * 30) == ["b" * 30]  # four items: the oldest goes
    assert kept.nbytes == 90 and "a" in kept and "b" not in kept
    assert kept.put("e", "e" * 200) == ["c" * 30, "a" * 30, "d" * 30]
    assert kept.values() == ["e" * 200] and kept.nbytes == 200
    kept.drop(lambda key: key != "e")
    assert len(kept) == 0 and kept.nbytes == 0


def _with_force(scene: dict, force: object, times: list[float]) -> dict:
    d = copy.deepcopy(scene)
    d["times"] = times
    if "punches" in d:
        d["punches"][0]["loading"]["force"] = force
    else:
        d["loading"]["force"] = force
    return d


@pytest.mark.parametrize("preset", ["uniform_flat", "new_footing_beside_old"])
@pytest.mark.parametrize(("times", "first"), [
    # one output time: a force rising linearly to 500 kN/m and one held at 500 kN/m
    # were one shape there, and the second's answer was given for the first (5 % off)
    ([365.0], 5e5),
    # two output times the loads meet at, held before the first instead of rising
    ([100.0, 365.0], {"kind": "table", "interpolation": "linear",
                      "points": [[0.0, 1e5 + 4e5 * 100 / 365],
                                 [100.0, 1e5 + 4e5 * 100 / 365], [365.0, 5e5]]}),
    # a ramp to the first output time's value, ending before it, of another length
    ([1.0, 10.0, 365.0], {"kind": "ramp", "start": 0.0, "end": 5e5, "duration": 0.3}),
])
def test_a_creep_answer_does_not_depend_on_the_loads_solved_before(
        preset: str, times: list[float], first: object) -> None:
    """The cached creep responses are keyed by each load's shape over the march's whole
    span, not at the output times alone (core.engines.nystrom.prepared.SHAPE_KEY_SAMPLES),
    for one punch and several."""
    from core.cache import clear_caches
    from core.presets import read_preset
    from core.scene import solve

    scene = read_preset(preset)
    rising = ({"kind": "ramp", "start": 0.0, "end": 5e5, "duration": 0.1}
              if isinstance(first, dict) and first["kind"] == "ramp"
              else {"kind": "linear", "start": 1e5, "end": 5e5})
    clear_caches()
    fresh = solve(_with_force(scene, rising, times))
    clear_caches()
    solve(_with_force(scene, first, times))
    after = solve(_with_force(scene, rising, times))
    if preset == "new_footing_beside_old":
        fresh, after = fresh.punches[0], after.punches[0]
    np.testing.assert_array_equal(after.settlement, fresh.settlement)
    np.testing.assert_array_equal(after.tilt, fresh.tilt)


def test_several_punches_key_a_temporary_overload_on_both_sides_of_its_steps() -> None:
    """Two overloads of punch 0 with the same steps, 1.2e6 and 9e5 N/m, between two of
    the key's samples: the second took the first's answer (1.3 % off) until the key was
    sampled on both sides of every step, as one punch's was (a review)."""
    from core.cache import clear_caches
    from core.presets import read_preset
    from core.scene import solve

    scene = read_preset("new_footing_beside_old")
    scene["solver"]["tol"] = 1e-4

    def overload(peak: float) -> dict:
        return _with_force(scene, {"kind": "step", "values": [6e5, peak, 6e5],
                                   "breaks": [1170.0, 1190.0]}, scene["times"])

    clear_caches()
    fresh = solve(overload(9e5)).punches[0]
    clear_caches()
    solve(overload(1.2e6))
    after = solve(overload(9e5)).punches[0]
    np.testing.assert_array_equal(after.settlement, fresh.settlement)
