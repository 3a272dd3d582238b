"""A scene answered at other output times, its loads the same functions of time.

A scene's load histories are functions of ``t`` on ``[0, last output time]``, and one
form refers to the end of that domain: ``{"kind": "linear", "start": y0, "end": y1}``
reaches ``y1`` at the last output time. Setting other output times on such a scene would
stretch the history over the new span (a force rising from 100 to 500 kN/m over a year,
fitted to readings of its first six months, would rise to 500 kN/m at six months).
:func:`at_output_times` pins it first: the same straight line as a table of its two end
rows, held at its end value past the scene's last output time (as every table is held
past its rows). Every other form is a function of ``t`` alone (``ramp`` starts at
``t = 0``; a ``step`` break at or after the last output time is a change that has not
come yet, and comes when the new times reach it).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from core.scene.model import Scene
from core.scene.punches import PunchesScene, has_punches, punches_from_dict
from core.scene.validate import scene_from_dict


def _pinned(spec: Any, last_time: float) -> Any:
    if isinstance(spec, Mapping) and spec.get("kind") == "linear":
        return {"kind": "table", "interpolation": "linear",
                "points": [[0.0, float(spec["start"])], [last_time, float(spec["end"])]]}
    return spec


def _pinned_loading(loading: Mapping[str, Any], last_time: float) -> dict[str, Any]:
    return {q: _pinned(spec, last_time) for q, spec in loading.items()}


def at_output_times(scene: Scene | PunchesScene | Mapping[str, Any],
                    times: Any) -> dict[str, Any]:
    """The scene's dict with output times ``times``, every load the same function of
    time as in the scene.

    Parameters
    ----------
    scene : Scene, PunchesScene or dict
        A scene of one punch or several (validated first).
    times : list of float or dict
        The new output times [day after loading], in any form a scene's ``times`` takes
        (a list, or ``{"end": ..., "count": ..., "spacing": ...}``); not validated here:
        the dict returned is, where it is read.

    Returns
    -------
    dict
        The canonical dict of ``scene`` with ``times`` set and each ``linear`` load
        history pinned to the scene's own last output time (a two-row table, held past
        it).
    """
    if isinstance(scene, PunchesScene) or (isinstance(scene, Mapping) and has_punches(scene)):
        valid = scene if isinstance(scene, PunchesScene) else punches_from_dict(scene)
        d = valid.to_dict()
        last = float(valid.times[-1])
        d["punches"] = [dict(p, loading=_pinned_loading(p["loading"], last))
                        for p in d["punches"]]
    else:
        valid = scene if isinstance(scene, Scene) else scene_from_dict(scene)
        d = valid.to_dict()
        d["loading"] = _pinned_loading(d["loading"], float(valid.times[-1]))
    d["times"] = times
    return d
