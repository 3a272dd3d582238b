"""The instant of loading: a scene whose base answers as it does when the load is applied.

At the instant of loading (t = 0 days after it) a creeping, aging base has not crept yet:
it responds elastically, with its modulus at loading ``E(t0)`` (``t0`` the base's age at
loading). :func:`elastic_at_loading` gives the scene with that elastic base. At later
times its answer is that of a base that neither creeps nor ages (``E`` stays ``E(t0)``):
what creep and aging add is the difference.

At t = 0 its answer is the scene's own up to the coating model: where both are answered
by the thin-layer model (a coating whose thickness or modulus varies, lift-off, several
punches) they agree within the two solves' tolerances (the lift-off preset: 5.7e-8
relative, estimates 8e-7); an even coating on an elastic base is answered by the exact
layered kernel instead, so there they differ by about the thin-layer model's own error,
which the scene's answer reports (the default scene: 0.23 % in the settlement, estimated
0.35 %). It costs an elastic solve: 6-50 ms of CPU with the explorer's view, where the
answer with creep takes 0.2-7 s, which is why the explorer shows it while a slider is
dragged faster than those solves can follow.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from typing import Any

from core.creep import creep_model_from_spec
from core.validation import positive_number

__all__ = ["creeps", "elastic_at_loading", "modulus_at_loading"]


def creeps(scene: Mapping[str, Any]) -> bool:
    """Whether the base of ``scene`` (a scene dict, either form) creeps or ages (its
    ``base.creep`` is not ``{"model": "elastic"}``); False for a dict without one."""
    base = scene.get("base") if isinstance(scene, Mapping) else None
    creep = base.get("creep") if isinstance(base, Mapping) else None
    return isinstance(creep, Mapping) and creep.get("model") != "elastic"


def modulus_at_loading(scene: Mapping[str, Any]) -> float:
    """``E(t0)`` [Pa]: the modulus of the base of ``scene`` (a scene dict, either form) at
    its age at loading ``t0`` = ``base.age_at_loading`` [days], from ``base.creep``.

    Reads and checks only those two fields (a ValueError names the one at fault), in well
    under a millisecond: the whole scene's checks (:func:`core.scene.scene_from_dict`)
    take 17-250 ms under the design-code laws."""
    if not isinstance(scene, Mapping):
        raise ValueError(f"scene: must be a scene dict, got {type(scene).__name__}")
    base = scene.get("base")
    if not isinstance(base, Mapping):
        raise ValueError("base: must be an object with the base's fields")
    if "creep" not in base:
        raise ValueError("base.creep: missing")
    if "age_at_loading" not in base:
        raise ValueError("base.age_at_loading: missing")
    age = positive_number(base["age_at_loading"], "base.age_at_loading")
    law = creep_model_from_spec(base["creep"], field="base.creep")
    return float(law.modulus(age))


def elastic_at_loading(scene: Mapping[str, Any]) -> dict[str, Any]:
    """``scene`` (a scene dict, single punch or ``punches``) with its base elastic at its
    modulus at loading ``E(t0)`` [Pa] (:func:`modulus_at_loading`): ``base.creep``
    becomes ``{"model": "elastic", "modulus": E(t0)}``, everything else is kept (a copy;
    the input is not changed).

    Its answer at t = 0 is the scene's own up to the coating model, later that of a base
    without creep or aging (see the module notes). A base already elastic comes back as
    a copy. Only ``base.creep`` and ``base.age_at_loading`` are checked here (ValueError
    naming the field); the solve of the scene returned checks the rest.
    """
    modulus = modulus_at_loading(scene)
    out = copy.deepcopy(dict(scene))
    out["base"] = dict(out["base"])
    out["base"]["creep"] = {"model": "elastic", "modulus": modulus}
    return out
