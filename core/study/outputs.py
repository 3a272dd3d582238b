"""What a study records of each point: the outputs of a solved scene, per output time.

One definition for every path that answers a point (a scene solved on its own, a batch
of loads, a lift-off family), so a study's columns mean the same whichever path ran.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np


def point_outputs(result: Any, outputs: Sequence[str]) -> np.ndarray:
    """The requested outputs of a :class:`core.scene.SceneSolution`, shape
    ``(len(outputs), n_times)``, in the units of :data:`core.study.definition.OUTPUT_UNITS`.

    ``q_max``/``q_min`` are the extremes of the pressure on the 201-point plotting grid;
    ``contact_width`` is the answer's ``contact_width``, the length of its contact set
    (:func:`core.scene.contact_width`: ``2a`` for a full-contact answer, even one flagged
    ``contact_lost``).
    """
    rows = []
    q = result.pressure_on_grid if {"q_max", "q_min"} & set(outputs) else None
    for name in outputs:
        if name in ("settlement", "tilt", "force", "moment"):
            rows.append(getattr(result, name))
        elif name == "q_max":
            rows.append(np.max(q, axis=0))
        elif name == "q_min":
            rows.append(np.min(q, axis=0))
        else:
            rows.append(result.contact_width)
    return np.asarray(rows, dtype=float)
