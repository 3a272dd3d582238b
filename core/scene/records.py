"""What every file of an answer records besides the numbers: the program's version, the
scene solved and the solver settings, so that a file can be traced and solved again.

The command line (:mod:`core.cli`) and the explorer's downloads write these: JSON files
carry :func:`provenance` at the top level (:meth:`SceneSolution.to_dict`), CSV files start with
the ``#`` lines of :func:`provenance_lines` (``pandas.read_csv(path, comment="#")`` reads
the table; each line is ``# key: value``).
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from core.scene.validate import scene_from_dict
from core.version import VERSION

if TYPE_CHECKING:
    from core.scene.model import Scene

#: The program's name in the files it writes.
PROGRAM = "coated-punch"


def solver_settings(scene: Scene | Mapping[str, Any]) -> dict[str, Any]:
    """The solver settings of a scene, defaults filled in: ``tol`` and ``model_tol`` [-],
    ``contact`` (``"auto"``, ``"full"`` or ``"unilateral"``)."""
    scene = scene_from_dict(scene)
    return {"tol": scene.tol, "model_tol": scene.model_tol, "contact": scene.contact}


def provenance(scene: Scene | Mapping[str, Any]) -> dict[str, Any]:
    """``program``, ``version`` (``core.__version__``) and ``solver`` (the settings) of a
    file written for ``scene``."""
    return {"program": PROGRAM, "version": VERSION, "solver": solver_settings(scene)}


def provenance_lines(scene: Scene | Mapping[str, Any]) -> list[str]:
    """The ``#`` lines of a CSV file written for ``scene``: ``version``, ``scene_json``
    (the canonical scene, one line of JSON) and ``solver`` (the settings, JSON)."""
    scene = scene_from_dict(scene)
    compact = {"separators": (",", ":"), "allow_nan": False}
    return [f"# version: {VERSION}",
            f"# scene_json: {json.dumps(scene.to_dict(), **compact)}",
            f"# solver: {json.dumps(solver_settings(scene), **compact)}"]
