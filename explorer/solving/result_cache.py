"""The process-wide cache of prepared results, shared by all sessions of a server.

Keyed by the scene's canonical JSON (:func:`result_key`); bounded by count and by bytes
(:func:`approx_bytes`). Nothing here imports Panel.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import fields, is_dataclass
from typing import Any

import numpy as np

from core.cache import StageCache


def approx_bytes(obj: Any, _seen: set[int] | None = None, _depth: int = 0) -> int:
    """Memory held by a result [bytes], approximately: numpy arrays (each buffer once),
    text, and the containers and objects of ``core`` and ``explorer`` that hold them."""
    seen = set() if _seen is None else _seen
    if id(obj) in seen or _depth > 8:
        return 0
    seen.add(id(obj))
    if isinstance(obj, np.ndarray):
        base = obj
        while isinstance(base.base, np.ndarray):
            base = base.base
        if base is not obj:
            return approx_bytes(base, seen, _depth)
        return int(obj.nbytes)
    if isinstance(obj, (str, bytes)):
        return len(obj) + 50
    if isinstance(obj, Mapping):
        return 100 + sum(approx_bytes(k, seen, _depth + 1) + approx_bytes(v, seen, _depth + 1)
                         for k, v in obj.items())
    if isinstance(obj, (list, tuple)):
        # a table row of a scene: a list of two floats, 24 bytes each plus the list
        return 56 + sum(8 + approx_bytes(v, seen, _depth + 1) for v in obj)
    if is_dataclass(obj) and not isinstance(obj, type):
        return 64 + sum(approx_bytes(getattr(obj, f.name, None), seen, _depth + 1)
                        for f in fields(obj))
    module = type(obj).__module__ or ""
    if hasattr(obj, "__dict__") and module.split(".")[0] in ("core", "explorer"):
        return 64 + sum(approx_bytes(v, seen, _depth + 1) for v in vars(obj).values())
    return 24


def result_key(scene: dict[str, Any]) -> str | None:
    """The key of a scene in :data:`RESULTS` (its canonical JSON), None if not JSON."""
    try:
        return json.dumps(scene, sort_keys=True, separators=(",", ":"), allow_nan=False)
    except (TypeError, ValueError):
        return None


#: Process-wide cache of prepared results, keyed by :func:`result_key`: a new session
#: opening a preset, or a slider going back to an earlier value, then costs nothing, and
#: sessions asking for the same scene at once solve it once. Views are never modified
#: after they are made, so sessions share them. One view of 2000 output times measured
#: 4.5 MB (tracemalloc), 4.75 MB by :func:`approx_bytes`; the byte bound keeps the
#: server (with the solver's own 512 MiB of stage caches) under 1 GiB.
RESULTS = StageCache("explorer_results", max_items=24, max_bytes=96 * 2**20,
                     sizeof=approx_bytes)
