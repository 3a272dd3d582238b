"""The instant of loading: a scene whose base answers as it does when the load is applied.

At the instant of loading (t = 0 days after it) a creeping, aging base has not crept yet:
it responds elastically, with its modulus at loading ``E(t0)`` (``t0`` the base's age at
loading). :func:`elastic_at_loading` gives the scene with that elastic base. Its answer
at t = 0 is the scene's own (the same model and loads at that instant: on the lift-off
preset the settlement, the tilt and the zone's end agree to 1e-7 relative, the two
solves' own tolerance); at later times it is the answer of a base that neither creeps
nor ages: what creep adds is the difference. It costs an elastic solve (17-35 ms of CPU
on the presets where the creeping one takes 0.2-7 s), which is what the explorer shows
while a slider is dragged faster than those solves can follow.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from typing import Any

from core.scene.punches import has_punches, punches_from_dict
from core.scene.validate import scene_from_dict

__all__ = ["elastic_at_loading", "creeps"]


def creeps(scene: Mapping[str, Any]) -> bool:
    """Whether the base of ``scene`` (a scene dict, either form) creeps or ages (its
    ``base.creep`` is not ``{"model": "elastic"}``); False for a dict without one."""
    base = scene.get("base") if isinstance(scene, Mapping) else None
    creep = base.get("creep") if isinstance(base, Mapping) else None
    return isinstance(creep, Mapping) and creep.get("model") != "elastic"


def elastic_at_loading(scene: Mapping[str, Any]) -> dict[str, Any]:
    """``scene`` (a scene dict, single punch or ``punches``) with its base elastic at its
    modulus at loading ``E(t0)`` [Pa]: ``base.creep`` becomes ``{"model": "elastic",
    "modulus": E(t0)}``, everything else is kept (a copy; the input is not changed).

    Its answer at t = 0 is the scene's own; later it is that of a base without creep (see
    the module notes). A base already elastic comes back as a copy. Raises ValueError
    naming the field when ``scene`` is not a valid scene (the checks of
    :func:`core.scene.scene_from_dict` or :func:`core.scene.punches_from_dict`).
    """
    if not isinstance(scene, Mapping):
        raise ValueError(f"scene: must be a scene dict, got {type(scene).__name__}")
    if has_punches(scene):
        modulus = punches_from_dict(scene).scenes[0].modulus_at_loading()
    else:
        modulus = scene_from_dict(scene).modulus_at_loading()
    out = copy.deepcopy(dict(scene))
    out["base"]["creep"] = {"model": "elastic", "modulus": float(modulus)}
    return out
