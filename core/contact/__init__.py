"""core.contact.unilateral."""

from __future__ import annotations

from core.contact.step import Space
from core.contact.switch import (
    check_contact_model,
    predicted_unilateral,
    refuse_loads_without_contact,
    with_contact_model,
)
from core.contact.unilateral import CONTACT_MODELS, solve_unilateral
from core.contact.zones import (
    ZONE_EDGE_WIDTH,
    ZONE_END_TOL,
    ZONE_PANEL_WIDTH,
    Resolution,
    zone_panels,
)

__all__ = [
    "check_contact_model",
    "CONTACT_MODELS",
    "predicted_unilateral",
    "refuse_loads_without_contact",
    "Resolution",
    "solve_unilateral",
    "Space",
    "with_contact_model",
    "ZONE_EDGE_WIDTH",
    "ZONE_END_TOL",
    "ZONE_PANEL_WIDTH",
    "zone_panels",
]
