"""Design-code creep of the base (fib MC2010, Eurocode 2) on the page.

The inputs (``CodeCreepState``) and the plot's columns (``creep_coefficient_data``) live
in :mod:`explorer.model.code_creep_state`, free of Panel.
``creep_coefficient_figure`` draws phi(t, t0) against the load duration on a log axis, to
be compared with the codes' tables and figures (EN 1992-1-1 Figure 3.1, MC2010 5.1.9.4).

``CodeCreepPanel`` shows the inputs and the plot in the base settings while a code model
is chosen.
"""

from __future__ import annotations

from typing import Any

import panel as pn
from bokeh.models import ColumnDataSource, HoverTool
from bokeh.plotting import figure

from core.scene import days_text

from ..model import (
    CODE_CREEP_MODELS,
    STRENGTH_CLASSES,
    CodeCreepState,
    creep_coefficient_data,
)
from .widgets import NumberBox, PromptSelect

__all__ = ["CodeCreepPanel", "creep_coefficient_figure", "update_creep_figure"]


def creep_coefficient_figure() -> tuple[Any, ColumnDataSource]:
    """An empty bokeh figure of phi(t, t0) against the load duration (log axis)."""
    source = ColumnDataSource({"duration": [], "phi": []}, name="creep_phi_source")
    fig = figure(height=240, sizing_mode="stretch_width", x_axis_type="log",
                 title="Creep coefficient φ(t, t₀)", tools="pan,wheel_zoom,reset,save",
                 name="creep_phi_figure")
    fig.line("duration", "phi", source=source, line_width=2)
    fig.xaxis.axis_label = "load duration t − t₀ [day]"
    fig.yaxis.axis_label = "φ(t, t₀) [−]"
    fig.add_tools(HoverTool(tooltips=[("t − t₀", "@duration{0.0} day"), ("φ", "@phi{0.000}")]))
    return fig, source


def update_creep_figure(fig: Any, source: ColumnDataSource, state: CodeCreepState,
                        age_at_loading: float, model: str | None = None) -> str:
    """Redraw the curve for ``state`` (``model`` replaces its ``code_model``); returns an
    error text ('' when drawn).

    A refused input empties the curve, so no stale curve stands beside the message.
    """
    try:
        data = creep_coefficient_data(state.spec(model), age_at_loading)
    except ValueError as exc:
        source.data = {"duration": [], "phi": []}
        return str(exc)
    source.data = data
    code = CODE_CREEP_MODELS[model or state.code_model]
    # three lines: one ran past the 1024 px page's sidebar ("..., fib Model Code 2010, " and
    # the age at loading cut off), and two cut Eurocode 2's ("... Annex B), t₀ = 28 day")
    fig.title.text = (f"Creep coefficient φ(t, t₀)\n{code}\n"
                      f"loaded at t₀ = {days_text(age_at_loading)}")
    return ""


class CodeCreepPanel:
    """Widgets of the code inputs and the phi(t, t0) plot, for the base settings.

    ``base`` is the explorer's base state: its ``code`` holds the inputs, its
    ``age_at_loading`` [day] is t0 of the plot.
    """

    def __init__(self, base: Any, binding: Any) -> None:
        self._base = base
        b = binding
        self.strength_class = b.add("strength_class", PromptSelect(
            label="strength class (or f_cm)", options=list(STRENGTH_CLASSES) + ["fcm"],
            sizing_mode="stretch_width", css_classes=["code-strength"]))
        self.fcm = b.add("fcm", NumberBox(
            label="mean strength f_cm [MPa]", step=1.0, sizing_mode="stretch_width"))
        self.cement = b.add("cement", PromptSelect(
            label="cement class", options={"S (slow)": "S", "N (normal)": "N", "R (rapid)": "R"},
            sizing_mode="stretch_width"))
        self.relative_humidity = b.add("relative_humidity", NumberBox(
            label="relative humidity RH [%]", step=5.0, sizing_mode="stretch_width",
            css_classes=["code-rh"]))
        self.notional_size = b.add("notional_size", NumberBox(
            label="notional size h = 2A/u [mm]", step=10.0, sizing_mode="stretch_width"))
        self.temperature = b.add("temperature", NumberBox(
            label="temperature T [°C]", step=1.0, sizing_mode="stretch_width"))
        b.bind(base.code)
        self.figure, self.source = creep_coefficient_figure()
        self.note = pn.pane.HTML("", styles={"color": "#b00020", "font-size": "12px"},
                                 css_classes=["code-creep-error"])
        self.panel = pn.Column(
            self.strength_class, self.fcm, self.cement, self.relative_humidity,
            self.notional_size, self.temperature, self.note,
            pn.pane.Bokeh(self.figure, sizing_mode="stretch_width"),
            sizing_mode="stretch_width", css_classes=["code-creep"])
        base.code.param.watch(lambda *e: self.refresh(), [n for n in base.code.param
                                                         if n != "name"])
        base.param.watch(lambda *e: self.refresh(), ["creep_model", "age_at_loading"])
        self.refresh()

    def refresh(self) -> None:
        """Show the panel for a code model only, and redraw its plot."""
        model = self._base.creep_model
        self.panel.visible = model in CODE_CREEP_MODELS
        self.fcm.visible = self._base.code.strength_class == "fcm"
        if not self.panel.visible:
            return
        message = update_creep_figure(self.figure, self.source, self._base.code,
                                      self._base.age_at_loading, model)
        self.note.object = message
        self.note.visible = bool(message)
