"""The Coating tab: the number of layers and the profiles of the layer being edited."""

from __future__ import annotations

from typing import TYPE_CHECKING

import panel as pn

from ..state import SCREEN_LAYERS
from ..widgets import ProfileEditor, PromptIntSlider
from .style import NOTE_STYLE, TAB_COLUMN, html_pane

if TYPE_CHECKING:
    from ..app import ExplorerApp


class CoatingView:
    """Widgets of ``state.layers``: thickness h(x), modulus E(x), Poisson ratio of each."""

    title = "Coating"

    def __init__(self, app: ExplorerApp) -> None:
        self.app = app
        s = app.state
        live = app.fast_solves
        self.n_layers = PromptIntSlider(label="number of layers", start=1, end=SCREEN_LAYERS,
                                        value=min(s.n_layers, SCREEN_LAYERS),
                                        sizing_mode="stretch_width")
        self.n_layers.param.watch(lambda e: setattr(s, "n_layers", e.new), "value_throttled")
        self.layer = pn.widgets.RadioButtonGroup(label="edit layer", options=["1"], value="1",
                                                 color="primary", variant="outline",
                                                 sizing_mode="stretch_width")
        self.layer.param.watch(lambda *e: self.bind_layer(), "value")
        self.thickness_editor = ProfileEditor("thickness", "mm", 0.5, 50.0, 0.1, "0[.]00",
                                              amplitude=("µm", -1000.0, 1000.0, 0.5),
                                              css="coating-thickness", live_when=live)
        self.modulus_editor = ProfileEditor("Young's modulus", "MPa", 1.0, 10000.0, 1.0,
                                            "0[.]0", live_when=live)
        self.poisson_editor = ProfileEditor("Poisson ratio", "-", 0.0, 0.49, 0.01, "0[.]000",
                                            variations=False, live_when=live)
        self.layer_note = html_pane("", styles=NOTE_STYLE)
        s.param.watch(lambda *e: self.refresh(), "n_layers")
        self.refresh()

    def content(self) -> pn.Column:
        """The tab's column."""
        return pn.Column(
            html_pane("<small>Layer 1 touches the punch. Changes apply when you release "
                      "a slider.</small>"),
            self.n_layers, self.layer, self.layer_note, self.thickness_editor.panel,
            self.modulus_editor.panel, self.poisson_editor.panel,
            self.app.fidelity.interface_panel, **TAB_COLUMN)

    def refresh(self) -> None:
        """Offer one button per layer on screen; say so when the scene has more."""
        n = self.app.state.n_layers
        shown = min(n, SCREEN_LAYERS)
        options = [str(k + 1) for k in range(shown)]
        if self.layer.value not in options:
            self.layer.value = options[-1]
        self.layer.options = options
        self.n_layers.value = shown
        self.layer_note.object = (f"This scene has {n} layers; the screen edits the first "
                                  f"{SCREEN_LAYERS}." if n > SCREEN_LAYERS else "")
        self.layer_note.visible = bool(self.layer_note.object)
        self.bind_layer()

    def bind_layer(self) -> None:
        """Point the editors at the layer chosen."""
        state = self.app.state
        layer = state.layers[int(self.layer.value) - 1]
        a = state.punch.half_width
        self.thickness_editor.bind(layer.thickness, a)
        self.modulus_editor.bind(layer.modulus, a)
        self.poisson_editor.bind(layer.poisson, a)
        self.app.fidelity.bind_layer(layer)
