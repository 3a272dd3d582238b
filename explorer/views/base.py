"""The Base tab: the aging viscoelastic layer under the coating and its creep model."""

from __future__ import annotations

import html
from collections.abc import Callable

import panel as pn

from ..model import CODE_CREEP_MODELS, CREEP_MODELS, ExplorerState
from .creep import CodeCreepPanel
from .style import NOTE_STYLE, TAB_COLUMN, html_pane
from .widgets import Binding, PromptSelect, slider


class BaseView:
    """Widgets of ``state.base``: thickness H, Poisson ratio, modulus and creep C(t, τ)."""

    title = "Base"

    def __init__(self, state: ExplorerState, reject: Callable[[str], None],
                 live_when: Callable[[], bool]) -> None:
        """``reject``: says why a value was refused; ``live_when``: whether a slider applies
        each drag step (else its release)."""
        self.state = s = state
        self.base = Binding(reject, live_when=live_when)
        bb = self.base
        self.base_thickness = bb.add("thickness", slider("thickness H [m]", 0.1, 20.0, 0.05,
                                                         css_classes=["base-thickness"]))
        self.base_poisson = bb.add("poisson", slider("Poisson ratio [-]", 0.0, 0.49, 0.01))
        self.base_modulus = bb.add("modulus", slider("Young's modulus E [GPa]", 0.1, 60.0, 0.1))
        self.creep_model = bb.add("creep_model", PromptSelect(
            label="creep model", options={v: k for k, v in CREEP_MODELS.items()},
            sizing_mode="stretch_width", css_classes=["creep-select"]))
        self.compliance = bb.add("compliance", slider("final creep compliance C∞ [1/GPa]",
                                                           0.0, 0.1, 0.0005))
        self.rate = bb.add("rate", slider("creep rate γ [1/day]", 0.001, 1.0, 0.001))
        self.beta = bb.add("beta", slider("modulus aging β [-]", 0.0, 0.95, 0.01))
        self.alpha = bb.add("alpha", slider("modulus aging rate α [1/day]", 0.001, 1.0,
                                                 0.001))
        self.aging = bb.add("aging", slider("aging creep A [day/GPa]", 0.0, 5.0, 0.01))
        self.age = bb.add("age_at_loading", slider("age at loading τ₀ [days]", 1.0, 3650.0,
                                                   1.0))
        self.creep_note = html_pane("", styles=NOTE_STYLE)
        bb.bind(s.base)
        s.base.param.watch(lambda *e: self.refresh(), ["creep_model", "custom"])
        s.param.watch(lambda *e: self.refresh(), ["tol_note"])
        # design-code creep (fib MC2010, Eurocode 2): inputs and phi(t, t0) plot
        self.code_creep = CodeCreepPanel(s.base, Binding(reject))
        self.refresh()

    def content(self) -> pn.Column:
        """The tab's column."""
        return pn.Column(
            self.base_thickness, self.base_poisson, self.creep_model, self.base_modulus,
            self.compliance, self.rate, self.beta, self.alpha, self.aging, self.age,
            self.creep_note, self.code_creep.panel, **TAB_COLUMN)

    def refresh(self) -> None:
        """Show the parameters of the chosen creep model only."""
        base = self.state.base
        model = base.creep_model
        creeps = model in ("exponential", "arutyunyan")
        self.compliance.visible = self.rate.visible = creeps
        self.beta.visible = self.alpha.visible = self.aging.visible = model == "arutyunyan"
        self.base_modulus.label = ("final Young's modulus E∞ [GPa]" if model == "arutyunyan"
                                   else "Young's modulus E [GPa]")
        self.base_modulus.visible = model not in ("custom", *CODE_CREEP_MODELS)
        # "the scene's own model" is offered only while the scene holds one: picked
        # without it, the base was silently solved as elastic
        offered = {v: k for k, v in CREEP_MODELS.items()
                   if k != "custom" or base.custom is not None}
        if offered != self.creep_model.options:
            self.creep_model.options = offered
        if model == "custom":
            kind = base.custom.get("model") if isinstance(base.custom, dict) else None
            named = f" ('{kind}')" if isinstance(kind, str) else ""
            note = (f"The scene's own creep model{named}, kept as the scene gives it; "
                    "choose another model to replace it.")
        else:
            note = self.state.tol_note  # a design code's law raised the accuracy target
        self.creep_note.object = html.escape(note)
        self.creep_note.visible = bool(note)
