"""Widgets of the model-fidelity settings: each layer's interface, the contact model and
the coating-model tolerance.

They edit :class:`~explorer.model.state.LayerState` ``interface`` (``coating[k].interface``) and
:class:`~explorer.model.state.ExplorerState` ``contact`` (``solver.contact``) and
``model_tol_percent`` (``solver.model_tol`` in %), through :class:`~explorer.views.widgets.Binding`
so that a loaded scene shows its values and a change is one scene change.
"""

from __future__ import annotations

from collections.abc import Callable

import panel as pn

from explorer.model import CONTACT_MODELS, INTERFACES, MODEL_TOL_RANGE, ExplorerState, LayerState
from explorer.views.widgets import Binding

#: What each contact model means, as the selector shows it.
CONTACT_LABELS: dict[str, str] = {
    "auto": "auto (full contact unless the base lifts off)",
    "full": "full contact (bilateral)",
    "unilateral": "unilateral (the base may lift off)",
}
assert set(CONTACT_LABELS) == set(CONTACT_MODELS)


class FidelityView:
    """The interface selector of the layer being edited, and the solver's contact model
    and model tolerance; place :attr:`interface` in the coating tab and
    :attr:`solver_panel` beside the accuracy target."""

    def __init__(self, state: ExplorerState,
                 on_reject: Callable[[str], None] | None = None) -> None:
        self.layer_binding = Binding(on_reject)
        self.interface = self.layer_binding.add("interface", pn.widgets.RadioButtonGroup(
            label="interface with the layer below", options=list(INTERFACES),
            sizing_mode="stretch_width", css_classes=["layer-interface"]))
        self.solver_binding = Binding(on_reject)
        self.contact = self.solver_binding.add("contact", pn.widgets.Select(
            label="contact model", options={v: k for k, v in CONTACT_LABELS.items()},
            sizing_mode="stretch_width", css_classes=["contact-select"]))
        low, high = (100.0 * v for v in MODEL_TOL_RANGE)
        self.model_tol = self.solver_binding.add("model_tol_percent", pn.widgets.FloatInput(
            label="coating-model tolerance [%]", start=low, end=high, step=0.5,
            sizing_mode="stretch_width", css_classes=["model-tol-input"]), live=True)
        self.solver_binding.bind(state)
        self.interface_label = pn.pane.HTML(
            "<small>Interface of this layer with the one below: smooth (free to slide) "
            "or bonded.</small>", sizing_mode="stretch_width", margin=(0, 5))
        self.solver_panel = pn.Column(self.contact, self.model_tol, margin=0,
                                      sizing_mode="stretch_width")
        self.interface_panel = pn.Column(self.interface_label, self.interface, margin=0,
                                         sizing_mode="stretch_width")

    def bind_layer(self, layer: LayerState) -> None:
        """Show and edit the interface of ``layer`` (the layer being edited)."""
        self.layer_binding.bind(layer)
