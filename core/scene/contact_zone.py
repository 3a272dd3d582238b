"""The contact width and the lift-off length of an answer: one definition for every output.

The contact width at a time is the length of the answer's contact set there, the
intervals of ``[-a, a]`` where the base touches (``SceneSolution.contact_set``); the
lift-off length is the rest of the base, ``2a`` minus the contact width. The study
outputs, the command line, the data exports, the report and the explorer all take them
from here, so a width never depends on where it is read.

The pressure's sign is not the test: a unilateral answer has q = 0 exactly on the parts
lifted off, which a ``q >= 0`` rule would count as contact. A full-contact answer keeps
the whole base in contact by the model's assumption, so its contact width is ``2a`` even
when it is flagged ``contact_lost`` (q < 0 somewhere): the flag says that answer, width
included, is not physical, and ``q_min < 0`` by how much it pulls. The width after
lift-off is the unilateral model's (``solver.contact`` ``"auto"``, the default, or
``"unilateral"``).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

#: A contact set narrower than ``(1 - LIFT_OFF_SHARE) * 2a`` is reported as lift-off: a
#: unilateral answer in full contact holds ``[(-a, a)]`` exactly (measured on the lift-off
#: preset at e = 0.41 m, back in full contact by 1000 days), so this only absorbs rounding.
LIFT_OFF_SHARE = 1e-9

ContactSet = Sequence[Sequence[tuple[float, float]]]


def contact_width(contact_set: ContactSet, half_width: float) -> np.ndarray:
    """The contact width [m] at each time: the total length of the contact zones.

    Parameters
    ----------
    contact_set
        Per time, the ``(start, end)`` intervals [m] in contact (``[(-a, a)]`` in full
        contact), as :attr:`core.scene.SceneSolution.contact_set` holds them.
    half_width
        The punch's half-width ``a`` [m]: the zones are taken within ``[-a, a]``.

    Returns
    -------
    numpy.ndarray
        One width [m] per time, between 0 and ``2a`` (zones that overlap count once).
    """
    a = float(half_width)
    widths = np.zeros(len(contact_set))
    for k, zones in enumerate(contact_set):
        edge = -a
        for lo, hi in sorted((float(lo), float(hi)) for lo, hi in zones):
            start, end = max(lo, edge), min(hi, a)
            if end > start:
                widths[k] += end - start
                edge = end
    return widths


def narrowest_zone(contact_set: ContactSet, half_width: float) -> float | None:
    """The length [m] of the narrowest contact zone over all times, None in full contact
    at every time (a zone of the whole width ``2a`` less the rounding share
    :data:`LIFT_OFF_SHARE` counts as full contact).

    The thin-coating model is a good model where the coating is thin against the zone
    it presses (:func:`core.coating.model_error_map` reads its error at this length)."""
    a = float(half_width)
    lengths = [min(float(hi), a) - max(float(lo), -a) for zones in contact_set
               for lo, hi in zones]
    narrowest = min(lengths, default=2.0 * a)
    return None if narrowest >= (1.0 - LIFT_OFF_SHARE) * 2.0 * a else max(narrowest, 0.0)


def lift_off_length(contact_set: ContactSet, half_width: float) -> np.ndarray:
    """The length of the base lifted off [m] at each time: ``2a`` less the
    :func:`contact_width` (0 in full contact)."""
    return 2.0 * float(half_width) - contact_width(contact_set, half_width)


def lifts_off(contact_set: ContactSet, half_width: float) -> np.ndarray:
    """Whether the base lifts off at each time: its :func:`lift_off_length` is more than
    the rounding share :data:`LIFT_OFF_SHARE` of the width ``2a``."""
    return lift_off_length(contact_set, half_width) > LIFT_OFF_SHARE * 2.0 * float(half_width)
