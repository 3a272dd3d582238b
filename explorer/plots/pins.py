"""The pinned results on the figures: one dashed line per pin, named in the legend.

The lines are made once per session, :data:`~explorer.model.pins.MAX_PINS` of them per figure,
and hidden while their slot is empty: pinning fills a slot's data, it never adds models
to the page. Nothing here imports Panel.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from bokeh.core.properties import value
from bokeh.models import ColumnDataSource, LegendItem

from ..model import MAX_PINS, QUANTITIES, DisplayScales, Pin, ResultView
from .bokeh_data import broken_at, f32, set_data, wrap_legend

#: Colours of the pins, in pin order (none of them the blue of the current result).
PIN_COLORS = ("#d62728", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2")
assert len(PIN_COLORS) >= MAX_PINS


class PinLines:
    """Dashed lines of the pinned results on the pressure plot and the histories.

    A slot's lines are made when a pin first needs them, and then kept (hidden while the
    slot is empty): a page without pins carries no pin models, which every repaint of a
    load step would walk past (measured: ~20 ms more of the page's CPU per load step
    with six slots made in advance)."""

    def __init__(self, q_fig: Any, history_fig: Mapping[str, Any],
                 scales: DisplayScales) -> None:
        """``q_fig``: the figure of q(x) (its legend names the pins); ``history_fig``: the
        figure of each quantity's history; ``scales``: the session's pressure unit."""
        self.q_fig = q_fig
        self.history_fig = history_fig
        self.scales = scales
        self.q_src: list[ColumnDataSource] = []
        self.q_lines: list = []
        self.history_src: dict[str, list[ColumnDataSource]] = {q: [] for q in QUANTITIES}
        self.history_lines: dict[str, list] = {q: [] for q in QUANTITIES}
        self.legend_items: list[LegendItem] = []
        self._labels: list[str] = []
        self._key: list[tuple[int, str]] = []   # the pins drawn: (id of the result, name)
        self._filled = 0                         # pressure slots holding data
        self._held: list[ResultView] = []

    def _make_slot(self) -> None:
        """The lines and the legend entry of one more pin slot."""
        k = len(self.q_lines)
        color = PIN_COLORS[k]
        dashed = {"line_color": color, "line_dash": "dashed", "line_width": 2}
        src = ColumnDataSource({"x": [], "q": []}, name=f"q_pin_source_{k}")
        self.q_src.append(src)
        self.q_lines.append(self.q_fig.line(x="x", y="q", source=src, **dashed))
        for q in QUANTITIES:
            hsrc = ColumnDataSource({"t": [], "v": []}, name=f"{q}_pin_source_{k}")
            self.history_src[q].append(hsrc)
            self.history_lines[q].append(
                self.history_fig[q].line(x="t", y="v", source=hsrc, **dashed))
        item = LegendItem(label=value(f"pin {k + 1}"), renderers=[self.q_lines[-1]],
                          name=f"pin_legend_{k}")
        self.legend_items.append(item)
        self._labels.append(f"pin {k + 1}")
        # the entries of the pins after "q < 0" and before the classical lines
        legend = self.q_fig.legend[0]
        legend.items = legend.items[:k + 1] + [item] + legend.items[k + 1:]

    def show(self, view: ResultView, pins: Sequence[Pin], index: int) -> None:
        """Draw the pins (histories and pressure at the time shown of ``view``).

        The pinned histories are sent only when the pins change, not at each new result
        (a load step): checking 24 empty sources per step cost 1 ms of the server."""
        key = [(id(pin.view), pin.label) for pin in pins]
        if key != self._key:
            self._key = key
            self._held = [pin.view for pin in pins]   # their ids stay theirs while drawn
            while len(self.q_lines) < min(len(pins), MAX_PINS):
                self._make_slot()
            for k in range(len(self.q_lines)):
                pin = pins[k] if k < len(pins) else None
                shown = pin is not None
                self.q_lines[k].visible = shown
                self.legend_items[k].visible = shown
                if shown and self._labels[k] != pin.label:  # a message only when renamed
                    # a plain string would be read as a column name (a "field") by the page
                    self.legend_items[k].label = value(pin.label)
                    self._labels[k] = pin.label
                for q in QUANTITIES:
                    self.history_lines[q][k].visible = shown
                    t, v = (broken_at(pin.view.times, pin.view.display(q), pin.view.jumps)
                            if shown else ([], []))
                    data = {"t": t, "v": v}
                    set_data(self.history_src[q][k], data)
            # the entries in columns when there are more than fit one row
            wrap_legend(self.q_fig.legend[0])
        self.show_time(view, pins, index)

    def show_time(self, view: ResultView, pins: Sequence[Pin], index: int) -> None:
        """The pinned pressures at the output time of ``view`` shown (nearest time)."""
        size = self.scales.pressure_unit(view)[1]
        t = float(view.times[index])
        for k, pin in enumerate(pins[:len(self.q_src)]):
            other = pin.view
            j = other.time_index(t)
            set_data(self.q_src[k], {"x": f32(other.x), "q": f32(other.pressure[:, j] / size)})
        for k in range(len(pins), self._filled):   # slots emptied since the last time
            set_data(self.q_src[k], {"x": [], "q": []})
        self._filled = min(len(pins), len(self.q_src))
