"""Design-code creep of the base (fib MC2010, Eurocode 2) in engineering units.

``CodeCreepState`` holds the inputs as an engineer reads them off a drawing (strength
class or mean strength in MPa, cement class, relative humidity in %, notional size in mm,
temperature in deg C) and turns them into the creep spec of SCENES.md; core validates
them and every refusal names the field. ``creep_coefficient_data`` and
``creep_coefficient_figure`` draw phi(t, t0) against the load duration on a log axis, to
be compared with the codes' tables and figures (EN 1992-1-1 Figure 3.1, MC2010 5.1.9.4).

``CodeCreepPanel`` shows the inputs and the plot in the base settings while a code model
is chosen.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import panel as pn
import param
from bokeh.models import ColumnDataSource, HoverTool
from bokeh.plotting import figure

import core

#: The design-code creep models offered by name: spec model name -> label on screen.
CODE_CREEP_MODELS: dict[str, str] = {
    "fib_mc2010": "fib Model Code 2010",
    "eurocode2": "Eurocode 2 (EN 1992-1-1, Annex B)",
}
#: Strength classes offered (EN 1992-1-1 Table 3.1); fcm = fck + 8 MPa in core.
STRENGTH_CLASSES: tuple[str, ...] = (
    "C20/25", "C25/30", "C30/37", "C35/45", "C40/50", "C45/55", "C50/60", "C55/67",
    "C60/75", "C70/85", "C80/95", "C90/105")
#: Load durations of the plot [day]: 0.1 day to 100 years, log spaced.
PLOT_DURATIONS: np.ndarray = np.geomspace(0.1, 36525.0, 161)


class CodeCreepState(param.Parameterized):
    """Inputs of a design-code creep model, in the codes' units."""

    code_model = param.Selector(default="fib_mc2010", objects=list(CODE_CREEP_MODELS),
                                doc="Design code whose creep and aging law is used.")
    strength_class = param.Selector(default="C30/37", objects=[*STRENGTH_CLASSES, "fcm"],
                                    doc="Strength class, or 'fcm' to give the mean "
                                        "cylinder strength directly.")
    fcm = param.Number(default=38.0, softbounds=(20.0, 130.0),
                       doc="Mean cylinder strength f_cm [MPa] (used when the class is 'fcm').")
    cement = param.Selector(default="N", objects=["S", "N", "R"],
                            doc="Cement class: S slow, N normal, R rapid hardening.")
    relative_humidity = param.Number(default=60.0, softbounds=(40.0, 100.0),
                                     doc="Relative humidity of the ambient air RH [%].")
    notional_size = param.Number(default=300.0, softbounds=(50.0, 1500.0),
                                 doc="Notional size h = 2 A_c / u [mm].")
    temperature = param.Number(default=20.0, softbounds=(5.0, 30.0),
                               doc="Mean temperature T [deg C].")

    def spec(self, model: str | None = None) -> dict[str, Any]:
        """The creep spec (SCENES.md, code units), checked by core; ``model`` replaces
        ``code_model`` (the base's creep selector names the code).

        Raises ValueError naming ``base.creep.<field>`` for an input the code does not
        cover.
        """
        out: dict[str, Any] = {"model": model or self.code_model}
        if self.strength_class == "fcm":
            out["fcm"] = self.fcm
        else:
            out["strength_class"] = self.strength_class
        out.update(cement=self.cement, relative_humidity=self.relative_humidity,
                   notional_size=self.notional_size, temperature=self.temperature)
        # one evaluation validates every field with core's own ranges and messages
        core.creep_coefficient_curve(out, 28.0, [0.0], field="base.creep")
        return out

    def load(self, spec: dict[str, Any]) -> None:
        """Show a code creep spec (as in a scene file) on the inputs."""
        if spec.get("model") not in CODE_CREEP_MODELS:
            raise ValueError("base.creep.model: must be one of " + ", ".join(CODE_CREEP_MODELS))
        values: dict[str, Any] = {"code_model": spec["model"],
                                  "cement": spec.get("cement", "N"),
                                  "relative_humidity": spec["relative_humidity"],
                                  "notional_size": spec["notional_size"],
                                  "temperature": spec.get("temperature", 20.0)}
        cls = spec.get("strength_class")
        if isinstance(cls, str) and cls.replace(" ", "") in STRENGTH_CLASSES:
            values["strength_class"] = cls.replace(" ", "")
        elif "fcm" in spec:
            values.update(strength_class="fcm", fcm=spec["fcm"])
        else:
            raise ValueError(f"base.creep.strength_class: {cls!r} is not one of "
                             + ", ".join(STRENGTH_CLASSES))
        self.param.update(**values)


def creep_coefficient_data(spec: dict[str, Any], age_at_loading: float,
                           durations: np.ndarray = PLOT_DURATIONS) -> dict[str, list]:
    """Columns of the creep-coefficient plot: ``duration`` [day], ``phi`` [-].

    ``phi`` is phi(t0 + duration, t0) of the code model ``spec`` for the age at loading
    t0 [day]; ValueErrors name the field.
    """
    phi = core.creep_coefficient_curve(spec, age_at_loading, durations, field="base.creep")
    return {"duration": [float(d) for d in durations], "phi": [float(p) for p in phi]}


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
    fig.title.text = f"Creep coefficient φ(t, t₀), {code}, t₀ = {age_at_loading:g} days"
    return ""


class CodeCreepPanel:
    """Widgets of the code inputs and the phi(t, t0) plot, for the base settings.

    ``base`` is the explorer's base state: its ``code`` holds the inputs, its
    ``age_at_loading`` [day] is t0 of the plot.
    """

    def __init__(self, base: Any, binding: Any) -> None:
        self._base = base
        b = binding
        self.strength_class = b.add("strength_class", pn.widgets.Select(
            label="strength class (or f_cm)", options=list(STRENGTH_CLASSES) + ["fcm"],
            sizing_mode="stretch_width", css_classes=["code-strength"]))
        self.fcm = b.add("fcm", pn.widgets.FloatInput(
            label="mean strength f_cm [MPa]", step=1.0, sizing_mode="stretch_width"))
        self.cement = b.add("cement", pn.widgets.Select(
            label="cement class", options={"S (slow)": "S", "N (normal)": "N", "R (rapid)": "R"},
            sizing_mode="stretch_width"))
        self.relative_humidity = b.add("relative_humidity", pn.widgets.FloatInput(
            label="relative humidity RH [%]", step=5.0, sizing_mode="stretch_width",
            css_classes=["code-rh"]))
        self.notional_size = b.add("notional_size", pn.widgets.FloatInput(
            label="notional size h = 2A/u [mm]", step=10.0, sizing_mode="stretch_width"))
        self.temperature = b.add("temperature", pn.widgets.FloatInput(
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
