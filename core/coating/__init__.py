"""The thin coating model: compliance per interface, its error, and a finite-element check.

- ``model.py``: the coating compliance ``m(x)`` of a stack of layers (smooth or bonded
  interfaces) and the model-error estimate read from the measured map;
- ``error_table.py`` (and ``error_table.json``): that map, measured against the FE check;
- ``fem_check.py``, ``fem_stack.py``, ``fem_mesh.py``: plane-strain P2 finite elements of
  the punch on the resolved coating layers and the base (scikit-fem), the independent
  check of the thin-coating model.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from core.coating.model import (
    DEFAULT_INTERFACE,
    DEFAULT_MODEL_TOL,
    INTERFACES,
    MODEL_TOL_RANGE,
    NEGLIGIBLE_SHARE,
    THIN_LAYER,
    equivalent_layers,
    layer_compliance,
    model_error_estimate,
    model_error_map,
    model_error_quantity,
    tilt_share,
)
from core.optional import lazy_exports

if TYPE_CHECKING:
    from core.coating.fem_check import solve_stack, solve_stack_contact, zone_ends_apart
    from core.coating.fem_stack import CoatingStrip, FEContact, Stack

# The finite-element check, loaded on first use: a scene's solve needs the thin coating
# model only, and the command line starts faster without the FE modules.
_LAZY: dict[str, str] = {
    "solve_stack": "core.coating.fem_check",
    "solve_stack_contact": "core.coating.fem_check",
    "zone_ends_apart": "core.coating.fem_check",
    "FEContact": "core.coating.fem_stack",
    "CoatingStrip": "core.coating.fem_stack",
    "Stack": "core.coating.fem_stack",
}

__all__ = [
    "CoatingStrip",
    "DEFAULT_INTERFACE",
    "DEFAULT_MODEL_TOL",
    "INTERFACES",
    "equivalent_layers",
    "FEContact",
    "layer_compliance",
    "model_error_estimate",
    "model_error_map",
    "model_error_quantity",
    "MODEL_TOL_RANGE",
    "NEGLIGIBLE_SHARE",
    "THIN_LAYER",
    "solve_stack",
    "solve_stack_contact",
    "Stack",
    "tilt_share",
    "zone_ends_apart",
]


__getattr__, __dir__ = lazy_exports(__name__, _LAZY, globals())
