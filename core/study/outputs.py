"""What a study records of each point: the outputs of a solved scene, per output time.

One definition for every path that answers a point (a scene solved on its own, a batch
of loads, a lift-off family), so a study's columns mean the same whichever path ran.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np


def contact_width(x: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Length [m] of the part of ``x`` where ``q(x, t) >= 0``, linear between points, per
    time (``q`` has shape ``(len(x), n_times)``)."""
    dx = np.diff(x)[:, None]
    q0, q1 = q[:-1], q[1:]
    both = (q0 >= 0) & (q1 >= 0)
    width = np.sum(np.where(both, dx, 0.0), axis=0)
    cross = (q0 >= 0) != (q1 >= 0)
    with np.errstate(invalid="ignore", divide="ignore"):
        share = np.where(q0 >= 0, q0, q1) / (np.abs(q0) + np.abs(q1))
    return width + np.sum(np.where(cross, dx * share, 0.0), axis=0)


def point_outputs(result: Any, outputs: Sequence[str]) -> np.ndarray:
    """The requested outputs of a :class:`core.scene.SceneSolution`, shape
    ``(len(outputs), n_times)``, in the units of :data:`core.study.definition.OUTPUT_UNITS`.

    ``q_max``/``q_min`` are the extremes of the pressure on the 201-point plotting grid;
    ``contact_width`` is where the computed pressure is >= 0 (``2a`` under full contact;
    less when ``contact_lost`` flags the full-contact answer as unphysical).
    """
    rows = []
    q = result.pressure_on_grid if {"q_max", "q_min", "contact_width"} & set(outputs) \
        else None
    for name in outputs:
        if name in ("settlement", "tilt", "force", "moment"):
            rows.append(getattr(result, name))
        elif name == "q_max":
            rows.append(np.max(q, axis=0))
        elif name == "q_min":
            rows.append(np.min(q, axis=0))
        else:
            rows.append(contact_width(result.x, q))
    return np.asarray(rows, dtype=float)
