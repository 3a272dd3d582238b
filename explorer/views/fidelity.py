"""Widgets of the model-fidelity settings: each layer's interface, the contact model and
the coating-model tolerance.

They edit :class:`~explorer.model.state.LayerState` ``interface`` (``coating[k].interface``) and
:class:`~explorer.model.state.ExplorerState` ``contact`` (``solver.contact``) and
``model_tol_percent`` (``solver.model_tol`` in %), through :class:`~explorer.views.widgets.Binding`
so that a loaded scene shows its values and a change is one scene change.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import panel as pn

from explorer.model import CONTACT_MODELS, INTERFACES, MODEL_TOL_RANGE, ExplorerState, LayerState
from explorer.views.widgets import Binding, NumberBox, PromptRadioButtonGroup, PromptSelect

#: What each contact model means, as the selector shows it.
CONTACT_LABELS: dict[str, str] = {
    "auto": "auto (full contact unless the base lifts off)",
    "full": "full contact (bilateral)",
    "unilateral": "unilateral (the base may lift off)",
}
assert set(CONTACT_LABELS) == set(CONTACT_MODELS)


#: A layer of this Poisson ratio or more gets the prompt to set its interface: bonded and
#: smooth differ most for nearly incompressible layers (0.1485 against 0.0630 mm of 50-year
#: settlement for the pad of tests/support/epoxy_on_pad.py at nu 0.45, 800 kN/m centred).
PROMPT_POISSON = 0.4


class FidelityView:
    """The interface selector of the layer being edited, and the solver's contact model
    and model tolerance; place :attr:`interface` in the coating tab and
    :attr:`solver_panel` beside the accuracy target."""

    def __init__(self, state: ExplorerState,
                 on_reject: Callable[[str], None] | None = None) -> None:
        self.layer_binding = Binding(on_reject)
        self.interface = self.layer_binding.add("interface", PromptRadioButtonGroup(
            label="interface with the layer below", options=list(INTERFACES),
            sizing_mode="stretch_width", css_classes=["layer-interface"]))
        self.solver_binding = Binding(on_reject)
        self.contact = self.solver_binding.add("contact", PromptSelect(
            label="contact model", options={v: k for k, v in CONTACT_LABELS.items()},
            sizing_mode="stretch_width", css_classes=["contact-select"]))
        low, high = (100.0 * v for v in MODEL_TOL_RANGE)
        self.model_tol = self.solver_binding.add("model_tol_percent", NumberBox(
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
        self._poisson_watch: tuple[Any, Any] | None = None

    def bind_layer(self, layer: LayerState) -> None:
        """Show and edit the interface of ``layer`` (the layer being edited)."""
        self.layer_binding.bind(layer)
        if self._poisson_watch is not None:
            self._poisson_watch[0].param.unwatch(self._poisson_watch[1])
        profile = layer.poisson
        self._poisson_watch = (profile, profile.param.watch(
            lambda *e: self._say_interface(profile.mean), ["mean"]))
        self._say_interface(profile.mean)

    def _say_interface(self, poisson: float) -> None:
        """The interface's note, a prompt where the choice matters most: a layer of Poisson
        ratio near 0.5 is stiff when bonded (confined) and soft when smooth."""
        text = ("Interface of this layer with the one below: smooth (free to slide) or "
                "bonded.")
        if poisson >= PROMPT_POISSON:
            text += (" <b>It matters here:</b> a layer of Poisson ratio near 0.5 is "
                     "confined when bonded and squeezes out when smooth (a 20 mm pad of 50 "
                     "MPa and ν 0.45 under 5 mm of epoxy on C30/37 at 800 kN/m settles 0.15 "
                     "mm in 50 years smooth, 0.063 mm bonded): set what its installation "
                     "gives.")
        self.interface_label.object = f"<small>{text}</small>"
