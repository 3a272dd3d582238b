"""The Check tab: limits of the design check and the eccentricity of the load."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import panel as pn

from ..model import DesignLimits, ExplorerState, Screen, screen_limits
from .punches import OnePunchOnly
from .style import TAB_COLUMN, html_pane


class CheckView:
    """Inputs of the session's :class:`~explorer.model.design.DesignLimits` and of e = M/P."""

    title = "Check"

    def __init__(self, state: ExplorerState, limits: DesignLimits, screen: Screen) -> None:
        """``limits``: set here; ``screen``: where a refused eccentricity is said."""
        self.state = state
        self.limits = limits
        self.screen = screen
        self.allowable_pressure = self._limit("allowable bearing pressure [kPa]",
                                              "allowable_pressure", "limit-pressure")
        self.settlement_limit = self._limit("settlement limit [mm]", "settlement_limit",
                                            "limit-settlement")
        self.tilt_limit = self._limit("tilt limit [mrad]", "tilt_limit", "limit-tilt")
        self.eccentricity = pn.widgets.FloatInput(
            label="eccentricity e = M/P [m] (sets the moment)", value=None,
            sizing_mode="stretch_width", css_classes=["eccentricity-input"])
        self.eccentricity.param.watch(self._on_eccentricity, "value")

    def show_limits(self, spec: Mapping[str, Any] | None) -> None:
        """Fill the limits from a scene file's ``limits`` (Pa, m, rad), when it has some;
        a scene without limits leaves those typed here."""
        if not spec:
            return
        for name, value in screen_limits(spec).items():
            getattr(self, name).value = value

    def _limit(self, label: str, name: str, css: str) -> pn.widgets.FloatInput:
        box = pn.widgets.FloatInput(label=label, value=None, start=0,
                                    sizing_mode="stretch_width", css_classes=[css])
        box.param.watch(lambda e: setattr(self.limits, name, e.new), "value")
        return box

    def content(self) -> pn.Column:
        """The tab's column."""
        return pn.Column(OnePunchOnly(
            self.state, "The design check and the eccentricity",
            html_pane("<small>Limits of the design check (leave empty: not checked). "
                      "The check covers the whole history. A scene file's limits fill "
                      "them, and a saved scene keeps them.</small>"),
            self.allowable_pressure, self.settlement_limit, self.tilt_limit,
            self.eccentricity).panel, **TAB_COLUMN)

    def _on_eccentricity(self, event: Any) -> None:
        """Set the moment so that M = e P (force and moment given, constant force)."""
        e = event.new
        loading = self.state.loading
        if e is None:
            return
        force = loading.histories["force"]
        if loading.given != ("force", "moment") or force.kind != "constant":
            self.screen.reject("the eccentricity sets the moment when force and moment are "
                               "given and the force is constant.")
            return
        moment = loading.histories["moment"]
        moment.param.update(kind="constant", value=float(e) * force.value)
