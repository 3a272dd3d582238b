"""The Time tab: output times and the accuracy target."""

from __future__ import annotations

import html
from collections.abc import Callable

import panel as pn

from ..model import ExplorerState
from .fidelity import FidelityView
from .style import NOTE_STYLE, TAB_COLUMN, html_pane
from .widgets import Binding, EditableIntSlider, NumberBox, slider

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
                                                  3650.0, 1.0, "0[.]0"))
        self.time_count = gb.add("time_count", EditableIntSlider(
            label="output times", start=2, end=200, step=1, sizing_mode="stretch_width"))
        self.time_spacing = gb.add("time_spacing", pn.widgets.RadioButtonGroup(
            label="spacing", options=list(SPACINGS), sizing_mode="stretch_width"))
        # where log spacing begins: over 50 years its default (the last three decades)
        # begins at 18 days, after most of a young concrete's early creep
        self.time_start = gb.add("time_start", NumberBox(
            label="first time after 0 [days] (empty: span / 1000)",
            start=0.0, step=1.0, sizing_mode="stretch_width", css_classes=["time-start"]))
        self.tol = gb.add("tol", pn.widgets.Select(
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

    def refresh(self) -> None:
        """Offer the tolerances the state allows; show the one set."""
        options = {f"{v:g}": v for v in self.state.param.tol.objects}
        if options != self.tol.options:
            self.tol.options = options
        self.tol.value = self.state.tol
        self.tol_note.object = html.escape(self.state.tol_note)
        self.tol_note.visible = bool(self.state.tol_note)
        self.time_start.visible = self.state.time_spacing == "log"
