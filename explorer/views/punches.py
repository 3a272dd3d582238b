"""Several punches on one foundation: the Punch tab's section for a scene of several
(``punches``), and the note that stands in for what applies to one punch only.

The section adds and removes punches (1 to :data:`~explorer.model.SCREEN_PUNCHES`),
chooses the punch edited, and edits its centre and half-width (on release, or at each
drag step while solves are fast, as the other geometry sliders) and its two given loads
(live while dragging, as the Scene tab's). Overlapping punches are refused by the core,
whose message the page shows as any other refusal, keeping the last good result.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import panel as pn

from ..model import SCREEN_PUNCHES, STATEMENTS, ExplorerState, PunchEntryState
from ..plots import PUNCH_COLORS
from .style import NOTE_STYLE, html_pane
from .widgets import NAMES, Binding, HistoryEditor, PromptRadioButtonGroup, PromptSelect, slider


class OnePunchOnly:
    """Parts of a tab that apply to a scene of one punch: hidden while the scene has
    several, a note saying so in their place."""

    def __init__(self, state: ExplorerState, what: str, *parts: Any) -> None:
        """``what``: the parts in words, the subject of the note ("The design check")."""
        self.state = state
        self.note = html_pane(
            f"{what}: for a scene of one punch. This scene has several punches, so this "
            "is off here for now.", styles=NOTE_STYLE, visible=False,
            css_classes=["one-punch-only"])
        self.body = pn.Column(*parts, margin=0, sizing_mode="stretch_width")
        self.panel = pn.Column(self.note, self.body, margin=0, sizing_mode="stretch_width")
        state.param.watch(lambda e: self.follow(), "n_punches")
        self.follow()

    def follow(self) -> None:
        """Show the parts or the note, as the scene has one punch or several."""
        several = self.state.n_punches > 0
        self.note.visible = several
        self.body.visible = not several


class PunchesSection:
    """The punches of a scene of several: how many, which one is edited, and its centre,
    half-width, statement and loads."""

    def __init__(self, state: ExplorerState, reject: Callable[[str], None],
                 live_when: Callable[[], bool]) -> None:
        """``reject``: says why a value was refused; ``live_when``: whether a geometry
        slider applies each drag step (else its release)."""
        self.state = s = state
        self.reject = reject
        self.count = html_pane("", css_classes=["punches-count"])
        self.add_button = pn.widgets.Button(label="+ Add a punch", css_classes=["punch-add"])
        self.remove_button = pn.widgets.Button(label="− Remove this punch", color="light",
                                               css_classes=["punch-remove"])
        self.add_button.on_click(lambda e: self.add())
        self.remove_button.on_click(lambda e: self.remove())
        self.select = PromptRadioButtonGroup(options=["1"], value="1", color="primary",
                                             variant="outline",
                                             css_classes=["punch-select"])
        self.select.param.watch(lambda e: self.bind(), "value")
        self.where = Binding(reject, live_when=live_when)
        self.center = self.where.add("center", slider(
            "centre x [m]", -10.0, 10.0, 0.01, css_classes=["punch-center"]))
        self.shape = Binding(reject, live_when=live_when)
        self.half_width = self.shape.add("half_width", slider(
            "half-width a [m]", 0.1, 5.0, 0.01, css_classes=["punch-half-width-of"]))
        self.statement = PromptSelect(label="statement (which two are given)",
                                      options=list(STATEMENTS),
                                      sizing_mode="stretch_width",
                                      css_classes=["punch-statement"])
        self.statement.param.watch(self._on_statement, "value")
        self.history_editors = (HistoryEditor("punch-load-0", reject, live_when),
                                HistoryEditor("punch-load-1", reject, live_when))
        self.note = html_pane(
            "Each punch's settlement and tilt are its own, its moment is about its own "
            "centre. Punches may not overlap or touch: the solver says which do. Loads "
            "update while you drag; the centre and half-width too while solves are "
            "quick, else when you release (the page says so).",
            styles=NOTE_STYLE)
        self.panel = pn.Column(
            html_pane("<b>Punches</b> (a scene of several)", margin=(10, 10, 0, 10)),
            self.count, pn.Row(self.add_button, self.remove_button, margin=0),
            self.select, self.center, self.half_width, self.statement,
            self.history_editors[0].panel, self.history_editors[1].panel, self.note,
            margin=0, sizing_mode="stretch_width", css_classes=["punches-section"])
        self._watched: list[tuple[Any, Any]] = []
        s.param.watch(lambda e: self.refresh(), "n_punches")
        s.param.watch(lambda e: self._say_count(), "revision")
        self.refresh()

    @property
    def index(self) -> int:
        """The punch edited (0 = first)."""
        return int(self.select.value) - 1

    @property
    def entry(self) -> PunchEntryState:
        """The state of the punch edited."""
        return self.state.punch_entries[self.index]

    def add(self) -> None:
        """Add a punch beside the rightmost (a copy of it) and edit it."""
        try:
            k = self.state.add_punch()
        except ValueError as exc:
            self.reject(str(exc))
            return
        self.refresh(select=k)

    def remove(self) -> None:
        """Remove the punch edited (one punch at least stays)."""
        try:
            self.state.remove_punch(self.index)
        except ValueError as exc:
            self.reject(str(exc))
            return
        self.refresh(select=min(self.index, self.state.n_punches - 1))

    def refresh(self, select: int | None = None) -> None:
        """Offer one button per punch (in its colour's order) and edit the one chosen."""
        n = self.state.n_punches
        if n == 0:
            return
        options = [str(k + 1) for k in range(n)]
        value = options[select] if select is not None and select < n else (
            self.select.value if self.select.value in options else options[-1])
        if self.select.options != options:
            self.select.options = options
        self.add_button.disabled = n >= SCREEN_PUNCHES
        self.remove_button.disabled = n <= 1
        if self.select.value != value:
            self.select.value = value  # binds
        else:
            self.bind()

    def _say_count(self) -> None:
        n = self.state.n_punches
        if not n:
            return
        dots = " ".join(f"<span style='color:{PUNCH_COLORS[k]}'>■ {k + 1}: x = "
                        f"{e.center:.3g} m</span>" for k, e in enumerate(self.state.punches))
        text = (f"<small>{n} punch{'es' if n > 1 else ''} (at most {SCREEN_PUNCHES}): "
                f"{dots}</small>")
        if self.count.object != text:
            self.count.object = text

    def bind(self) -> None:
        """Point the widgets at the punch chosen."""
        if not 0 <= self.index < self.state.n_punches:
            return
        entry = self.entry
        self.where.bind(entry)
        self.shape.bind(entry.punch)
        for obj, watcher in self._watched:
            obj.param.unwatch(watcher)
        self._watched = [(entry.loading, entry.loading.param.watch(
            lambda e: self._bind_loads(), "statement"))]
        self._bind_loads()
        self._say_count()

    def _bind_loads(self) -> None:
        loading = self.entry.loading
        if self.statement.value != loading.statement:
            self._syncing = True
            try:
                self.statement.value = loading.statement
            finally:
                self._syncing = False
        for editor, q in zip(self.history_editors, loading.given, strict=True):
            editor.bind(loading.histories[q], self.state.time_end)
        unknowns = " and ".join(NAMES[q] for q in loading.unknowns)
        self.note.object = (
            f"Computed for punch {self.index + 1}: <b>{unknowns}</b>. Each punch's "
            "settlement and tilt are its own, its moment is about its own centre. Punches "
            "may not overlap or touch: the solver says which do. Loads update while you "
            "drag; the centre and half-width too while solves are quick, else when you "
            "release (the page says so).")

    def _on_statement(self, event: Any) -> None:
        if self._syncing or not 0 <= self.index < self.state.n_punches:
            return
        self.entry.loading.statement = event.new

    _syncing = False
