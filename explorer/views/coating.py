"""The Coating tab: the number of layers, the profiles of the layer being edited, and the
"check the coating model" button (the resolved finite-element check of the scene)."""

from __future__ import annotations

import html
import logging
import threading
from collections.abc import Callable
from typing import Any

import panel as pn

from core.scene import check_scene, check_settled, checked_key, percent_text, pressure_caution

from ..model import SCREEN_LAYERS, ExplorerState, Screen
from ..solving import SolveController, run_in_background
from .fidelity import FidelityView
from .loop import PageLoop
from .punches import OnePunchOnly
from .style import NOTE_STYLE, TAB_COLUMN, html_pane
from .widgets import ProfileEditor, PromptIntSlider, PromptRadioButtonGroup, significant_format

log = logging.getLogger(__name__)

#: FE mesh level of the check (0, the coarsest: ~1-3 s of one core; P and M to ~2e-4).
CHECK_LEVEL = 0
#: FE coating checks running at once in one server: one took the server's processes from
#: 0.3 to 3.3 GiB, so several pages pressing the button at once were bounded by nothing
#: but the machine. A check waits for the one before it, at most CHECK_WAIT_S [s].
MAX_RUNNING_CHECKS = 1
CHECK_WAIT_S = 300.0
_CHECKS = threading.BoundedSemaphore(MAX_RUNNING_CHECKS)
#: Rows of the check's table: quantity, unit shown, factor from SI.
CHECK_ROWS = (("settlement", "mm", 1e3), ("tilt", "mrad", 1e3), ("force", "kN/m", 1e-3),
              ("moment", "kN·m/m", 1e-3))
#: A value of the check's table below this share of its pair's scale is shown as 0: the
#: FE solve's own round-off (the default scene's centred load: FE tilt -2.09e-15 rad, 8.6e-11
#: of its settlement over a, read "-2.0939e-12 mrad").
ROUND_OFF = 1e-9


#: What the tab says with no coating layer (the scope of core's bare-base answer).
BARE_NOTE = ("<small>No coating: the punch presses the bare base, whose pressure rises "
             "without bound at the punch edges (like 1 / &radic;(distance to the edge)). "
             "Solved in full contact under a smooth punch; add a layer to see what a "
             "coating does.</small>")


#: The tab's first line, with layers and without.
TOP_NOTE = ("<small>Layer 1 touches the punch. Changes apply while you drag when solves are "
            "quick, else when you release a slider.</small>")
TOP_NOTE_BARE = ("<small>Changes apply while you drag when solves are quick, else when you "
                 "release a slider.</small>")


class CoatingView:
    """Widgets of ``state.layers``: thickness h(x), modulus E(x), Poisson ratio of each."""

    title = "Coating"

    def __init__(self, state: ExplorerState, fidelity: FidelityView,
                 controller: SolveController, loop: PageLoop,
                 live_when: Callable[[], bool], screen: Screen | None = None) -> None:
        """``fidelity``: its interface selector edits the layer chosen here;
        ``controller`` and ``loop``: where the coating-model check runs and reports;
        ``live_when``: whether a slider applies each drag step (else its release);
        ``screen``: where the check's report is put for the badges, status and report."""
        self.state = s = state
        self.fidelity = fidelity
        self.n_layers = PromptIntSlider(label="number of layers", start=0, end=SCREEN_LAYERS,
                                        value=min(s.n_layers, SCREEN_LAYERS),
                                        sizing_mode="stretch_width")
        self.n_layers.param.watch(lambda e: setattr(s, "n_layers", e.new), "value_throttled")
        self.layer = PromptRadioButtonGroup(label="edit layer", options=["1"], value="1",
                                            color="primary", variant="outline",
                                            sizing_mode="stretch_width")
        self.layer.param.watch(lambda *e: self.bind_layer(), "value")
        # where an emptied or refused box is said (the thickness box emptied said nothing)
        reject = None if screen is None else screen.reject
        self.thickness_editor = ProfileEditor("thickness", "mm", 0.5, 50.0, 0.1,
                                              significant_format(),
                                              amplitude=("µm", -1000.0, 1000.0, 0.5),
                                              css="coating-thickness", live_when=live_when,
                                              on_reject=reject)
        self.modulus_editor = ProfileEditor("Young's modulus", "MPa", 1.0, 10000.0, 1.0,
                                            significant_format(), css="coating-modulus",
                                            live_when=live_when, on_reject=reject)
        self.poisson_editor = ProfileEditor("Poisson ratio", "-", 0.0, 0.49, 0.01,
                                            variations=False, live_when=live_when,
                                            on_reject=reject)
        self.layer_note = html_pane("", styles=NOTE_STYLE)
        self.bare_note = html_pane(BARE_NOTE, styles=NOTE_STYLE, css_classes=["bare-note"])
        self.check = CoatingCheckView(state, controller, loop, screen)
        # (said of the layers only while there are layers: "Layer 1 touches the punch"
        # read above "no coating" at 0 layers)
        self.top_note = html_pane(TOP_NOTE)
        s.param.watch(lambda *e: self.refresh(), "n_layers")
        self.refresh()

    def content(self) -> pn.Column:
        """The tab's column."""
        return pn.Column(
            self.top_note,
            self.n_layers, self.bare_note, self.layer, self.layer_note,
            self.thickness_editor.panel,
            self.modulus_editor.panel, self.poisson_editor.panel,
            self.fidelity.interface_panel,
            OnePunchOnly(self.state, "The coating model's FE check", self.check.panel).panel,
            **TAB_COLUMN)

    def refresh(self) -> None:
        """Offer one button per layer on screen; say so when the scene has more; with no
        layer, hide the layer's editors and say what is solved."""
        n = self.state.n_layers
        shown = min(n, SCREEN_LAYERS)
        self.n_layers.value = shown
        bare = shown == 0
        self.bare_note.visible = bare
        self.top_note.object = TOP_NOTE_BARE if bare else TOP_NOTE
        for part in self.layer_parts:
            part.visible = not bare
        if bare:
            self.layer_note.visible = False
            return
        options = [str(k + 1) for k in range(shown)]
        if self.layer.value not in options:
            self.layer.value = options[-1]
        self.layer.options = options
        self.layer_note.object = (f"This scene has {n} layers; the screen edits the first "
                                  f"{SCREEN_LAYERS}." if n > SCREEN_LAYERS else "")
        self.layer_note.visible = bool(self.layer_note.object)
        self.bind_layer()

    @property
    def layer_parts(self) -> tuple[Any, ...]:
        """The widgets of the layer being edited (hidden when there is none)."""
        return (self.layer, self.thickness_editor.panel, self.modulus_editor.panel,
                self.poisson_editor.panel, self.fidelity.interface_panel, self.check.panel)

    def bind_layer(self) -> None:
        """Point the editors at the layer chosen."""
        state = self.state
        if state.n_layers == 0:
            return
        layer = state.layers[int(self.layer.value) - 1]
        a = state.punch.half_width
        self.thickness_editor.bind(layer.thickness, a)
        self.modulus_editor.bind(layer.modulus, a)
        self.poisson_editor.bind(layer.poisson, a)
        self.fidelity.bind_layer(layer)


def check_report_html(report: dict[str, Any]) -> str:
    """The FE check's report (:func:`core.scene.check_scene`) as HTML: the model
    error of the fast answer beside its estimate, and a row per quantity."""
    errors = report["errors"]
    given = report.get("given", ())
    a = float(report.get("half_width_m", 1.0))
    fe = report["fe"]
    # a value below 1e-12 of its pair's scale is round-off (the tilt of a centred load
    # read "-2.4826e-15 mrad"): shown as 0
    kin = max(abs(fe["settlement"]), a * abs(fe["tilt"]))
    stat = max(abs(fe["force"]), abs(fe["moment"]) / a)
    scales = {"settlement": kin, "tilt": kin / a, "force": stat, "moment": stat * a}
    rows = []
    for name, unit, factor in CHECK_ROWS:
        error = "given" if name in given else f"{100 * errors[name]:+.3f}"
        shown = [0.0 if abs(v) < ROUND_OFF * scales[name] else factor * v
                 for v in (report["fast"][name], fe[name])]
        rows.append(f"<tr><td>{name} [{unit}]</td><td>{shown[0]:.5g}</td>"
                    f"<td>{shown[1]:.5g}</td><td>{error}</td></tr>")
    where = report.get("pressure_error_at_m")
    # q of each model where they differ most, in kPa (the cells were empty: an error
    # beside no values, a teacher's audit)
    at = [f"{v / 1e3:.5g}" if isinstance(v, (int, float)) else ""
          for v in (report.get("pressure_fast_Pa"), report.get("pressure_fe_Pa"))]
    rows.append("<tr><td>pressure q [kPa], |x| &le; 0.9 a"
                + ("" if where is None else f" (at x = {where:.4g} m, where they differ most)")
                + f"</td><td>{at[0]}</td><td>{at[1]}</td>"
                f"<td>{100 * errors['pressure']:.3f}</td></tr>")
    caution = pressure_caution(report)
    return (
        f"<div class='coating-check-report'><small>At loading, against the resolved "
        f"finite-element model ({report['fe_dofs']:,} unknowns, "
        f"{report['fe_seconds']:.1f} s). Coating model: {report['coating_model']}.</small>"
        f"<br><b>model error: {_measured_word(report)} "
        f"{percent_text(report['model_error'])}, estimated {percent_text(report['estimate'])}</b>"
        + _contact_note(report)
        + "<table class='cp-readout'><tr><th></th><th>fast</th><th>FE</th><th>error [%]</th>"
        "</tr>" + "".join(rows) + "</table>"
        + (f"<div class='check-pressure-caution' style='color:#9b1c1c;font-size:12px'>"
           f"⚠ {html.escape(caution)}</div>" if caution else "") + "</div>")


def _measured_word(report: dict[str, Any]) -> str:
    """How the report's model error reads: measured, or not (the FE contact set had not
    settled, :func:`core.scene.check_settled`)."""
    return "measured" if check_settled(report) else "not measured (FE contact unsettled),"


def _zones_text(zones: list[list[float]]) -> str:
    """Contact zones [m] as text."""
    return ", ".join(f"[{lo:.4g}, {hi:.4g}]" for lo, hi in zones) + " m"


def _contact_note(report: dict[str, Any]) -> str:
    """How the check treated contact: both models with lift-off where the scene lifts
    off (their contact sets side by side), or a full-contact answer with q < 0."""
    lift = report.get("lift_off")
    if lift:
        unsettled = "" if check_settled(report) else (
            f" The FE contact set had not settled after {lift.get('fe_sweeps', 0)} sweeps: "
            "these numbers are not a measurement, and the badges keep the estimate.")
        return ("<br><span class='cp-msg'>The punch lifts off here: both models are "
                f"compared with lift-off. Contact: fast {_zones_text(lift['fast'])}, FE "
                f"{_zones_text(lift['fe'])} (zone ends "
                f"{report['errors']['contact_ends']:.3g} a apart).{unsettled}</span>")
    if report.get("contact_lost"):
        return ("<br><span class='cp-msg'>This full-contact answer has q &lt; 0: both "
                "models are compared in full contact (solver.contact 'full').</span>")
    return ""


#: Above a check report made for another scene than the one on screen.
STALE_NOTE = ("<span class='cp-msg coating-check-stale-note'>Made for an earlier scene "
              "(the coating, the punch, the base or the loads changed since): these are not "
              "this scene's numbers, and the badges use the estimate again. Run the check "
              "again for this scene.</span>")


class CoatingCheckView:
    """The "check the coating model" button: runs :func:`core.scene.check_scene`
    on the scene on screen where the session's solves run (a worker process, or a thread
    of the solver pool; never the page's event loop), shows a progress bar meanwhile and
    the report when it is done."""

    def __init__(self, state: ExplorerState, controller: SolveController,
                 loop: PageLoop, screen: Screen | None = None) -> None:
        """``screen``: its ``model_check`` receives each report, so that the badges, the
        status and the report download speak of the measured error of the scene it was
        made for (the estimate of any other)."""
        self.state = state
        self.screen = screen
        self.controller = controller
        self.loop = loop
        self.button = pn.widgets.Button(label="check the coating model",
                                        sizing_mode="stretch_width",
                                        css_classes=["coating-check-button"])
        self.progress = pn.indicators.Progress(active=True, visible=False,
                                               sizing_mode="stretch_width",
                                               css_classes=["coating-check-progress"])
        self.result = html_pane("", css_classes=["coating-check-result"],
                                sizing_mode="stretch_width")
        self._report: dict[str, Any] | None = None  # the report on screen
        self._stale = False
        self.button.on_click(lambda event: self.run())
        self.panel = pn.Column(
            html_pane("<small>Compare the answer with a finite-element model that resolves "
                      "the coating (at loading, a few seconds).</small>", styles=NOTE_STYLE),
            self.button, self.progress, self.result, margin=0, sizing_mode="stretch_width")

    def run(self) -> None:
        """Start the check of the current scene (the outcome arrives by :meth:`show`)."""
        try:
            scene = self.state.to_scene()
        except ValueError as exc:
            self.result.object = f"<span class='cp-msg'>Not checked: {exc}</span>"
            return
        self.button.disabled = True
        self.progress.visible = True
        self.result.object = "<small>Solving the resolved model…</small>"
        if self.controller.executor is None:
            self.show(_check(scene))
            return

        def work() -> None:
            # a thread of its own, not the solver pool's: it may wait for another
            # page's check, and the pool's threads serve every page's slider solves
            self._finish(_check(scene, lambda: self.loop.dispatch(self._say_waiting)))

        start_in_background(work)

    def _say_waiting(self) -> None:
        self.result.object = ("<small>Waiting for another page's coating check to finish "
                              "(one runs at a time on this server)…</small>")

    def _finish(self, outcome: dict[str, Any] | str) -> None:
        self.loop.dispatch(lambda: self.show(outcome))

    def show(self, outcome: dict[str, Any] | str) -> None:
        """Show a report (dict) or a message (str) and make the button ready again."""
        self.progress.visible = False
        self.button.disabled = False
        self._report = outcome if isinstance(outcome, dict) else None
        self._stale = False
        self.result.object = (check_report_html(outcome) if isinstance(outcome, dict)
                              else f"<span class='cp-msg'>{outcome}</span>")
        if isinstance(outcome, dict) and self.screen is not None:
            self.screen.model_check = outcome
            # the scene may have changed while the FE model solved
            if self.screen.drawn is not None:
                self.follow(self.screen.drawn.scene)

    def follow(self, scene: dict[str, Any]) -> None:
        """A new result of ``scene``: a report made for another scene (the geometry, the
        materials or the loads changed since) is marked as such, and unmarked when the
        scene it was made for is back (an undo)."""
        if self._report is None:
            return
        stale = checked_key(scene) != self._report.get("scene_key")
        if stale == self._stale:
            return
        self._stale = stale
        report = check_report_html(self._report)
        self.result.object = (STALE_NOTE + f"<div class='coating-check-stale'>{report}</div>"
                              if stale else report)


def start_in_background(work: Callable[[], None]) -> None:
    """Run ``work`` on a thread of its own (a check may wait for another page's)."""
    threading.Thread(target=work, name="coating-check", daemon=True).start()


def _check(scene: dict[str, Any], waiting: Callable[[], None] | None = None
           ) -> dict[str, Any] | str:
    """The check's report, or why there is none (runs off the event loop): one check at a
    time on the server (:data:`MAX_RUNNING_CHECKS`), ``waiting()`` called when it has to
    wait for another, at most :data:`CHECK_WAIT_S`."""
    if not _CHECKS.acquire(blocking=False):
        if waiting is not None:
            waiting()
        if not _CHECKS.acquire(timeout=CHECK_WAIT_S):
            return (f"Not checked: other pages' coating checks kept the server busy for "
                    f"{CHECK_WAIT_S:.0f} s; try again later.")
    try:
        # at a lower priority than the pages' slider solves in the other workers
        return run_in_background(check_scene, scene, 0.0, CHECK_LEVEL)
    except ValueError as exc:
        return f"Not checked: {exc}"
    except Exception as exc:  # the session must survive a failed check
        log.exception("coating check failed")
        return f"The check failed ({type(exc).__name__}: {exc})."
    finally:
        _CHECKS.release()
