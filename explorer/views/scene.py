"""The Scene tab: presets, undo and reset, and the loading (which two are given)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import panel as pn

from ..model import STATEMENTS, preset_label
from .eccentricity import EccentricityControl
from .style import TAB_COLUMN, html_pane
from .widgets import NAMES, HistoryEditor

if TYPE_CHECKING:
    from ..app import ExplorerApp


class SceneView:
    """The preset chooser, undo/reset and the editors of the two given histories."""

    title = "Scene"

    def __init__(self, app: ExplorerApp) -> None:
        self.app = app
        s = app.state
        options = {"(custom scene)": ""}
        options.update({preset_label(k, v): k for k, v in app.presets.items()})
        self.preset = pn.widgets.Select(label="Preset scene", options=options,
                                        value=app.preset_key or "",
                                        sizing_mode="stretch_width",
                                        css_classes=["preset-select"])
        self.preset_description = pn.pane.Markdown(self._preset_text(), margin=(0, 10),
                                                   styles={"font-size": "13px"})
        self.preset.param.watch(self._on_preset, "value")
        self.undo_button = pn.widgets.Button(label="↶ Undo", disabled=True,
                                             css_classes=["undo-button"])
        self.undo_button.on_click(lambda e: app.undo())
        self.reset_button = pn.widgets.Button(label="Reset to the loaded scene",
                                              css_classes=["reset-button"])
        self.reset_button.on_click(lambda e: app.reset())

        self.statement = pn.widgets.Select(label="statement (which two are given)",
                                           options=list(STATEMENTS), value=s.loading.statement,
                                           sizing_mode="stretch_width",
                                           css_classes=["statement-select"])
        self.statement.param.watch(lambda e: setattr(s.loading, "statement", e.new), "value")
        s.loading.param.watch(self.refresh, "statement")
        self.history_editors = (HistoryEditor("load-0"), HistoryEditor("load-1"))
        self.unknowns_note = html_pane("", styles={"font-size": "13px"})
        self.eccentric_load = EccentricityControl(app)
        self.refresh()

    def content(self) -> pn.Column:
        """The tab's column."""
        return pn.Column(
            self.preset, pn.Row(self.undo_button, self.reset_button),
            self.preset_description,
            html_pane("<b>Loading</b> (updates while you drag)", margin=(10, 10, 0, 10)),
            self.statement, self.eccentric_load.panel, self.history_editors[0].panel,
            self.history_editors[1].panel, self.unknowns_note, **TAB_COLUMN)

    def _preset_text(self) -> str:
        key = getattr(self, "preset", None) and self.preset.value
        scene = self.app.presets.get(key) if key else None
        if scene is None:
            return "Your own scene: start from a preset, a file or a link."
        return str(scene.get("description", ""))

    def _on_preset(self, event: Any) -> None:
        key = event.new
        self.preset_description.object = self._preset_text()
        if not key or key not in self.app.presets:
            return
        self.app.load_scene(self.app.presets[key])

    def refresh(self, *events: Any) -> None:
        """Point the history editors at the two given quantities; name the unknowns."""
        loading = self.app.state.loading
        if self.statement.value != loading.statement:
            self.statement.value = loading.statement
        for editor, q in zip(self.history_editors, loading.given, strict=True):
            editor.bind(loading.histories[q], self.app.state.time_end)
        unknowns = " and ".join(NAMES[q] for q in loading.unknowns)
        self.unknowns_note.object = f"Computed: <b>{unknowns}</b> (and the pressure)."
