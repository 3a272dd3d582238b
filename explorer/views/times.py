"""The Time tab: output times and the accuracy target."""

from __future__ import annotations

import html
from collections.abc import Callable
from typing import Any

import panel as pn

from ..model import ExplorerState
from .fidelity import FidelityView
from .style import NOTE_STYLE, TAB_COLUMN, html_pane
from .widgets import (
    Binding,
    EditableIntSlider,
    NumberBox,
    PromptRadioButtonGroup,
    PromptSelect,
    next_tick,
    slider,
)

SPACINGS = {"linear": "linear", "log": "log"}


class TimesView:
    """Widgets of the state's time span [days], output times and tolerance."""

    title = "Time"

    def __init__(self, state: ExplorerState, fidelity: FidelityView,
                 reject: Callable[[str], None], live_when: Callable[[], bool]) -> None:
        """``fidelity``: its solver settings sit under the accuracy target."""
        self.state = s = state
        self.fidelity = fidelity
        self.global_binding = Binding(reject, live_when=live_when)
        gb = self.global_binding
        self.time_end = gb.add("time_end", slider("time span [days after loading]", 1.0,
                                                  3650.0, 1.0,
                                                  css_classes=["time-end"]))
        self.time_count = gb.add("time_count", EditableIntSlider(
            label="output times", start=2, end=200, step=1, sizing_mode="stretch_width",
            css_classes=["time-count"]))
        self.time_spacing = gb.add("time_spacing", PromptRadioButtonGroup(
            label="spacing", options=list(SPACINGS), sizing_mode="stretch_width"))
        # where log spacing begins: over 50 years its default (the last three decades)
        # begins at 18 days, after most of a young concrete's early creep. Not through
        # the binding: an emptied box is a value here (the default), not a refusal
        self._reject = reject
        self.time_start = NumberBox(
            label="first time after 0 [days] (empty: span / 1000)", value=s.time_start,
            # no lower bound on the box: the page would keep -1 on show unsent, unsaid
            step=1.0, sizing_mode="stretch_width", css_classes=["time-start"])
        self.time_start.param.watch(self._on_time_start, "value")
        s.param.watch(self._show_time_start, "time_start")
        self.tol = gb.add("tol", PromptSelect(
            label="accuracy target (relative)",
            options={f"{v:g}": v for v in s.param.tol.objects},
            sizing_mode="stretch_width", css_classes=["tol-select"]))
        # why the target was raised (a design code's creep law), under the target
        self.tol_note = html_pane("", styles=NOTE_STYLE, css_classes=["tol-note"])
        gb.bind(s)
        s.param.watch(lambda *e: self.refresh(), ["tol", "tol_note", "time_spacing"])
        self.refresh()

    def content(self) -> pn.Column:
        """The tab's column."""
        return pn.Column(self.time_end, self.time_count, self.time_spacing, self.time_start,
                         self.tol,
                         self.tol_note, self.fidelity.solver_panel, **TAB_COLUMN)

    def _on_time_start(self, event: Any) -> None:
        value = event.new
        if value is not None and not value == value:  # an emptied box: the page sends NaN
            value = None
        if value == self.state.time_start:
            return
        try:
            self.state.time_start = value
        except ValueError:
            self._reject(f"first time after 0: must be a number of days > 0 (leave it "
                         f"empty: a thousandth of the span), got {value:g}; it stays "
                         + ("empty" if self.state.time_start is None
                            else f"{self.state.time_start:g}"))
            next_tick(lambda: self._show_time_start())

    def _show_time_start(self, *events: Any) -> None:
        if self.time_start.value != self.state.time_start:
            self.time_start.value = self.state.time_start

    def refresh(self) -> None:
        """Offer the tolerances the state allows; show the one set."""
        options = {f"{v:g}": v for v in self.state.param.tol.objects}
        if options != self.tol.options:
            self.tol.options = options
        self.tol.value = self.state.tol
        self.tol_note.object = html.escape(self.state.tol_note)
        self.tol_note.visible = bool(self.state.tol_note)
        self.time_start.visible = self.state.time_spacing == "log"
