"""Design-code creep inputs (fib MC2010, Eurocode 2) in engineering units, without Panel.

``CodeCreepState`` holds the inputs as an engineer reads them off a drawing (strength
class or mean strength in MPa, cement class, relative humidity in %, notional size in mm,
temperature in deg C) and turns them into the creep spec of SCENES.md; core validates
them and every refusal names the field. ``creep_coefficient_data`` gives the columns of
the phi(t, t0) plot.

Nothing here imports Panel or Bokeh: :mod:`explorer.model.state` needs these inputs, and the
solver workers import the state's names without the page's libraries
(:mod:`explorer.views.creep` draws them on the page).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import param

import core
from core.creep import CUBE_STRENGTHS, RANGES

#: The design-code creep models offered by name: spec model name -> label on screen.
CODE_CREEP_MODELS: dict[str, str] = {
    "fib_mc2010": "fib Model Code 2010",
    "eurocode2": "Eurocode 2 (EN 1992-1-1, Annex B)",
}
#: Strength classes offered: the tables' (EN 1992-1-1 Table 3.1, fib MC2010 to C120/140),
#: as core reads them (fcm = fck + 8 MPa); a class a code does not cover is refused by core
#: naming its range. Its own list here refused a scene's C12/15 that core accepts.
STRENGTH_CLASSES: tuple[str, ...] = tuple(f"C{fck}/{cube}" for fck, cube in CUBE_STRENGTHS.items())
#: Load durations of the plot [day]: 0.1 day to 100 years, log spaced.
PLOT_DURATIONS: np.ndarray = np.geomspace(0.1, 36525.0, 161)


def _code_input(name: str, default: float, doc: str) -> param.Number:
    # the slider's soft range is the range core accepts for the default code (fib MC2010)
    low, high, _source = RANGES["fib_mc2010"][name]
    return param.Number(default=default, softbounds=(low, high), doc=doc)


class CodeCreepState(param.Parameterized):
    """Inputs of a design-code creep model, in the codes' units."""

    code_model = param.Selector(default="fib_mc2010", objects=list(CODE_CREEP_MODELS),
                                doc="Design code whose creep and aging law is used.")
    strength_class = param.Selector(default="C30/37", objects=[*STRENGTH_CLASSES, "fcm"],
                                    doc="Strength class, or 'fcm' to give the mean "
                                        "cylinder strength directly.")
    fcm = _code_input("fcm", 38.0, "Mean cylinder strength f_cm [MPa] (used when the class "
                      "is 'fcm').")
    cement = param.Selector(default="N", objects=["S", "N", "R"],
                            doc="Cement class: S slow, N normal, R rapid hardening.")
    relative_humidity = _code_input("relative_humidity", 60.0,
                                    "Relative humidity of the ambient air RH [%].")
    notional_size = _code_input("notional_size", 300.0, "Notional size h = 2 A_c / u [mm].")
    temperature = _code_input("temperature", 20.0, "Mean temperature T [deg C].")

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
        # as core reads a class: spaces and the letter's case do not matter ("c30/37")
        shown = cls.replace(" ", "").upper() if isinstance(cls, str) else None
        if shown in STRENGTH_CLASSES:
            values["strength_class"] = shown
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
