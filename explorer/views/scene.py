"""The Scene tab: presets, undo and reset, and the loading (which two are given)."""

from __future__ import annotations

import html
import re
from collections.abc import Callable
from typing import Any

import panel as pn

from core.scene import days_text, number_text

from ..fixes import layout_batch
from ..model import QUANTITY_UNITS, STATEMENTS, ExplorerState, SceneHistory, preset_label
from ..solving import SolveController
from .eccentricity import EccentricityControl
from .punches import OnePunchOnly
from .style import TAB_COLUMN, html_pane
from .widgets import NAMES, HistoryEditor, PromptSelect


def _held(change: Callable[[], Any]) -> None:
    """Make ``change`` (a whole scene set again) reach the page in one message, the
    page's models walked once for the sliders it makes (``layout_batch``)."""
    with pn.io.hold(), layout_batch.batch():
        change()


def _as_text(text: str) -> str:
    """A file's text shown as it is in the Markdown pane: HTML escaped (the pane renders
    HTML within Markdown) and the characters that format Markdown inline too ("2*3*4"
    read "2<em>3</em>4"). Quotes are left as they are: their entities' "#", escaped as
    Markdown, showed "coating&#x27;s"."""
    return re.sub(r"([\\`*_\[\]$~#|])", r"\\\1", html.escape(text, quote=False))


class SceneView:
    """The preset chooser, undo/reset and the editors of the two given histories."""

    title = "Scene"

    def __init__(self, state: ExplorerState, presets: dict[str, dict[str, Any]],
                 preset_key: str | None, history: SceneHistory,
                 load_scene: Callable[[dict[str, Any]], bool], controller: SolveController,
                 reject: Callable[[str], None], drag: Any = None) -> None:
        """``presets``: key -> scene, offered in this order; ``preset_key``: the preset on
        screen (None: another scene); ``history``: undo and reset; ``load_scene``: shows
        a preset chosen; ``controller``, ``reject`` and ``drag`` (its drag steps held:
        see :class:`~.eccentricity.EccentricityControl`): for the eccentricity slider."""
        self.state = s = state
        self.presets = presets
        self.history = history
        self.load_scene = load_scene
        options = {"(custom scene)": ""}
        options.update({preset_label(k, v): k for k, v in presets.items()})
        self.preset = PromptSelect(label="Preset scene", options=options,
                                   value=preset_key or "",
                                   sizing_mode="stretch_width",
                                   css_classes=["preset-select"])
        self.preset_description = pn.pane.Markdown(self._preset_text(), margin=(0, 10),
                                                   styles={"font-size": "13px"})
        self.preset.param.watch(self._on_preset, "value")
        self.undo_button = pn.widgets.Button(label="↶ Undo", disabled=not history.can_undo,
                                             css_classes=["undo-button"])
        self._syncing = False  # the selector set to follow the scene, not to load one
        self.undo_button.on_click(lambda e: _held(lambda: self._back(history.undo)))
        history.param.watch(lambda e: setattr(self.undo_button, "disabled", not e.new),
                            "can_undo")
        self.reset_button = pn.widgets.Button(label="Reset to the loaded scene",
                                              css_classes=["reset-button"])
        self.reset_button.on_click(lambda e: _held(lambda: self._back(history.reset)))

        self.statement = PromptSelect(label="statement (which two are given)",
                                      options=list(STATEMENTS), value=s.loading.statement,
                                      sizing_mode="stretch_width",
                                      css_classes=["statement-select"])
        self.controller = controller
        self.statement.param.watch(self._on_statement, "value")
        s.loading.param.watch(self.refresh, "statement")
        self.history_editors = (HistoryEditor("load-0", reject, drag),
                                HistoryEditor("load-1", reject, drag))
        self.unknowns_note = html_pane("", styles={"font-size": "13px"})
        # where the quantities a statement newly gives came from, until one is changed
        self._taken = ""
        for load in s.loading.histories.values():
            load.param.watch(self._given_changed, ["value", "kind", "second", "time",
                                                   "custom"])
        self.eccentric_load = EccentricityControl(state, controller, reject, drag)
        self.loading = OnePunchOnly(
            state, "This loading", self.statement, self.eccentric_load.panel,
            self.history_editors[0].panel, self.history_editors[1].panel,
            self.unknowns_note)
        self.loading.note.object = ("This scene has several punches: each one's loads are "
                                    "set in the Punch tab.")
        self.refresh()

    def content(self) -> pn.Column:
        """The tab's column."""
        return pn.Column(
            self.preset, pn.Row(self.undo_button, self.reset_button),
            self.preset_description,
            html_pane("<b>Loading</b> (updates while you drag)", margin=(10, 10, 0, 10)),
            self.loading.panel, **TAB_COLUMN)

    def _preset_text(self) -> str:
        key = getattr(self, "preset", None) and self.preset.value
        scene = self.presets.get(key) if key else None
        if scene is None:
            # a scene of its own (a file, a lesson's step) says what it is, as a preset
            # does: the scene on screen's (an undo brings its name and text back)
            state = getattr(self, "state", None)
            if state is not None and state.description.strip():
                return (f"**{_as_text(state.scene_name)}**: "
                        f"{_as_text(state.description)}")
            return "Your own scene: start from a preset, a file or a link."
        return str(scene.get("description", ""))

    def _on_preset(self, event: Any) -> None:
        key = event.new
        self.preset_description.object = self._preset_text()
        if self._syncing or not key or key not in self.presets:
            return
        self.load_scene(self.presets[key])

    def _back(self, action: Callable[[], None]) -> None:
        """Undo or reset (``action``), then show the preset of the scene it brought back
        (by its name; none for a scene of its own) with its description: an undo across
        a preset change left the later preset's name and text on screen."""
        action()
        name = self.state.scene_name
        key = next((k for k, scene in self.presets.items() if scene.get("name") == name), "")
        if self.preset.value != key:
            self._syncing = True
            try:
                self.preset.value = key
            finally:
                self._syncing = False
        self.preset_description.object = self._preset_text()

    def forget_preset(self) -> None:
        """Show no preset as chosen (a scene from a file or a lesson's step is a scene of
        its own), and that scene's name and description."""
        self.preset.value = ""
        self.preset_description.object = self._preset_text()

    def _on_statement(self, event: Any) -> None:
        """A statement chosen on the page: the quantities it newly gives start at the
        answer on screen, constant at its value at the last output time (they started at
        0.05 mm and 0 mrad whatever the answer was, a teacher's audit: another scene);
        on an elastic base under constant loads the answer stays the same."""
        loading = self.state.loading
        if event.new == loading.statement:  # (the selector following the state)
            return
        view = self.controller.view
        taken = []
        if view is not None and not view.several:
            for q in STATEMENTS[event.new]:
                if q not in loading.given:
                    value = float(view.display(q)[-1])
                    loading.histories[q].param.update(kind="constant", value=value,
                                                      custom=None)
                    taken.append(f"{NAMES[q]} = {number_text(value, 5)} "
                                 f"{QUANTITY_UNITS[q][0]}")
        # said, as the loads it replaced are not brought back by switching back (force
        # and moment 800 and 120 came back as 740.27 and 110.99 after three switches on
        # a creeping base: an audit)
        self._taken = ("" if not taken else
                       f"Now given, held at the answer's values at "
                       f"t = {days_text(float(view.times[-1]))}: {', '.join(taken)}. "
                       "Under creep the answer then changes, and a switch back takes the "
                       "values of that answer, not the loads given before.")
        loading.statement = event.new

    def refresh(self, *events: Any) -> None:
        """Point the history editors at the two given quantities; name the unknowns."""
        loading = self.state.loading
        if self.statement.value != loading.statement:
            self.statement.value = loading.statement
        for editor, q in zip(self.history_editors, loading.given, strict=True):
            editor.bind(loading.histories[q], self.state.time_end)
        unknowns = " and ".join(NAMES[q] for q in loading.unknowns)
        taken = ("" if not self._taken else "<br><small class='statement-taken'>"
                 f"{html.escape(self._taken, quote=False)}</small>")
        self.unknowns_note.object = f"Computed: <b>{unknowns}</b> (and the pressure).{taken}"

    def _given_changed(self, *events: Any) -> None:
        """A given load changed (typed, a file, another scene): what the last statement
        took from the answer is no longer what is given."""
        if self._taken:
            self._taken = ""
            self.refresh()
