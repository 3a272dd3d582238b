"""What a study records of each point: the outputs of a solved scene, per output time.

One definition for every path that answers a point (a scene solved on its own, a batch
of loads, a lift-off family), so a study's columns mean the same whichever path ran.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from core.study.definition import PUNCH_OUTPUT


def point_outputs(result: Any, outputs: Sequence[str]) -> np.ndarray:
    """The requested outputs of a :class:`core.scene.SceneSolution`, shape
    ``(len(outputs), n_times)``, in the units of :data:`core.study.definition.OUTPUT_UNITS`.

    ``q_max``/``q_min`` are the extremes of the pressure on the 201-point plotting grid;
    ``contact_width`` is the answer's ``contact_width``, the length of its contact set
    (:func:`core.scene.contact_width`: ``2a`` for a full-contact answer, even one flagged
    ``contact_lost``). Of several punches (a :class:`core.scene.PunchesSolution`), each
    output names its punch, ``punches[k].<output>``, and is that punch's.
    """
    rows = []
    for name in outputs:
        match = PUNCH_OUTPUT.fullmatch(name)
        answer, name = (result.punches[int(match[1])], match[2]) if match else (result, name)
        if name in ("settlement", "tilt", "force", "moment"):
            rows.append(getattr(answer, name))
        elif name == "q_max":
            rows.append(np.max(answer.pressure_on_grid, axis=0))
        elif name == "q_min":
            rows.append(np.min(answer.pressure_on_grid, axis=0))
        else:
            rows.append(answer.contact_width)
    return np.asarray(rows, dtype=float)
