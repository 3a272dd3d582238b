"""Unilateral contact: the punch may lift off, and the contact set is an unknown.

``solve_unilateral`` (``unilateral.py``) answers ``contact="unilateral"``; ``switch.py``
holds the ``contact=`` switch of ``solve_dimensionless`` (full, unilateral, auto) and the
cheap check that lets ``auto`` skip a full-contact solve.

- ``active_set.py``: the nodal active set (primal-dual sweeps on a fixed panel rule) and
  the zones it finds; ``nodal.py``: its operator and start from the next coarser rule;
- ``zones.py``: zone ends as roots of the Nystrom pressure on panels graded toward them,
  with the error estimate against a coarser rule;
- ``step.py``: the problem at one time; ``systems.py``: the bordered systems;
- ``elastic.py``: lift-off on an elastic base, each time on its own;
- ``creep.py``, ``march.py``, ``memory.py``, ``bands.py``, ``kinks.py``: lift-off under
  creep (error control, one march on a fixed rule, the memory of past pressures, the
  bands the zone ends sweep, kink-corrected zone ends);
- ``result.py``: ``UnilateralSolution`` and ``contact_set_from_pressure``;
- ``coupled.py``: lift-off of several punches on one elastic base
  (``solve_unilateral_punches``), the single punch's machinery over their block system;
  ``coupled_creep.py``: on a creeping base (``solve_creep_punches``), the single punch's
  creep march over it, one memory for all punches.
"""

from __future__ import annotations

from core.contact.coupled import solve_unilateral_punches
from core.contact.coupled_creep import solve_creep_punches
from core.contact.step import LoadNotCarried, Space
from core.contact.switch import (
    check_contact_model,
    predicted_unilateral,
    refuse_loads_without_contact,
    with_contact_model,
)
from core.contact.unilateral import CONTACT_MODELS, solve_unilateral
from core.contact.zones import (
    LOCATING_ZONE_ENDS,
    ZONE_EDGE_WIDTH,
    ZONE_END_TOL,
    ZONE_PANEL_WIDTH,
    Resolution,
    zone_panels,
)

__all__ = [
    "check_contact_model",
    "CONTACT_MODELS",
    "LoadNotCarried",
    "LOCATING_ZONE_ENDS",
    "predicted_unilateral",
    "refuse_loads_without_contact",
    "Resolution",
    "solve_creep_punches",
    "solve_unilateral",
    "solve_unilateral_punches",
    "Space",
    "with_contact_model",
    "ZONE_EDGE_WIDTH",
    "ZONE_END_TOL",
    "ZONE_PANEL_WIDTH",
    "zone_panels",
]
