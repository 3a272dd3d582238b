"""The Check tab: limits of the design check and the eccentricity of the load."""

from __future__ import annotations

import math
from typing import Any

import panel as pn

from ..model import DesignLimits, ExplorerState, Screen
from .punches import OnePunchOnly
from .style import TAB_COLUMN, html_pane
from .widgets import NumberBox, next_tick


class CheckView:
    """Inputs of the session's :class:`~explorer.model.design.DesignLimits` and of e = M/P."""

    title = "Check"

    def __init__(self, state: ExplorerState, limits: DesignLimits, screen: Screen) -> None:
        """``limits``: set here; ``screen``: where a refused value is said."""
        self.state = state
        self.limits = limits
        self.screen = screen
        # why a limit typed was refused, beside the boxes (the page's notice is above the
        # plots, out of sight from here)
        self.limit_note = html_pane("", css_classes=["limit-refused"], visible=False)
        self.allowable_pressure = self._limit("allowable bearing pressure [kPa]",
                                              "allowable_pressure", "limit-pressure")
        self.settlement_limit = self._limit("settlement limit [mm]", "settlement_limit",
                                            "limit-settlement")
        self.tilt_limit = self._limit("tilt limit [mrad]", "tilt_limit", "limit-tilt")
        self.eccentricity = NumberBox(
            label="eccentricity e = M/P [m] (sets the moment)", value=None,
            sizing_mode="stretch_width", css_classes=["eccentricity-input"])
        self._showing = False  # the box follows the loads: not a value typed
        # the limit a refusal puts back in its box, by name: that change is no value typed
        self._put_back: dict[str, float | None] = {}
        self.eccentricity.param.watch(self._on_eccentricity, "value")
        self.show_eccentricity()

    def _limit(self, label: str, name: str, css: str) -> NumberBox:
        # no lower bound on the box: the page would clamp -5 to 0 unsaid, a limit that
        # every answer fails; a negative value is refused here, saying so
        # (the session's limit: one from the page's link is there before this tab)
        box = NumberBox(label=label, value=getattr(self.limits, name),
                        sizing_mode="stretch_width", css_classes=[css])
        box.param.watch(lambda e: self._on_limit(box, label, name, e), "value")
        # the limits a loaded scene brings (DesignLimits.take), shown
        self.limits.param.watch(lambda e: setattr(box, "value", e.new), name)
        return box

    def _on_limit(self, box: NumberBox, label: str, name: str, event: Any) -> None:
        value = event.new
        if value is not None and value != value:
            value = None  # an emptied box: the page sends NaN; not checked
        if value is not None and (value < 0 or not math.isfinite(value)):
            # (a limit of infinity, "1e400" typed, was taken unsaid: never checked)
            good = getattr(self.limits, name)
            need = "a number >= 0" if math.isfinite(value) else "a finite number >= 0"
            message = (f"{label}: must be {need} (leave it empty: not checked), "
                       f"got {value:g}; the limit stays "
                       + ("unset" if good is None else f"{good:g}"))
            self.screen.reject(message)
            self.limit_note.object = f"<span class='cp-msg'>Not accepted: {message}</span>"
            self.limit_note.visible = True
            # the last good limit, on the page too (next_tick: see there)
            self._put_back[name] = good
            next_tick(lambda: setattr(box, "value", good))
            return
        if name in self._put_back and value == self._put_back.pop(name):
            return  # the last good limit put back: the refusal stays said
        # a value taken (the limit in force typed again, too): the refusal is over
        self.screen.accepted()
        if value is None and getattr(self.limits, name) is not None:
            # an emptied box, or text the box could not read ("abc" came as empty): the
            # limit goes, said, not silently (the verdict turned green unsaid)
            self.limit_note.object = (f"<span class='cp-msg'>{label}: emptied, not checked "
                                      "(type a number to check it again)</span>")
            self.limit_note.visible = True
        else:
            self.limit_note.visible = False
        if value != getattr(self.limits, name):
            setattr(self.limits, name, value)

    def show_eccentricity(self) -> None:
        """Show e = M/P of the loads on screen (empty when force and moment are not both
        given as constants), so that the box never holds a stale value."""
        loading = self.state.loading
        force, moment = (loading.histories.get(name) for name in ("force", "moment"))
        e = None
        if loading.given == ("force", "moment") and force.kind == "constant" \
                and moment.kind == "constant" and force.value:
            e = float(moment.value) / float(force.value)
        if e != self.eccentricity.value:
            self._showing = True
            try:
                self.eccentricity.value = e
            finally:
                self._showing = False

    def content(self) -> pn.Column:
        """The tab's column: the limits (of each punch, for several: their checks were
        the report's alone), then the eccentricity, of a scene of one punch."""
        return pn.Column(
            html_pane("<small>Limits of the design check (leave empty: not checked). "
                      "The check covers the whole history, under each punch where there "
                      "are several. A scene file's limits fill them, and a saved scene "
                      "keeps them.</small>"),
            self.allowable_pressure, self.settlement_limit, self.tilt_limit,
            self.limit_note,
            OnePunchOnly(self.state, "The eccentricity box", self.eccentricity).panel,
            **TAB_COLUMN)

    def _on_eccentricity(self, event: Any) -> None:
        """Set the moment so that M = e P (force and moment given, constant force)."""
        e = event.new
        loading = self.state.loading
        if e is None or self._showing:
            return
        if not math.isfinite(e):
            self.screen.reject(f"eccentricity e = M/P [m]: must be a finite number, got {e}; "
                               "the moment stays as it is.")
            next_tick(self.show_eccentricity)  # the box says what the loads give
            return
        force = loading.histories["force"]
        if loading.given != ("force", "moment") or force.kind != "constant":
            self.screen.reject("the eccentricity sets the moment when force and moment are "
                               "given and the force is constant.")
            self.show_eccentricity()  # the box says what the loads give, not what was typed
            return
        moment = loading.histories["moment"]
        moment.param.update(kind="constant", value=float(e) * force.value)
