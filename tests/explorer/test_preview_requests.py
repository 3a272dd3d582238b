"""The controller's previews (``SolveController.request_preview``) on a thread pool, as
a served page without worker processes runs them: the base elastic at loading is
solved, one at a time with the newest asked next, only for a creeping base, and a
request made meanwhile drops the previews asked before it."""

from __future__ import annotations

import threading
import time
from concurrent.futures import ThreadPoolExecutor
from typing import Any

from core import solve
from explorer.model import ExplorerState
from explorer.solving import SolveController


def _wait(check, timeout: float = 60.0) -> bool:
    deadline = time.monotonic() + timeout
    while not check():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.005)
    return True


def _state() -> ExplorerState:
    """The default scene (a creeping base), four output times at tol 1e-4."""
    from core.presets import read_preset

    state = ExplorerState()
    state.load_scene(read_preset("uniform_flat"))
    state.param.update(time_count=4, tol=1e-4)
    return state


def test_previews_run_one_at_a_time_the_newest_next_and_a_request_drops_them() -> None:
    pool = ThreadPoolExecutor(max_workers=2, thread_name_prefix="test-preview")
    gate = threading.Event()
    seen: list[float] = []

    def gated(scene: dict[str, Any]) -> Any:
        # previews, and the request at thickness 3.5, wait for the gate
        if scene["base"]["creep"]["model"] == "elastic":
            seen.append(scene["base"]["thickness"])
            gate.wait(60)
        elif scene["base"]["thickness"] == 3.5:
            gate.wait(60)
        return solve(scene)

    try:
        state = _state()
        controller = SolveController(state, solve=gated, executor=pool, auto=False)
        controller.request()
        assert controller.wait(120) and controller.view is not None
        real = controller.view
        scene = state.to_scene()
        assert scene["base"]["creep"]["model"] != "elastic"
        for thickness in (2.0, 2.5, 3.0):     # three steps while the first one solves
            assert controller.request_preview({**scene, "base": {**scene["base"],
                                                                 "thickness": thickness}})
        assert _wait(lambda: len(seen) == 1)
        gate.set()
        # the first, then the newest of the two asked meanwhile (never the middle one)
        assert _wait(lambda: controller.preview is not None
                     and controller.preview.scene["base"]["thickness"] == 3.0)
        assert seen == [2.0, 3.0]
        preview = controller.preview
        assert preview.scene["base"]["creep"]["model"] == "elastic"
        assert controller.view is real          # never the result on screen
        # a request drops the preview shown and those asked before it
        gate.clear()
        controller.request_preview({**scene, "base": {**scene["base"], "thickness": 4.0}})
        assert _wait(lambda: 4.0 in seen)
        controller.request()
        assert controller.preview is None
        gate.set()
        assert controller.wait(120)
        # the dropped preview's answer came back and was not shown
        assert _wait(lambda: not controller._preview_running)
        assert controller.preview is None and controller.view is not real
        # a preview asked while a request solves starts when it ends
        gate.clear()
        state.base.thickness = 3.5
        controller.request()
        controller.request_preview({**scene, "base": {**scene["base"], "thickness": 5.0}})
        time.sleep(0.2)
        assert controller.preview is None and 5.0 not in seen and controller.busy
        gate.set()
        assert controller.wait(120)
        assert _wait(lambda: controller.preview is not None
                     and controller.preview.scene["base"]["thickness"] == 5.0)
    finally:
        gate.set()
        pool.shutdown(wait=True)


def test_a_base_that_does_not_creep_is_not_previewed() -> None:
    state = _state()
    controller = SolveController(state, executor=None, auto=False)
    scene = state.to_scene()
    elastic = {**scene, "base": {**scene["base"], "creep": {"model": "elastic",
                                                            "modulus": 3.0e10}}}
    assert not controller.request_preview(elastic)
    assert controller.preview is None
    # a scene the core refuses is not shown (the release's solve says why)
    bad = {**scene, "base": {**scene["base"], "thickness": -1.0}}
    assert controller.request_preview(bad)
    assert controller.preview is None and controller.error == ""
