"""The Fit tab: back-analysis of the scene on screen from measured readings.

The user uploads a readings file (settlements and/or tilts over time, ``core/SCENES.md``,
"Readings files"); the readings are drawn on the settlement and tilt histories. Fit fits
up to three fields of the scene (the Study tab's fields) with ``core.calibrate`` off the
page's event loop (:class:`explorer.solving.FitRun`); the tab then shows the fitted values
with their standard errors, chi^2/dof, the correlations and the warnings, and the
histories the forecast of the fitted scene with its band. "Apply fitted values" shows the
fitted scene.
"""

from __future__ import annotations

import html
from collections.abc import Callable
from typing import Any

import numpy as np
import panel as pn

from core.back_analysis import BAND_LEVEL, Readings
from core.limits import MAX_READINGS_BYTES

from ..model import (
    MAX_FIT_FIELDS,
    ExplorerState,
    FitOutcome,
    Screen,
    fit_choices,
    forecast_columns,
    read_upload,
    readings_columns,
    readings_note,
)
from ..plots import Figures
from ..solving import FitRun, SolveController
from .loop import PageLoop
from .punches import OnePunchOnly
from .style import NOTE_STYLE, TAB_COLUMN, html_pane
from .upload import BoundedUpload
from .widgets import PromptSelect

#: The choice of "no field" for the second and third field.
NONE = "(none)"
#: The status of a fit once the scene on screen is another.
STALE_FIT = ("The fit below was made for the scene as it was before the last change: its "
             "forecast is hidden and Apply is off (it would set that scene back). Fit "
             "again to fit this scene.")
def earlier_readings_note(earlier: str, now: str) -> str:
    """The status of a fit made from the readings ``earlier`` once ``now`` are shown."""
    return (f"The fit below was made from the earlier readings, {earlier}; its forecast is "
            f"drawn beside the readings now shown, {now}. Press Fit to fit these.")


#: Under the table of a fit whose fields the readings do not all determine.
NOT_APPLIED = ("Apply is off: the readings do not determine every field fitted (see the "
               "warnings), so the fitted values are arbitrary along a combination of them; "
               "fit fewer fields, or add readings that separate them.")


class FitView:
    """Upload, fields, Fit button and the fitted values of the session's back-analysis."""

    title = "Fit"

    def __init__(self, state: ExplorerState, controller: SolveController, loop: PageLoop,
                 figures: Figures, load_scene: Callable[[dict[str, Any]], bool],
                 screen: Screen | None = None,
                 on_settings: Callable[[], None] | None = None) -> None:
        """``state``: the scene fitted; ``controller``: the fields offered follow its
        results; ``loop``: where the fit's answer is shown; ``figures``: the histories the
        readings and the forecast are drawn on; ``load_scene``: shows the fitted scene;
        ``screen``: receives each fit (the report carries it while its fitted scene is on
        screen); ``on_settings``: called when the readings or the fields change (the
        page's link keeps them)."""
        self.state = state
        self.screen = screen
        self.figures = figures
        self.load_scene = load_scene
        self.readings: Readings | None = None
        self.fit_run = FitRun(dispatch=loop.dispatch)
        self.background = loop.served
        stretch = {"sizing_mode": "stretch_width"}
        self.upload = BoundedUpload([".csv", ".json", ".txt"], MAX_READINGS_BYTES)
        self.upload.param.watch(self._on_upload, "value")
        self.readings_status = html_pane("<small><i>No readings yet.</i></small>",
                                         css_classes=["fit-readings"], **stretch)
        self.fields = [PromptSelect(label=f"field {k + 1} to fit",
                                    css_classes=[f"fit-field-{k + 1}"], **stretch)
                       for k in range(MAX_FIT_FIELDS)]
        self.fit_button = pn.widgets.Button(label="Fit", color="primary", disabled=True,
                                            css_classes=["fit-run"], **stretch)
        self.fit_button.on_click(lambda e: self.start())
        self.fit_status = html_pane("", css_classes=["fit-status"], **stretch)
        self.fit_table = html_pane("", css_classes=["fit-table"], **stretch)
        self.apply_button = pn.widgets.Button(label="Apply fitted values", disabled=True,
                                              css_classes=["fit-apply"], **stretch)
        self.apply_button.on_click(lambda e: self.apply())
        self.fit_run.param.watch(self._on_run, ["status", "message"])
        self.fit_run.param.watch(self._on_outcome, "outcome")
        self._choices: dict[str, Any] = {}
        # whether the fit shown is of the scene on screen (None: no fit shown), and its
        # status
        self._current: bool | None = None
        self._done = ""
        # fields a link asked for that the scene on screen does not offer yet
        self._wanted: list[str | None] | None = None
        self.on_settings = on_settings or (lambda: None)
        for select in self.fields:
            select.param.watch(lambda e: self.on_settings(), "value")
        controller.param.watch(lambda e: self.refresh(getattr(e.new, "scene", None)), "view")
        self.refresh(getattr(controller.view, "scene", None))  # (as study.py)

    def content(self) -> pn.Column:
        """The tab's column."""
        return pn.Column(OnePunchOnly(
            self.state, "The back-analysis",
            html_pane("<small>Back-analysis: fit fields of the scene on screen to measured "
                      "settlements and tilts. Upload a readings file (CSV or JSON): "
                      "<code>time [day], settlement [mm], settlement_std, tilt [urad], "
                      "tilt_std</code>, times in days after loading, a unit in brackets "
                      "per column, an empty cell for no reading.</small>"),
            pn.Column(self.upload, css_classes=["fit-upload"], sizing_mode="stretch_width",
                      margin=0),
            self.readings_status, *self.fields, self.fit_button,
            self.fit_status, self.fit_table, self.apply_button,
            html_pane(f"<small>On the histories: the readings (black, with their "
                      f"standard deviations) and the fitted scene's forecast (cyan, "
                      f"dot-dashed) with its {100 * BAND_LEVEL:.0f} % band, from the "
                      f"fields' uncertainty only, "
                      "not the model's error. Every step of a fit is a full solve at the "
                      "readings' times. Once the fitted values are applied, the printable "
                      "report (Files tab) carries the fit. The page's link keeps the "
                      "readings and the fields.</small>", styles=NOTE_STYLE)).panel,
            **TAB_COLUMN)

    # -- choices ---------------------------------------------------------------------------
    def refresh(self, scene: dict[str, Any] | None = None) -> None:
        """Offer the fields of ``scene`` (default: the state's), keeping those chosen."""
        if scene is None:
            try:
                scene = self.state.to_scene()
            except ValueError:
                return
        self._follow(scene)
        choices = {c.key: c for c in fit_choices(scene)}
        if list(choices) == list(self._choices):
            self._choices = choices
            return
        self._choices = choices
        options = {c.title: c.key for c in choices.values()}
        for k, select in enumerate(self.fields):
            keep = select.value
            select.options = (options if k == 0 else {NONE: NONE} | options)
            if keep in select.options.values():
                select.value = keep
            else:
                select.value = next(iter(choices), None) if k == 0 else NONE
        if self._wanted is not None:
            self._choose(self._wanted)

    def _follow(self, scene: dict[str, Any]) -> None:
        """Mark the last fit as of another scene once the scene on screen changes (its
        table and forecast looked current, and Apply set the earlier scene back: a force
        typed after the fit returned to the fitted one), and as current again when the
        scene is the fitted one or its fitted scene."""
        outcome = self.fit_run.outcome
        if outcome is None or self._current is None or self.fit_run.running:
            return
        self._show_current(outcome, outcome.made_for(scene))

    def _show_current(self, outcome: FitOutcome, current: bool) -> None:
        """Apply, the forecast and the status of the fit shown, of the scene on screen
        (``current``) or of another."""
        if current == self._current:
            return
        self._current = current
        self.apply_button.disabled = not (current and outcome.determined)
        self.figures.show_forecast(forecast_columns(outcome.forecast if current else None))
        self._say(self._done if current else STALE_FIT, bad=not current)

    def _choose(self, fields: list[str | None]) -> None:
        """Choose ``fields`` (None: no field) when the scene offers them all, else keep
        them for when it does."""
        offered = set(self._choices)
        if not all(f is None or f in offered for f in fields):
            self._wanted = list(fields)
            return
        self._wanted = None
        for k, select in enumerate(self.fields):
            field = fields[k] if k < len(fields) else None
            if field is None and k == 0:
                continue  # the first field is always one
            select.value = NONE if field is None else field

    # -- the link --------------------------------------------------------------------------
    def fit_settings(self) -> dict[str, Any] | None:
        """The readings and the fields chosen, as a link keeps them
        (:func:`explorer.model.view_link.fit_settings`), or None without readings."""
        if self.readings is None:
            return None
        return {"fields": self.chosen(), "readings": self.readings.to_dict(),
                "source": self.readings.source}

    def apply_fit_settings(self, settings: dict[str, Any]) -> None:
        """Show the readings of a link and choose its fields (checked by
        :func:`explorer.model.view_link.fit_settings`); the fit is not run."""
        self.show_readings(settings["readings"])
        self._choose(settings["fields"])

    def chosen(self) -> list[str | None]:
        """The fields chosen (None: no field)."""
        return [None if s.value in (None, NONE) else s.value for s in self.fields]

    # -- readings --------------------------------------------------------------------------
    def _on_upload(self, event: Any) -> None:
        data = event.new
        if data is None:
            return
        name = self.upload.filename or "readings"
        try:
            readings = read_upload(data, name)
        except ValueError as exc:
            self.upload.clear()
            # the readings in use stay (nothing is lost), and the page says which they
            # are: after a refused file, Fit ran on the previous one without a word
            kept = "" if self.readings is None else (
                f" The Fit button still uses the previous readings, {self.readings.source}: "
                f"{readings_note(self.readings)}.")
            self._readings_text(f"The readings were not used: {exc}.{kept}", bad=True)
            return
        self.show_readings(readings)

    def show_readings(self, readings: Readings) -> None:
        """Use ``readings``. The last fit stays on screen, said to be of the readings
        before (its forecast beside the new readings checks it); Fit fits these. (New
        readings cleared the fit's table and band and left "Done: fitted ..." over
        nothing.)"""
        earlier, self.readings = self.readings, readings
        self.figures.show_readings(readings_columns(readings))
        self._readings_text(f"{readings.source}: {readings_note(readings)}.")
        self.fit_button.disabled = self.fit_run.running
        if self.fit_run.outcome is not None and earlier is not None and self.fit_table.object:
            self._done = earlier_readings_note(earlier.source, readings.source)
            if self._current:
                self._say(self._done)
        self.on_settings()

    def _readings_text(self, text: str, bad: bool = False) -> None:
        color = "#9b1c1c" if bad else "#333"
        self.readings_status.object = (f"<div class='fit-readings-message' style='font-size:"
                                       f"13px;color:{color}'>{html.escape(text)}</div>")

    # -- fitting ---------------------------------------------------------------------------
    def start(self) -> bool:
        """Fit the fields chosen of the scene on screen to the readings; False (and the
        reason on the page) when it cannot start."""
        if self.fit_run.running:
            return False
        if self.readings is None:
            self._say("Not fitted: upload a readings file first.", bad=True)
            return False
        try:
            scene = self.state.to_scene()
        except ValueError as exc:
            self._say(f"Not fitted: {exc}", bad=True)
            return False
        self.fit_button.disabled = True
        # the last fit's values leave the page with its Apply (a failed fit left them on,
        # applicable, beside its failure)
        self._current = None
        self.fit_table.object = ""
        self.apply_button.disabled = True
        self.figures.show_forecast(forecast_columns(None))
        self.fit_run.start(scene, self.readings, self.chosen(), background=self.background)
        return True

    def _say(self, text: str, bad: bool = False) -> None:
        color = "#9b1c1c" if bad else "#333"
        self.fit_status.object = (f"<div class='fit-message' style='font-size:13px;"
                                  f"color:{color}'>{html.escape(text)}</div>")

    def _on_run(self, *events: Any) -> None:
        run = self.fit_run
        self.fit_button.disabled = run.status == "running" or self.readings is None
        if run.status == "running":
            self._say("Fitting: every step is a full solve (seconds)...")
        elif run.status == "failed":
            self._say(f"Not fitted: {run.message}", bad=True)
        elif run.status == "done":
            self._done = f"Done: {run.message}."
            if self._current is not False:  # (a fit of another scene says so instead)
                self._say(self._done)

    def _on_outcome(self, event: Any) -> None:
        outcome = event.new
        if outcome is None:
            return
        self.fit_table.object = outcome_html(outcome)
        if self.screen is not None:
            self.screen.fit = outcome
        # the scene may have changed while the fit ran (seconds): shown current only
        # when it is of the scene on screen
        try:
            current = outcome.made_for(self.state.to_scene())
        except ValueError:
            current = False
        self._current = None
        self._show_current(outcome, current)
        self.fit_button.disabled = self.readings is None

    def apply(self) -> bool:
        """Show the last fit's fitted scene; False when there is none or it is refused."""
        outcome = self.fit_run.outcome
        if outcome is None:
            return False
        return self.load_scene(outcome.fitted_scene())


def outcome_html(outcome: FitOutcome) -> str:
    """The fitted values ± standard errors, chi^2/dof, the correlations and the warnings
    of a fit, as the tab's HTML (user text escaped)."""
    c = outcome.calibration
    rows = "".join(
        f"<tr class='fit-row'><td>{html.escape(label)}</td><td>{html.escape(value)} ± "
        f"{html.escape(se)} {html.escape(unit)}</td><td>{html.escape(interval)}</td></tr>"
        for (label, value, se, unit), interval in zip(outcome.rows(), outcome.intervals(),
                                                      strict=True))
    noise = ("the readings' standard deviations" if c.std_given
             else f"the noise estimated from the scatter about the fit, "
             f"{outcome.noise_text()} (the interval by Student's t, {c.dof} degrees of "
             "freedom)")
    parts = [f"<table class='fit-values' style='font-size:13px'>"
             f"<tr><th>field</th><th>fitted value ± standard error</th>"
             f"<th>{100 * BAND_LEVEL:g} % interval</th></tr>{rows}</table>",
             f"<div style='font-size:12px'>{c.readings.count} readings, "
             + (f"χ²/dof = {c.chi2_text}; " if c.std_given else "")
             + f"standard errors from {noise}.</div>"]
    pairs = outcome.correlations()
    if pairs:
        parts.append("<div style='font-size:12px'>correlations: " + "; ".join(
            f"{html.escape(a)} ~ {html.escape(b)}: "
            f"{'n/a' if not np.isfinite(r) else f'{r:+.3f}'}" for a, b, r in pairs)
            + "</div>")
    # the fields as the table names them (the warnings said "coating[0].thickness"
    # beside "coating 1: thickness")
    names = sorted(((choice.key, choice.label) for choice in outcome.choices),
                   key=lambda pair: -len(pair[0]))
    for warning in c.warnings:
        for key, label in names:
            warning = warning.replace(key, label)
        parts.append(f"<div class='fit-warning' style='font-size:12px;color:#9b1c1c'>"
                     f"warning: {html.escape(warning)}</div>")
    if not outcome.determined:
        parts.append(f"<div class='fit-not-applied' style='font-size:12px;color:#9b1c1c'>"
                     f"{html.escape(NOT_APPLIED)}</div>")
    if outcome.forecast_error:
        parts.append(f"<div class='fit-warning' style='font-size:12px;color:#9b1c1c'>no "
                     f"forecast: {html.escape(outcome.forecast_error)}</div>")
    return "".join(parts)
