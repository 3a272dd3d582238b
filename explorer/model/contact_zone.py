"""The contact zone of a result in numbers: where the base touches, how wide, how much lifts.

The contact width and the lift-off length are the core's (:func:`core.scene.contact_width`,
:func:`core.scene.lift_off_length`): the lengths of the contact set the solver reported
(``ResultView.contact_set``), so the width plot, the readout, the design check, the files
and a study's ``contact_width`` never disagree. A full-contact answer keeps the whole base
in contact (width ``2a``) even when it lost contact; where it pulls (q < 0 beyond the
error band) is drawn and named apart, as
:meth:`~explorer.model.results.ResultView.negative_intervals` gives it (the lifted parts of
a unilateral answer, or those pulling parts). Nothing here imports Panel or Bokeh.
"""

from __future__ import annotations

import numpy as np

from core.scene import contact_width, lift_off_length
from core.scene import lifts_off as core_lifts_off

from .results import PunchResult, ResultView, lifted_intervals


def _local_set(p: PunchResult) -> list[list[tuple[float, float]]]:
    """A punch's contact set in its own x (from its centre) [m], for the core's width
    functions, which take the zones within ``[-a, a]``."""
    c = p.center
    return [[(lo - c, hi - c) for lo, hi in zones] for zones in p.contact_set]


def _contact_set(view: ResultView) -> list[list[tuple[float, float]]]:
    """The view's contact set, one entry per output time; a solution that reports none
    answered with the full-contact model: the whole base at every time."""
    if len(view.contact_set) == len(view.times):
        return view.contact_set
    a = view.geometry.half_width
    return [[(-a, a)] for _ in view.times]


def contact_zones(view: ResultView, index: int) -> list[tuple[float, float]]:
    """Intervals of ``x`` [m] drawn in contact at output ``index`` (the whole ``[-a, a]``
    in full contact): the complement of the parts drawn lifted off or pulling (under
    every punch, for several)."""
    if view.punches:
        zones = []
        for p in view.punches:
            c = p.center
            off = [(lo - c, hi - c) for lo, hi in p.negative_intervals(index)]
            zones += [(lo + c, hi + c) for lo, hi in lifted_intervals(off, p.half_width)]
        return zones
    a = view.geometry.half_width
    return lifted_intervals(view.negative_intervals(index), a)


def punch_contact_widths(p: PunchResult) -> np.ndarray:
    """The contact width [m] of one punch of several at each output time."""
    return contact_width(_local_set(p), p.half_width)


def contact_widths(view: ResultView) -> np.ndarray:
    """The contact width [m] at each output time (``2a`` in full contact), the core's
    :func:`core.scene.contact_width` of the view's contact set (summed over the punches,
    for several)."""
    if view.punches:
        return np.sum([punch_contact_widths(p) for p in view.punches], axis=0)
    return contact_width(_contact_set(view), view.geometry.half_width)


def lift_off_lengths(view: ResultView) -> np.ndarray:
    """The length of the base lifted off [m] at each output time (0 in full contact), the
    core's :func:`core.scene.lift_off_length` (summed over the punches, for several)."""
    if view.punches:
        return np.sum([lift_off_length(_local_set(p), p.half_width) for p in view.punches],
                      axis=0)
    return lift_off_length(_contact_set(view), view.geometry.half_width)


def lifts_off(view: ResultView) -> bool:
    """Whether the contact set is narrower than the base at some output time (the core's
    :func:`core.scene.lifts_off`; of any punch, for several)."""
    return bool(np.any(lifted_times(view)))


def lifted_times(view: ResultView) -> np.ndarray:
    """At each output time, whether the contact set is narrower than the base (of any
    punch, for several): boolean, shape (len(times),)."""
    if view.punches:
        return np.any([np.asarray(core_lifts_off(_local_set(p), p.half_width), dtype=bool)
                       for p in view.punches], axis=0)
    return np.asarray(core_lifts_off(_contact_set(view), view.geometry.half_width),
                      dtype=bool)


def lifts_or_pulls(view: ResultView) -> bool:
    """Whether some part of the base is drawn lifted off or pulling (q < 0 of a
    full-contact answer that lost contact) at some output time."""
    return any(view.negative_intervals(j) for j in range(len(view.times)))


def model_name(view: ResultView) -> str:
    """Which contact model answered, in words (the solver's ``info["contact"]``)."""
    contact = view.info.get("contact")
    if contact == "unilateral":
        return "unilateral contact"
    if contact == "full":
        return "full-contact model"
    return "contact model not reported"


def _fmt_m(value: float) -> str:
    return f"{value:.3f}".rstrip("0").rstrip(".") if abs(value) >= 1e-3 else f"{value:.2g}"


def contact_text(view: ResultView, index: int) -> str:
    """The contact at output ``index`` in plain words, lengths in m, e.g. "contact
    1.306 m of 2 m (65 %), lifted 0.694 m: x = -1 to -0.306 m (unilateral contact)", or
    for a full-contact answer that pulls "contact 2 m of 2 m, as the full-contact model
    assumes; q < 0 (contact lost) on 0.372 m: x = -1 to -0.628 m (not physical)"; for
    several punches, one such text per punch ("punch 1: ...; punch 2: ...")."""
    if view.punches:
        return "; ".join(f"punch {k + 1}: {_punch_contact_text(view, p, index)}"
                         for k, p in enumerate(view.punches))
    a = view.geometry.half_width
    full = 2 * a
    off = view.negative_intervals(index)
    where = ", ".join(f"x = {_fmt_m(lo)} to {_fmt_m(hi)} m" for lo, hi in off)
    width = float(contact_widths(view)[index])
    if core_lifts_off(_contact_set(view)[index:index + 1], a)[0]:
        return (f"contact {_fmt_m(width)} m of {_fmt_m(full)} m ({100 * width / full:.0f} %), "
                f"lifted {_fmt_m(full - width)} m: {where} ({model_name(view)})")
    if off:
        pulled = sum(hi - lo for lo, hi in off)
        return (f"contact {_fmt_m(width)} m of {_fmt_m(full)} m, as the {model_name(view)} "
                f"assumes; q < 0 (contact lost) on {_fmt_m(pulled)} m: {where} (not physical)")
    return f"full contact: the whole width 2a = {_fmt_m(full)} m touches"


def _punch_contact_text(view: ResultView, p: PunchResult, index: int) -> str:
    """The contact of one punch of several at output ``index``, in words (global x)."""
    full = 2 * p.half_width
    width = float(contact_width(_local_set(p)[index:index + 1], p.half_width)[0])
    off = p.negative_intervals(index)
    where = ", ".join(f"x = {_fmt_m(lo)} to {_fmt_m(hi)} m" for lo, hi in off)
    if core_lifts_off(_local_set(p)[index:index + 1], p.half_width)[0]:
        return (f"contact {_fmt_m(width)} m of {_fmt_m(full)} m, lifted "
                f"{_fmt_m(full - width)} m: {where}")
    if off:
        return f"full-contact model, q < 0 (contact lost) at {where} (not physical)"
    return f"full contact over {_fmt_m(full)} m"
