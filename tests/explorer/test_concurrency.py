"""Many sessions at once: shared caches stay bounded and correct, sessions stay apart.

The explorer serves a classroom from one process: every browser session has its own
state and controller, and all share the core's stage caches, the explorer's result cache
and a small solver pool. Solving from several threads must give what serial solves give;
one session's bad input or slow solve must not reach another; a download must hold the
result on screen, also while a newer solve runs.
"""

from __future__ import annotations

import asyncio
import copy
import json
import random
import threading
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np
import pytest

from core import scene_from_dict, solve
from core.cache import _REGISTRY, _REGISTRY_LOCK, StageCache, cache_report, clear_caches
from explorer.model import ExplorerState, presets
from explorer.solving import RESULTS, SolveController, approx_bytes

pytestmark = pytest.mark.timeout(600)

PRESETS = presets()


def small(scene: dict[str, Any], count: int = 6) -> dict[str, Any]:
    scene = copy.deepcopy(scene)
    scene["times"] = {"end": 200.0, "count": count, "spacing": "log"}
    scene["solver"] = {"tol": 1e-5}
    return scene


def scenes() -> list[dict[str, Any]]:
    """Different geometries, materials and loads (all six presets, and load variants that
    share their geometry with a preset)."""
    # the presets of one punch (the histories compared are a single punch's)
    out = [small(s) for s in PRESETS.values() if "punch" in s]
    for k, force in enumerate((3e5, 7e5)):
        variant = small(PRESETS["uniform_flat"])
        variant["loading"]["force"] = force
        variant["loading"]["moment"] = 2e4 * (k + 1)
        out.append(variant)
    return out


def answer(scene: dict[str, Any]) -> dict[str, np.ndarray]:
    result = solve(scene)
    out = {q: np.array(getattr(result, q)) for q in ("settlement", "tilt", "force", "moment")}
    out["pressure"] = np.array(result.pressure_on_grid)
    return out


def assert_same_answers(a: dict[str, np.ndarray], b: dict[str, np.ndarray]) -> None:
    for key in a:
        # bitwise equal: every stage is a pure function of its inputs, and a cached stage
        # returns the very value a fresh evaluation computes (measured: no difference)
        np.testing.assert_array_equal(a[key], b[key], err_msg=key)


def test_threads_solving_at_once_agree_with_serial_solves() -> None:
    work = scenes()
    clear_caches()
    serial = [answer(s) for s in work]
    clear_caches()
    # each scene three times, shuffled, on eight threads: identical scenes race for the
    # same cache entries, different ones for the cache's room
    jobs = [i for i in range(len(work)) for _ in range(3)]
    random.Random(7).shuffle(jobs)
    with ThreadPoolExecutor(max_workers=8) as pool:
        futures = [(i, pool.submit(answer, work[i])) for i in jobs]
        for i, future in futures:
            assert_same_answers(serial[i], future.result(timeout=300))
    for name, report in cache_report().items():
        cache = _REGISTRY[name]
        assert report["items"] <= cache.max_items, name
        assert report["bytes"] <= cache.max_bytes, name


def test_a_stage_cache_computes_each_key_once_and_stays_bounded() -> None:
    cache = StageCache("test-concurrency", max_items=5, max_bytes=5 * 8 * 1000)
    calls: list[int] = []
    lock = threading.Lock()
    start = threading.Barrier(16)

    def compute(key: int) -> np.ndarray:
        with lock:
            calls.append(key)
        threading.Event().wait(0.01)  # long enough for the others to pile up on the key
        return np.full(1000, float(key))

    def worker(seed: int) -> None:
        start.wait()
        rng = random.Random(seed)
        for _ in range(50):
            key = rng.randrange(8)
            value, _ = cache.get_or_compute(key, lambda key=key: compute(key))
            assert value[0] == key and value.shape == (1000,)
            assert len(cache) <= 5 and cache.size_bytes <= 5 * 8 * 1000

    threads = [threading.Thread(target=worker, args=(seed,)) for seed in range(16)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=120)
        assert not t.is_alive()
    assert len(cache) <= 5 and cache.size_bytes <= 5 * 8 * 1000
    assert cache.evaluations == len(calls)
    assert cache.hits + cache.evaluations == 16 * 50
    # an entry larger than the byte bound is returned but not kept
    big, cached = cache.get_or_compute("big", lambda: np.zeros(10_000))
    assert big.size == 10_000 and not cached and "big" not in cache._data
    # a failure reaches its caller and leaves no entry; the next caller computes again
    with pytest.raises(RuntimeError):
        cache.get_or_compute("bad", lambda: (_ for _ in ()).throw(RuntimeError("no")))
    value, cached = cache.get_or_compute("bad", lambda: np.ones(3))
    assert not cached and value.sum() == 3
    with _REGISTRY_LOCK:
        _REGISTRY.pop("test-concurrency", None)


def test_threads_asking_for_the_same_stage_at_once_compute_it_once() -> None:
    cache = StageCache("test-concurrency-once", max_items=4)
    calls: list[int] = []
    start = threading.Barrier(12)

    def compute() -> np.ndarray:
        calls.append(1)
        threading.Event().wait(0.2)  # the other eleven arrive while this one works
        return np.arange(4.0)

    results: list[tuple[float, bool]] = []

    def worker() -> None:
        start.wait()
        value, cached = cache.get_or_compute("same", compute)
        results.append((float(value.sum()), cached))

    threads = [threading.Thread(target=worker) for _ in range(12)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=60)
    assert len(calls) == 1 and cache.evaluations == 1
    assert sorted(results) == [(6.0, False)] + [(6.0, True)] * 11
    with _REGISTRY_LOCK:
        _REGISTRY.pop("test-concurrency-once", None)


def test_waiters_for_a_failing_computation_retry_it() -> None:
    cache = StageCache("test-concurrency-fail", max_items=4)
    entered = threading.Event()
    release = threading.Event()
    outcomes: list[str] = []

    def failing() -> np.ndarray:
        entered.set()
        release.wait(30)
        raise ValueError("first attempt fails")

    def first() -> None:
        try:
            cache.get_or_compute("k", failing)
        except ValueError:
            outcomes.append("first failed")

    def second() -> None:
        value, cached = cache.get_or_compute("k", lambda: np.arange(3.0))
        outcomes.append(f"second got {value.sum():g}")

    t1 = threading.Thread(target=first)
    t1.start()
    assert entered.wait(30)
    t2 = threading.Thread(target=second)
    t2.start()
    release.set()
    t1.join(30)
    t2.join(30)
    assert sorted(outcomes) == ["first failed", "second got 3"]
    with _REGISTRY_LOCK:
        _REGISTRY.pop("test-concurrency-fail", None)


def test_the_result_cache_is_bounded_in_items_and_bytes_across_threads() -> None:
    state = ExplorerState()
    state.param.update(time_count=3, tol=1e-3)
    controller = SolveController(state, executor=None, auto=False)
    controller.solve_now()
    view = controller.view
    size = approx_bytes(view)
    # the estimate is close to what the view really holds: its arrays at least
    arrays = view.pressure.nbytes + view.image.nbytes + view.x.nbytes
    assert arrays <= size <= 20 * 2**20
    cache = StageCache("test-results", max_items=10, max_bytes=4 * size, sizeof=approx_bytes)
    errors: list[BaseException] = []

    def worker(seed: int) -> None:
        rng = random.Random(seed)
        try:
            for _ in range(300):
                key = json.dumps({"k": rng.randrange(30)})
                if rng.random() < 0.5:
                    got, _ = cache.get_or_compute(key, lambda: view)
                    assert got is view
                else:
                    got = cache.get(key)
                    assert got is None or got is view
                assert len(cache) <= 10 and cache.size_bytes <= 4 * size
        except BaseException as exc:  # reported below, from the main thread
            errors.append(exc)

    threads = [threading.Thread(target=worker, args=(seed,)) for seed in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=120)
    assert errors == []
    assert 0 < len(cache) <= 4 and cache.size_bytes <= 4 * size
    with _REGISTRY_LOCK:
        _REGISTRY.pop("test-results", None)
    # the process-wide cache has bounds too
    assert RESULTS.max_items >= 1 and RESULTS.max_bytes <= 256 * 2**20
    assert len(RESULTS) <= RESULTS.max_items and RESULTS.size_bytes <= RESULTS.max_bytes


def test_all_shared_caches_together_stay_under_the_memory_budget() -> None:
    """The solver's stage caches within STAGE_CACHE_BYTES, and with the explorer's result
    cache under 640 MiB: the server measured ~130 MiB idle and ~7 MiB per session
    (benchmarks/results/load_test.md), so 20 sessions stay under 1 GiB."""
    from core.budget import STAGE_CACHE_BYTES
    from core.engines.projection import PROJECTION_CACHES

    stages = list(PROJECTION_CACHES)
    budget = STAGE_CACHE_BYTES
    assert sum(c.max_bytes for c in stages) <= budget <= 512 * 2**20
    assert budget + RESULTS.max_bytes <= 640 * 2**20


# --------------------------------------------------------------------------- sessions


def test_sessions_share_no_state() -> None:
    """What one session loads or types stays in it: parameters, choices, layers."""
    first, second = ExplorerState(), ExplorerState()
    scene = small(PRESETS["rounded_graded"])
    scene["solver"] = {"tol": 3e-9}  # not one of the offered choices: the list grows
    first.load_scene(scene)
    first.layers[0].thickness.mean = 99.0
    first.loading.statement = "settlement + tilt given"
    assert 3e-9 in first.param.tol.objects and 3e-9 not in second.param.tol.objects
    assert 3e-9 not in ExplorerState().param.tol.objects
    assert second.to_scene() == ExplorerState().to_scene()
    assert first.to_scene() != second.to_scene()


def test_a_slow_or_bad_session_does_not_hold_up_or_touch_another() -> None:
    pool = ThreadPoolExecutor(max_workers=2, thread_name_prefix="test-solve")
    release = threading.Event()

    def slow_and_bad(scene: dict[str, Any]) -> Any:
        release.wait(60)
        raise ValueError("coating[0].thickness: must be > 0, is -1 at x = 0 m")

    try:
        slow = SolveController(ExplorerState(), solve=slow_and_bad, executor=pool,
                               auto=False)
        slow.request()
        fast_state = ExplorerState()
        fast_state.param.update(time_count=4, tol=1e-3)
        fast = SolveController(fast_state, executor=pool, auto=False)
        for force in (400.0, 450.0, 500.0):
            fast_state.loading.histories["force"].value = force
            fast.request()
            assert fast.wait(120)
            assert fast.error == "" and fast.view is not None
            assert fast.view.values["force"][0] == pytest.approx(force * 1e3, rel=1e-12)
        assert slow.busy and slow.view is None and slow.error == ""
        release.set()
        assert slow.wait(60)
        assert "coating[0].thickness" in slow.error
        assert fast.error == "" and fast.view.values["force"][0] == pytest.approx(5e5)
    finally:
        release.set()
        pool.shutdown(wait=True)


def test_many_sessions_on_the_shared_pool_each_get_their_own_answer() -> None:
    pool = ThreadPoolExecutor(max_workers=2, thread_name_prefix="test-solve")
    try:
        sessions = []
        for k in range(10):
            state = ExplorerState()
            state.param.update(time_count=4, tol=1e-4)
            state.base.thickness = 2.0 + 0.25 * (k % 3)       # three geometries
            state.loading.histories["force"].value = 300.0 + 40.0 * k
            if k == 7:
                state.layers[0].modulus.mean = -5.0             # one session errs
            sessions.append((state, SolveController(state, executor=pool, auto=False)))
        for _, controller in sessions:
            controller.request()
        for k, (state, controller) in enumerate(sessions):
            assert controller.wait(300)
            if k == 7:
                assert "coating[0].modulus" in controller.error and controller.view is None
                continue
            assert controller.error == ""
            expected = answer(state.to_scene())
            assert controller.view.scene == state.to_scene()
            np.testing.assert_array_equal(controller.view.values["settlement"],
                                          expected["settlement"])
    finally:
        pool.shutdown(wait=True)


def test_downloads_hold_the_result_on_screen_while_a_newer_one_is_solved(explorer_app) -> None:

    gate = threading.Event()
    started = threading.Event()

    def gated(scene: dict[str, Any]) -> Any:
        if scene["loading"]["force"] != 5e5:
            started.set()
            assert gate.wait(120)
        return solve(scene)

    # two threads: a download is work of the pool too, and here the solve holds one
    pool = ThreadPoolExecutor(max_workers=2)
    try:
        scene = small(PRESETS["uniform_flat"], count=5)
        app = explorer_app(scene=scene, solve=gated, executor=pool)
        assert app.controller.wait(120) and app.controller.view is not None
        shown = app.screen.drawn
        assert shown is app.controller.view

        def check_downloads_match(view: Any) -> None:
            from explorer.files import parse_csv

            # the CSV holds the plotted numbers in the units on screen (mm, kN/m), to
            # 10 significant digits; the JSON the solver's SI numbers in full
            _, names, table = parse_csv(asyncio.run(app.files_tab._csv_file()).getvalue())
            assert names[:4] == ["time_day", "settlement_mm", "tilt_mrad", "force_kN_per_m"]
            result = json.loads(asyncio.run(app.files_tab._json_file()).getvalue())
            saved = json.loads(app.files_tab._scene_file().getvalue())
            assert saved == view.scene
            assert scene_from_dict(saved) == scene_from_dict(result["scene"])
            np.testing.assert_allclose(table[:, 0], result["times"], rtol=1e-9)
            np.testing.assert_allclose(table[:, 1] * 1e-3, result["settlement"], rtol=1e-9)
            np.testing.assert_allclose(table[:, 3] * 1e3, result["force"], rtol=1e-9)
            # what the plots show: settlement in mm, the pressure line at the time shown
            shown_mm = np.asarray(app.figures.history_src["settlement"].data["v"])
            # the plot holds float32 (7 digits), the file 10 digits of the same number
            np.testing.assert_allclose(table[:, 1], shown_mm, rtol=1e-7, atol=0)
            index = app.screen.time_index
            unit = view.pressure_unit[1]
            q_file = np.asarray(result["pressure"])[:, index]
            np.testing.assert_allclose(q_file / unit, app.figures.q_src.data["q"],
                                       rtol=1e-7, atol=0)  # float32 on screen
            _, _, long = parse_csv(asyncio.run(app.files_tab._pressure_file()).getvalue())
            assert len(long) == len(result["times"]) * len(result["x"])

        check_downloads_match(shown)
        old_force = shown.values["force"][0]
        # a load change: the new solve starts and waits behind the gate
        app.state.loading.histories["force"].value = 650.0
        assert started.wait(60)
        assert app.controller.busy and app.screen.drawn is shown
        check_downloads_match(shown)
        from explorer.files import parse_csv

        table = parse_csv(asyncio.run(app.files_tab._csv_file()).getvalue())[2]
        assert table[0, 3] == old_force / 1e3
        gate.set()
        assert app.controller.wait(120)
        assert app.screen.drawn is app.controller.view and app.screen.drawn is not shown
        check_downloads_match(app.screen.drawn)
        table = parse_csv(asyncio.run(app.files_tab._csv_file()).getvalue())[2]
        assert table[0, 3] == pytest.approx(650.0, rel=1e-12)
    finally:
        gate.set()
        pool.shutdown(wait=True)
