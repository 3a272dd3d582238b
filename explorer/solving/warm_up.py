"""Solving presets before the first visitor comes (``python -m explorer --warm-up``)."""

from __future__ import annotations

from ..model import DEFAULT_PRESET, ExplorerState, presets
from .controller import SolveController, worker_processes
from .workers import solve_view


def warm_up(keys: tuple[str, ...] = (DEFAULT_PRESET,)) -> None:
    """Solve some presets now, so that the first visitors find them in the caches."""
    available = presets()
    for key in keys:
        scene = available.get(key)
        if scene is None:
            continue
        state = ExplorerState()
        state.load_scene(scene)
        SolveController(state, executor=None, auto=False).solve_now()
        processes = worker_processes()
        if processes is not None and processes.lanes > 1:
            # the first solve warmed one worker; the others get the same caches
            processes.run_everywhere(solve_view, state.to_scene())
