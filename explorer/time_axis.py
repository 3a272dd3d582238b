"""A logarithmic time axis for the histories, switched in place on the same figures.

A creep history over years changes fastest in its first days: on a linear axis the
first tenth of the plot holds most of the change. The figures are kept (their data, zoom
and shared range), only their scale and ticker change; BokehJS redraws a frame whose
scale was replaced. Times at or before loading (t <= 0) have no place on a log axis and
are left out of the drawn line. Nothing here imports Panel.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from bokeh.models import BasicTicker, DataRange1d, LinearScale, LogScale, LogTicker

#: Axis label of the histories' time axis, linear and logarithmic.
LABELS = {False: "t [days after loading]", True: "t [days after loading, log scale]"}


def is_log(fig: Any) -> bool:
    """Whether ``fig`` draws its x axis on a log scale."""
    return isinstance(fig.x_scale, LogScale)


def set_log_time(figures: Iterable[Any], log: bool) -> None:
    """Draw the time (x) axis of ``figures`` logarithmic (``log``) or linear."""
    figures = [fig for fig in figures if is_log(fig) != log]
    # A new shared range: BokehJS marks a range it finds under a log scale to fit the
    # positive values only, and never unmarks it, so a range back on a linear scale
    # would leave out t = 0.
    shared = DataRange1d()
    for fig in figures:
        fig.x_scale = LogScale() if log else LinearScale()
        if isinstance(fig.x_range, DataRange1d):
            fig.x_range = shared
        for axis in fig.xaxis:
            axis.ticker = LogTicker() if log else BasicTicker()
            axis.axis_label = LABELS[log]
