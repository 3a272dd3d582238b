"""The changes of a scene dict that the scene benchmarks time: a load slider's step and a
geometry slider's step (:mod:`benchmarks.scene_overhead`, :mod:`benchmarks.compare_trees`).

It imports nothing of the project: :mod:`benchmarks.compare_trees` loads it by its path
into a worker that imports ``core`` from another tree.
"""

from __future__ import annotations

import copy
from typing import Any


def changed_scene(scene: dict[str, Any], kind: str, i: int, step: float) -> dict[str, Any]:
    """A copy of ``scene`` changed ``i`` steps of relative size ``step`` away from it.

    ``kind`` ``"geometry"``: the punch's half-width ``(1 + i step)`` times as wide (every
    geometry cache misses); of several punches, the last one moved by ``i step`` of its
    half-width (the drag of a punch's centre). ``"loads"``: the first given constant load
    ``(1 + i step)`` times as large (of several punches, the first punch's), or ``1e-9 i``
    where it is zero (a centred force's moment).
    """
    new = copy.deepcopy(scene)
    several = "punches" in new
    if kind == "geometry" and several:
        last = new["punches"][-1]
        last["center"] = last["center"] + step * i * last["half_width"]
    elif kind == "geometry":
        new["punch"]["half_width"] = scene["punch"]["half_width"] * (1 + step * i)
    elif kind == "loads":
        loading = new["punches"][0]["loading"] if several else new["loading"]
        quantity = next(q for q, v in loading.items() if not isinstance(v, dict))
        value = loading[quantity]
        loading[quantity] = value * (1 + step * i) if value else 1e-9 * i
    else:
        raise ValueError(f"kind: 'geometry' or 'loads', not {kind!r}")
    return new
