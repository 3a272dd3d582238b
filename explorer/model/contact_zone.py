"""The contact zone of a result in numbers: where the base touches, how wide, how much lifts.

A unilateral solve reports its contact set per output time (``ResultView.contact_set``);
a full-contact solve that lost contact reports negative pressure instead, and
:meth:`~explorer.model.results.ResultView.negative_intervals` turns either into the lifted
parts. Everything here follows that one rule, so the drawing, the width plot, the
readout and the design check never disagree. Nothing here imports Panel or Bokeh.
"""

from __future__ import annotations

import numpy as np

from .results import ResultView, lifted_intervals


def contact_zones(view: ResultView, index: int) -> list[tuple[float, float]]:
    """Intervals of ``x`` [m] in contact at output ``index`` (the whole ``[-a, a]`` in full
    contact): the complement of the lifted parts."""
    a = view.geometry.half_width
    return lifted_intervals(view.negative_intervals(index), a)


def contact_widths(view: ResultView) -> np.ndarray:
    """Total length in contact [m] at each output time (``2a`` in full contact)."""
    a = view.geometry.half_width
    return np.array([2 * a - sum(hi - lo for lo, hi in view.negative_intervals(j))
                     for j in range(len(view.times))], dtype=float)


def lifts_off(view: ResultView) -> bool:
    """Whether some part of the base is lifted off at some output time."""
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
    1.306 m of 2 m (65 %), lifted 0.694 m: x = -1 to -0.306 m (unilateral contact)"."""
    a = view.geometry.half_width
    lifted = view.negative_intervals(index)
    full = 2 * a
    if not lifted:
        return f"full contact: the whole width 2a = {_fmt_m(full)} m touches"
    width = full - sum(hi - lo for lo, hi in lifted)
    where = ", ".join(f"x = {_fmt_m(lo)} to {_fmt_m(hi)} m" for lo, hi in lifted)
    kind = ("lifted" if view.info.get("contact") == "unilateral"
            else "q < 0 (contact lost)")
    return (f"contact {_fmt_m(width)} m of {_fmt_m(full)} m ({100 * width / full:.0f} %), "
            f"{kind} {_fmt_m(full - width)} m: {where} ({model_name(view)})")
