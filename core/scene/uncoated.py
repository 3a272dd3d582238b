"""A scene with no coating layers: the punch on the bare base, and what is solved of it.

With ``coating: []`` the compliance ``m*`` is 0 and the thin-layer model has nothing to
stand on (its projection divides by ``m``); the exact layered kernel
(:mod:`core.engines.layered.answer`) with an empty stack is the base's own kernel and
solves the bare layer exactly, inverse square-root corners included (a creeping or aging
base by scalar Volterra equations in time, :mod:`core.engines.layered.bare_creep`). It
answers full contact under a smooth punch, and a punch lifting off
(:mod:`core.engines.layered.bare_lift_off`; on a base that creeps or ages,
:mod:`core.engines.layered.bare_growing_zone`, step by step where the zone grows and
recedes in turn);
:func:`check_uncoated` refuses
the rest when the scene is read, naming the field and the reason, and
:func:`lift_off_refusal` words the refusal of a punch that lifts off where that is not
answered (known only once solved).
"""

from __future__ import annotations

import math
from typing import Any

from core.engines.layered import bare_creep_declines, thinnest_bare_base

__all__ = ["check_uncoated", "lift_off_refusal", "UNCOATED_SCOPE"]

#: What a scene without coating layers is solved for, as its refusals say it.
UNCOATED_SCOPE = ("a scene with no coating layers is solved under a punch shape without "
                  "jumps or kinks; on a base that creeps or ages it lifts off in every "
                  "statement, exactly where its contact zone keeps its size, only grows (a "
                  "crown pressed as the base creeps) or only recedes (a growing "
                  "eccentricity), and step by step where it grows and recedes in turn, to "
                  "the tol that march meets (about 1e-3 to 5e-3)")


def check_uncoated(scene: Any) -> None:
    """Refuse a scene without coating layers that the exact layered kernel does not
    answer (ValueError naming the field); nothing for a coated scene or one it answers."""
    if scene.coating:
        return
    problem = scene.dimensionless
    if scene.breakpoints:
        raise ValueError(
            f"punch.shape: {UNCOATED_SCOPE}; this shape jumps or kinks at x = "
            f"{', '.join(f'{b:.6g}' for b in scene.breakpoints[:3])} m (on a bare elastic base a "
            "jump carries an infinite force in full contact, a kink a log-singular pressure):"
            " use a smooth shape, or add a coating layer")
    reason = bare_creep_declines(scene, problem)
    if reason is not None and "table" in reason:
        # the base's kernel table grows like (a / H)^2: the thickness answered, in numbers
        # (the scope's words of shapes and creep said nothing of it)
        a, thickness = scene.half_width, scene.base_thickness
        # three digits, rounded up: the thickness said is one that is answered
        thinnest = thinnest_bare_base(a)
        step = 10.0 ** (math.floor(math.log10(thinnest)) - 2)
        least = math.ceil(thinnest / step) * step
        raise ValueError(
            f"base.thickness: without coating layers the base must be at least "
            f"{least:.3g} m thick under this punch (a / H at most {a / least:.3g}), got "
            f"{thickness:.6g} m (a / H = {a / thickness:.3g}): the bare base's kernel table "
            "would take too long; a thicker base is answered, or a coating layer (the thin-"
            "layer model)")
    if reason is not None:
        raise ValueError(f"coating: {UNCOATED_SCOPE}; this one is not solved: {reason}")


def lift_off_refusal(reason: str | None = None,
                     turns: tuple[float, float] | None = None) -> str:
    """The refusal of a scene without coating layers whose punch lifts off on a base that
    creeps or ages where that is not answered, with the engine's ``reason`` and, if known,
    the days after loading between which the zone turned (``turns``)."""
    why = reason or ("its contact zone would move in a way that is not answered (a point "
                     "that touched would leave the punch)")
    if turns is not None:
        lo, hi = (f"{t:.3g}" for t in turns)
        why += (f" (it turns at about {lo} days after loading)" if lo == hi else
                f" (it turns between {lo} and {hi} days after loading)")
    return ("loading: the punch lifts off the bare base on a base that creeps or ages, and "
            f"{why}; {UNCOATED_SCOPE}: loosen solver.tol, set solver.contact to 'full' for "
            "the full-contact answer (flagged contact_lost), change the loading so that the "
            "zone only grows or only recedes, or add a coating layer")
