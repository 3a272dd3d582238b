"""The explorer page: one session's model objects, its views, and the page made of them.

``create_app()`` builds one :class:`ExplorerApp` per browser session (serve the factory,
not an instance). The page calls only the public API of ``core`` (through the
controller); every number the user sets lives in :class:`~explorer.model.ExplorerState`.
The session owns the model objects (state, screen, history, scales, limits), the solve
controller and the figures; each view is given those it needs
(:meth:`ExplorerApp._build_sidebar` is the one place where the sidebar's tabs are made),
and the session ties what happens in one to the others.
"""

from __future__ import annotations

import contextlib
import html
import logging
import time
from collections.abc import Callable, Iterator
from typing import Any

import panel as pn
import param

from .fixes import (
    bokeh_fixes,
    closed_pages,
    dropper_labels,
    gc_policy,
    idle_painter,
    install_in_process,
    layout_batch,
)
from .model import (
    DEFAULT_PRESET,
    DesignLimits,
    DisplayScales,
    ExplorerState,
    ResultView,
    SceneHistory,
    Screen,
    decode_scene,
    lesson_title,
    presets,
    read_fit_query,
    read_study_query,
    read_view_query,
    validated_scene,
)
from .plots import Figures
from .solving import SolveController, format_error, idle_release, install_websocket_marks, mark
from .views import (
    HELD_AFTER_MS,
    AddressLink,
    BaseView,
    CheckView,
    CoatingView,
    DeferredTabs,
    FidelityView,
    FilesView,
    FitView,
    LessonsView,
    PageLoop,
    PinsView,
    PromptToggle,
    PunchView,
    ResultsView,
    SceneView,
    StudyView,
    TimesView,
    html_pane,
    status_html,
)

__all__ = ["DragSteps", "ExplorerApp", "LIVE_BOUND_LIMITS_S", "LIVE_SOLVE_S", "check_live_bound",
           "create_app"]

log = logging.getLogger(__name__)
install_in_process()
install_websocket_marks()

#: Geometry and material sliders apply each drag step (not only the release) while the
#: last solve took less than this much CPU time [s]. CPU time, not wall time: on a shared
#: server the wall time of the same scene swings 2-3x with what others run, and the
#: sliders would turn live and back from one step to the next; the CPU time is what the
#: scene costs. A step that arrives late costs no backlog: the controller runs one solve at
#: a time and keeps only the newest request, and results are drawn at most every
#: DRAW_EVERY_MS. Measured in Chromium (benchmarks/explorer_latency.py, 1 s drags, a
#: 2-core machine): at 0.030 s the geometry sliders of both creep presets (solves of 36 and
#: 53 ms of CPU) applied on release only, one update 363-418 ms after it; at 0.100 s they
#: drew 3-16 frames during the drag and their last 206-682 ms after the release, as the
#: load sliders do. The lift-off preset's solves (~230 ms) stay on release. The default of
#: a session's ``live_bound`` (the server's ``--live-bound``). The CPU time of a scene is
#: steadier than its wall time, not fixed: on a loaded 2-core machine the default scene's
#: half-width steps cost 60-115 ms of CPU against ~35 ms on a quiet day.
LIVE_SOLVE_S = 0.100
#: The live bounds a session accepts [s] (``live_bound``, the server's ``--live-bound``).
LIVE_BOUND_LIMITS_S = (0.001, 60.0)


def check_live_bound(value: object) -> float:
    """``value`` as a live bound [s], or ValueError naming ``live_bound`` and the reason."""
    low, high = LIVE_BOUND_LIMITS_S
    if isinstance(value, bool) or not isinstance(value, (int, float)) \
            or not low <= value <= high:
        raise ValueError(f"live_bound: must be a number of seconds from {low:g} to "
                         f"{high:g}, got {value!r}")
    return float(value)


#: Shortest time between two results drawn on a served page [ms]: the page takes ~45-65
#: ms of its CPU to show one (benchmarks/results/explorer_latency.md), so a faster stream
#: of results only queues up in front of it (12 fps at most: a drag stays live).
DRAW_EVERY_MS = 80.0
#: For this long after a slider's release (a key step is one too), results are drawn as
#: they come, not spaced out by DRAW_EVERY_MS: only the answer in flight and the
#: release's own are still to come [s]. A new drag step ends it.
AFTER_RELEASE_S = 2.0


class DragSteps:
    """What a drag step of a slider that otherwise waits for its release does (the
    ``live_when`` of the views' bindings and the eccentricity slider's ``drag``):
    calling it says whether the step applies at once (the last solve was fast enough,
    :meth:`ExplorerApp.fast_solves`); a step not applied goes to :meth:`held`, where the
    page previews the dragged value if the base creeps (its base elastic at loading:
    6-50 ms of CPU with its view, where the answer with creep takes 0.2-7 s), and the
    release to :meth:`released`, after which the answer with creep is shown again."""

    def __init__(self, app: ExplorerApp) -> None:
        self._app = app

    def __call__(self) -> bool:
        return self._app._drag_step_applies()

    def held(self, target: Any, name: str, value: Any) -> None:
        """A step of parameter ``name`` of ``target`` (a part of the session's state) to
        ``value``, held until the release."""
        self._app.preview_step(target, name, value)

    def dragging(self) -> None:
        """A drag step of a slider: its results are spaced out again."""
        self._app.dragging()

    def released(self, dragged: bool = True) -> None:
        """A slider was released (its value, if new, is in the state); ``dragged``: after
        a drag (not a key press)."""
        self._app.released(dragged)

    @contextlib.contextmanager
    def applying(self) -> Iterator[None]:
        """Within: a drag step of a slider that applies every step (a load) reaches the
        state. The solve it asks lets this session's running one finish (that answer is
        the drag's next frame: a lift-off scene under creep took ~0.3 s a solve, and each
        step cancelled the one before, so a drag drew nothing until its release); the
        release cancels it instead (:meth:`released`). Where solves are slower than the
        live bound the page says that the plots follow the handle behind it."""
        app = self._app
        app._drag_step_now = True
        try:
            yield
        finally:
            app._drag_step_now = False
        app.say_following()

    def gesture_step(self) -> None:
        """A slider's handle moved: its changes up to :meth:`gesture_ended` are one step of
        undo (:meth:`~explorer.model.SceneHistory.drag_step`)."""
        self._app.history.drag_step()

    def gesture_ended(self) -> None:
        """The page released the handle (its last value, if new, is in the state)."""
        self._app.history.drag_ended()


class ExplorerApp(pn.viewable.Viewer):
    """One session of the explorer: its model objects, views and page."""

    def __init__(self, scene: dict[str, Any] | None = None, *,
                 query: dict[str, str] | None = None,
                 solve: Callable[[dict[str, Any]], Any] | None = None,
                 executor: Any = "shared", live_bound: float | None = None,
                 **params: Any) -> None:
        """``live_bound`` [s]: sliders that otherwise wait for their release follow a drag
        while the last solve took less CPU time than this (default :data:`LIVE_SOLVE_S`;
        the server's ``--live-bound``)."""
        super().__init__(**params)
        self.live_bound = None if live_bound is None else check_live_bound(live_bound)
        # within a drag step of a slider that applies every step (DragSteps.applying)
        self._drag_step_now = False
        # the note that the plots follow a load's drag behind the handle is up
        self._following = False
        self.loop = PageLoop(pn.state.curdoc)
        self.state = ExplorerState()
        self.screen = Screen()
        self.controller = SolveController(self.state, solve=solve, executor=executor,
                                          dispatch=self.loop.dispatch, auto=False)
        self.presets = presets()
        self.scales = DisplayScales()
        self.limits = DesignLimits()
        self.history = SceneHistory(self.state)
        self.figures = Figures(self.scales)
        self._initial_scene(scene, query or {})
        self.state.param.watch(lambda _: self.screen.scene_changed(), "revision")
        self.link = AddressLink(self.screen, self.controller, self.loop,
                                pn.state.location if self.loop.served else None,
                                self._view_parts, self.limits)
        self.pins = PinsView(self.state, self.screen, self.controller, self.loop,
                             on_change=self._on_pins)
        self.results = ResultsView(self.screen, self.controller, self.loop, self.figures,
                                   self.limits, self.pins, self.link)
        # model fidelity (layer interface, contact model, coating-model tolerance): one
        # view whose widgets sit in the Coating and Time tabs (see ``fidelity``)
        self._fidelity = FidelityView(self.state, self.screen.reject)
        # previews of held drag steps: the scene wanted next, whether a preview is asked
        # for (between a held step and its release), one is due (scheduled)
        self.drag = DragSteps(self)
        self._preview_scene: dict[str, Any] | None = None
        self._previewing = False
        self._preview_due = False
        # the time on screen before the first preview drawn (given back with the answer)
        self._index_before_preview: int | None = None
        self._layout = self._build_layout(self._build_sidebar())
        self._wanted_index, tab, pin_scenes, pin_message = read_view_query(
            query or {}, len(self.sidebar))
        if tab:
            self.tabs.fill(tab)
            self.sidebar.active = tab
        if pin_scenes:
            self.pins.solve_from_link(pin_scenes)
        if pin_message and not self.screen.notice:
            self.screen.notice = pin_message
        study_settings, study_message = read_study_query(query or {})
        if study_settings is not None:
            self.study_tab.apply_study_settings(study_settings)
        if study_message and not self.screen.notice:
            self.screen.notice = study_message
        fit_settings, fit_message = read_fit_query(query or {})
        if fit_settings is not None:
            self.fit_tab.apply_fit_settings(fit_settings)
        if fit_message and not self.screen.notice:
            self.screen.notice = fit_message
        # Changes to plain Bokeh models made after the page was generated but before its
        # websocket connects would never reach the browser: hold them until it does.
        self._initializing = True
        self._last_draw = float("-inf")  # when a result was last drawn (time.monotonic)
        self._draw_due = False  # a later draw of the newest result is scheduled
        # when a slider was last released, and no drag step since (time.monotonic)
        self._released_at = float("-inf")
        self._connected = not self.loop.served
        if self.loop.served:
            pn.state.onload(self._on_load)
        self.controller.param.watch(self._on_view, "view")
        self.controller.param.watch(self._on_preview, "preview")
        self.controller.param.watch(self._on_settled, "busy")
        self.controller.param.watch(self._on_answered, "solves")
        self.controller.param.watch(self.results.on_status, ["error", "busy"])
        self.screen.param.watch(self._on_time, "time_index")
        self.screen.param.watch(self._on_notice, "notice")
        self.state.param.watch(self._on_revision, "revision")
        # A known answer (a preset solved at start-up) is shown before the page is sent;
        # anything else is solved in the background while the page loads.
        self.controller.start()
        if self.controller.view is None and self.controller.error:
            self._fallback_to_default()
        if self.controller.view is None:
            # a slow first solve (a link to a long history): say so, not a blank page
            self.results.status.object = status_html(None, True)
        self._initializing = False

    def _build_sidebar(self) -> list[tuple[str, Any]]:
        """The sidebar's tabs, in their order on the page: each its title and its view's
        column, or the function that makes the view and its column. The index of a tab is
        part of the page's links (``explorer.model.view_link``): a new tab is appended,
        never inserted.

        The Scene, Check, Files and Lessons views are made at once (the others' results
        reach them, and they cost ~40 ms together); the other six only when their tab is
        filled (:class:`~explorer.views.DeferredTabs`: when opened, or a link names it; on
        a served page also in the background, elsewhere when the page is first shown), or
        when asked for (``app.base_tab``): they are ~0.6-0.9 s of the ~2 s of the server's
        CPU that a new page cost, and a page may never show them."""
        state, screen, controller, loop = self.state, self.screen, self.controller, self.loop
        live = self.drag
        self._views: dict[str, Any] = {}
        self._makers: dict[str, Callable[[], Any]] = {
            "punch": lambda: PunchView(state, screen, live),
            "coating": lambda: CoatingView(state, self._fidelity, controller, loop, live,
                                           screen),
            "base": lambda: BaseView(state, screen.reject, live),
            "times": lambda: TimesView(state, self._fidelity, screen.reject, live),
            "study": lambda: StudyView(state, controller, loop, self.link.schedule),
            "fit": lambda: FitView(state, controller, loop, self.figures, self.load_scene,
                                   screen, on_settings=self._fit_settings),
        }
        self._views["scene"] = SceneView(state, self.presets, self.preset_key, self.history,
                                         self.load_scene, controller, screen.reject, live)
        self._views["check"] = CheckView(state, self.limits, screen)
        self._views["files"] = FilesView(state, screen, controller, self.scales, self.limits,
                                         self._load_file, self.results.show_download_error)
        self._views["lessons"] = LessonsView(self.pins, self.results.log_time,
                                             self._load_lesson_step)
        order = (("scene", SceneView), ("punch", PunchView), ("coating", CoatingView),
                 ("base", BaseView), ("times", TimesView), ("check", CheckView),
                 ("files", FilesView), ("lessons", LessonsView), ("study", StudyView),
                 ("fit", FitView))
        self._tab_names = [name for name, _ in order]
        return [(cls.title, self._views[name].content() if name in self._views
                 else (lambda name=name: self._view(name).content()))
                for name, cls in order]

    def _view(self, name: str) -> Any:
        """The view of sidebar tab ``name``, made now if it was not yet."""
        view = self._views.get(name)
        if view is None:
            view = self._views[name] = self._makers[name]()
        return view

    def _made(self, name: str) -> Any | None:
        """The view of sidebar tab ``name`` if it was made, else None."""
        return self._views.get(name)

    @property
    def fidelity(self) -> FidelityView:
        """The model-fidelity view (the layer interface, the contact model, the coating
        model's tolerance). Its interface selector edits the layer that the Coating tab
        edits: that tab's view is made first, if it was not yet."""
        self._view("coating")
        return self._fidelity

    scene_tab = property(lambda self: self._view("scene"), doc="The Scene tab's view.")
    punch_tab = property(lambda self: self._view("punch"), doc="The Punch tab's view.")
    coating_tab = property(lambda self: self._view("coating"), doc="The Coating tab's view.")
    base_tab = property(lambda self: self._view("base"), doc="The Base tab's view.")
    times_tab = property(lambda self: self._view("times"), doc="The Time tab's view.")
    check_tab = property(lambda self: self._view("check"), doc="The Check tab's view.")
    files_tab = property(lambda self: self._view("files"), doc="The Files tab's view.")
    lessons_tab = property(lambda self: self._view("lessons"), doc="The Lessons tab's view.")
    study_tab = property(lambda self: self._view("study"), doc="The Study tab's view.")
    fit_tab = property(lambda self: self._view("fit"), doc="The Fit tab's view.")

    def page_parts(self) -> list[Any]:
        """Every viewable of the page: the layout, the sidebar tabs not filled yet, and
        the views made before their tab was filled (a link's Study or Fit settings)."""
        waiting = {k for k, (_, objects) in self.tabs.deferred.items()
                   if not isinstance(objects, list)}
        made = [self._views[name].content() for k, name in enumerate(self._tab_names)
                if k in waiting and name in self._views]
        return [self._layout, *self.tabs.parts(), *made]

    def _initial_scene(self, scene: dict[str, Any] | None, query: dict[str, str]) -> None:
        default = self.presets.get(DEFAULT_PRESET) or next(iter(self.presets.values()), None)
        chosen = scene
        if chosen is None and query.get("scene"):
            try:
                chosen = decode_scene(query["scene"])
                validated_scene(chosen)
            except ValueError as exc:
                self.screen.notice = (f"The scene in the link was not used: "
                                      f"{format_error(str(exc))}. Showing the default scene "
                                      "instead.")
                chosen = None
        if chosen is None and query.get("preset"):
            chosen = self.presets.get(query["preset"])
            if chosen is None:
                self.screen.notice = (f"Unknown preset {query['preset'][:40]!r} in the link; "
                                      "showing the default scene.")
        chosen = chosen or default
        if chosen is not None:
            try:
                self.state.load_scene(chosen)
                self.history.loaded = chosen
                # a link's (or a given scene's) design limits, as a scene file's are taken
                self.limits.take(chosen.get("limits"))
            except ValueError as exc:
                self.screen.notice = f"The scene could not be shown: {exc}"
        self.history.remember()
        self.preset_key = next((k for k, s in self.presets.items() if s == chosen), None)

    def _fallback_to_default(self) -> None:
        default = self.presets.get(DEFAULT_PRESET)
        if default is None:
            return
        self.screen.notice = (f"The scene could not be solved ({self.controller.error}); "
                              "showing the default scene instead.")
        self.scales.reset()
        self.state.load_scene(default)
        self.controller.solve_now()

    def fast_solves(self) -> bool:
        """Whether the last solve was quick enough for sliders to apply every drag step."""
        bound = LIVE_SOLVE_S if self.live_bound is None else self.live_bound
        return self.controller.solved_within(bound)

    def _drag_step_applies(self) -> bool:
        """At a drag step of a slider that otherwise waits for its release: whether the
        step applies now (:meth:`fast_solves`); when not, the page says so."""
        self.tabs.touch()
        self.dragging()
        fast = self.fast_solves()
        self.results.say_held(not fast, self._last_cpu_seconds(), self._drawn_preview is not None)
        return fast

    def say_following(self) -> None:
        """After a drag step of a slider that applies every step: where solves are slower
        than the live bound, the page says that the plots follow the handle behind it
        (each frame the last value solved), until the release."""
        following = not self.fast_solves()
        if following != self._following:  # (said once a drag, not at every step)
            self._following = following
            self.results.say_held(following, self._last_cpu_seconds(), following=True)

    @property
    def _drawn_preview(self) -> ResultView | None:
        """The preview on screen, if one (the results view keeps what it drew)."""
        view, preview = self.results.on_screen()
        return view if preview else None

    def _last_cpu_seconds(self) -> float | None:
        view = self.controller.view
        spent = None if view is None else view.info.get("cpu_seconds", view.info.get("seconds"))
        return float(spent) if isinstance(spent, (int, float)) else None

    # -- previews of held drag steps -----------------------------------------------
    def preview_step(self, target: Any, name: str, value: Any) -> None:
        """A drag step held until the release (:class:`DragSteps`): where the base creeps,
        the scene with ``target.name = value`` is previewed with its base elastic at
        loading (:meth:`SolveController.request_preview`): the first step of a drag is
        asked :data:`HELD_AFTER_MS` after it on a served page (a key press's release comes
        first: no preview then), the next ones at once (the newest when the worker is
        free). The state is not changed; a step back to the value applied ends the
        preview (:meth:`end_preview`)."""
        scene = self._scene_with(target, name, value)
        if scene is None:
            # a value with no scene (back at a refused one): no preview of another value
            # stays under it (the release there may not even reach the server)
            self.end_preview()
            return
        try:
            applied: dict[str, Any] | None = self.state.to_scene()
        except ValueError:
            # the value applied was refused (a crown radius of -3 km, its message on
            # screen): the step away from it is previewed (it raised here, a traceback
            # in the server's log)
            applied = None
        if scene == applied:
            # back at the value applied (a release there may not even reach the server:
            # the browser sends only a changed value): the answer with creep again
            self.end_preview()
            return
        if applied is not None and not self.controller.previews_differ(scene, applied):
            return  # a creep field alone (C∞, a rate): its preview would not move
        self._preview_scene = scene
        dragging, self._previewing = self._previewing, True
        if self._preview_due:
            return
        if dragging or not self.loop.served:
            self._ask_preview()  # a drag under way: every step (the newest when free)
            return
        self._preview_due = True
        self.loop.later(self._ask_preview, HELD_AFTER_MS)

    def _scene_with(self, target: Any, name: str, value: Any) -> dict[str, Any] | None:
        """The state's scene with ``target.name`` at ``value`` (the state left as it was,
        none of its watchers told); None when the state cannot make one."""
        old = getattr(target, name)
        try:
            with param.parameterized.discard_events(target):
                setattr(target, name, value)
                try:
                    return self.state.to_scene()
                finally:
                    setattr(target, name, old)
        except (ValueError, TypeError):
            return None

    def _ask_preview(self) -> None:
        self._preview_due = False
        scene, self._preview_scene = self._preview_scene, None
        if scene is not None and self._previewing:
            self.controller.request_preview(scene)

    def dragging(self) -> None:
        """A drag (again): its results are spaced out (:data:`DRAW_EVERY_MS`)."""
        self._released_at = float("-inf")

    def released(self, dragged: bool = True) -> None:
        """A slider was released: results are drawn as they come for a while
        (:data:`AFTER_RELEASE_S`), and the preview ends (:meth:`end_preview`). After a
        drag (``dragged``: not a key press) the solve of a value dragged over that still
        runs gives way to the released value's (:meth:`SolveController.released`), which
        otherwise waited for it: an answer drawn and at once replaced."""
        self._released_at = time.monotonic()
        if dragged:
            self.controller.released()
        self._following = False  # (a load's drag applied its value before: no revision)
        self.results.say_held(False)
        self.end_preview()

    def end_preview(self) -> None:
        """A release, or a held drag back at the value applied: no more previews; a
        preview on screen gives way to the new answer with creep once solved (to the one
        kept when none is solving)."""
        self._previewing = False
        self._preview_scene = None
        self.controller.stop_previews()
        # while the release's answer is solving the preview stays (the kept answer drawn
        # first would cost the page one more draw); without one, the kept answer at once
        if self._drawn_preview is not None and not self.controller.busy \
                and self.controller.view is not None:
            self._draw(self.controller.view)

    def _on_settled(self, event: Any) -> None:
        # the release's request answered without a new result (refused, or the result on
        # screen again): a preview drawn gives way to the answer with creep kept
        if (not event.new and self._drawn_preview is not None and not self._previewing
                and self.controller.view is not None):
            self._draw(self.controller.view)

    def _on_answered(self, event: Any) -> None:
        # the newest request answered (and drawn: the view's watcher came first): a pause
        # of the user's starts here (one undo step for a drag whose steps a loaded server
        # took seconds apart)
        if not self.controller.busy:
            self.history.went_idle()

    def _on_preview(self, event: Any) -> None:
        if self.controller.preview is None or not self._previewing:
            return
        self._on_view(None)

    # -- layout ----------------------------------------------------------------------
    def _build_layout(self, tabs: list[tuple[str, Any]]) -> pn.viewable.Viewable:
        self.tabs = DeferredTabs(self.loop, tabs)
        sidebar = self.tabs.sidebar
        sidebar.param.watch(lambda e: self.link.schedule(), "active")
        self.sidebar = sidebar
        header = html_pane(
            "<h2 style='margin:4px 0'>Coated punch explorer</h2>"
            "<div style='font-size:13px;color:#555'>A rigid punch on thin elastic coatings "
            "over an aging viscoelastic layer (plane strain, per metre out of plane). "
            "Sliders update while you drag when the solver keeps up, else on release."
            "</div>",
            sizing_mode="stretch_width")
        self.header = header
        self.presenting = PromptToggle(label="Presentation mode", width=170,
                                       css_classes=["presentation-toggle"])
        self.presenting.param.watch(self._on_presentation, "value")
        return pn.Column(pn.Row(header, self.presenting, sizing_mode="stretch_width"),
                         pn.Row(sidebar, self.results.content(), sizing_mode="stretch_width"),
                         sizing_mode="stretch_width")

    def _on_presentation(self, event: Any) -> None:
        """Presentation mode: large fonts, the whole story on a 1024x768 projector."""
        on = bool(event.new)
        with pn.io.hold():
            self.figures.set_presentation(on)
            self.header.visible = not on
            self.results.set_presentation(on)
        self.results.push()

    def __panel__(self) -> pn.viewable.Viewable:
        if not self.loop.served:
            # a notebook cell (or the page saved with pn.panel(app).save) shows every tab
            # as it is: no event loop fills them later
            self.tabs.fill_all()
        return self._layout

    # -- events ----------------------------------------------------------------------
    def _on_revision(self, event: Any) -> None:
        mark("revision")
        self.tabs.touch()  # the closed tabs are filled once the page is left alone
        if not self._drag_step_now:
            # a release applied: the plots follow now (a drag step of a load says its own
            # note after this, DragSteps.applying: hidden and shown again at every step,
            # the page would lay out twice a step)
            self._following = False
            self.results.say_held(False)
        self.history.remember()
        lessons = self._made("lessons")
        if lessons is not None:  # (a tab never opened has no lesson running)
            lessons.follow(self.state.scene_name)
        self.controller.request(keep_running=self._drag_step_now)

    def load_scene(self, scene: dict[str, Any], same_family: bool = False) -> bool:
        """Validate a scene dict with the core and show it; False (and a notice) if bad.
        ``same_family``: the scene continues the one on screen (a lesson's next step), so
        the unit of pressure and the colour scale stay (:class:`DisplayScales`)."""
        # one message to the page for every widget the scene sets, and the page's models
        # walked once for all the sliders it shows for the first time
        with pn.io.hold(), layout_batch.batch():
            try:
                validated_scene(scene)
                # before the load: a result found in the caches is drawn within it, and
                # took the last scene's unit of pressure (MPa or kPa by the way it came)
                if not same_family:
                    self.scales.reset()
                self.pins.forget_steps()
                self.state.load_scene(scene)
            except ValueError as exc:
                self.screen.notice = f"The scene was not loaded: {format_error(str(exc))}"
                return False
            self.history.loaded = scene
            self.screen.notice = ""
            self.limits.take(scene.get("limits"))
        return True

    def _fit_settings(self) -> None:
        """The Fit tab's readings or fields changed: the link keeps them, and readings
        over time on an answer at one output time bring its histories back."""
        self.link.schedule()
        view = self.screen.shown()
        if view is not None:
            self.results.follow_time_span(view)

    def _load_lesson_step(self, scene: dict[str, Any], first: bool) -> bool:
        """A lesson's step: its steps keep one unit of pressure (a class read q in kPa at
        one step and in MPa at the next), and the Scene tab shows the step's name and
        note (it kept the preset's, "a centred force of 500 kN per metre", beside plots of
        1000 kN/m)."""
        # the same lesson's step on screen (changed or not): else a preset or a file was
        # loaded meanwhile, and the step starts a family of its own
        same = not first and lesson_title(self.state.scene_name) == lesson_title(
            str(scene["name"]))
        if not self.load_scene(scene, same_family=same):
            return False
        self.scene_tab.forget_preset()
        return True

    def _load_file(self, scene: dict[str, Any]) -> bool:
        """A scene read from a file: shown as a scene of its own, no preset chosen."""
        if not self.load_scene(scene):
            return False
        self.scene_tab.forget_preset()
        return True

    def _view_parts(self) -> tuple[int, list[dict[str, Any]], dict[str, Any] | None,
                                   dict[str, Any] | None]:
        """What a link keeps besides the scene and the time: the open tab, the pinned
        scenes, the Study tab's settings and the Fit tab's readings and fields."""
        # (a tab never made has nothing of its own to keep: its defaults follow the scene)
        study, fit = self._made("study"), self._made("fit")
        return (self.sidebar.active, self.pins.board.scenes(),
                None if study is None else study.study_settings(),
                None if fit is None else fit.fit_settings())

    def _on_pins(self) -> None:
        self.results.show_pins()
        self.link.schedule()

    def _on_notice(self, event: Any) -> None:
        # notices echo user text (file names, field names, formulas, links): the alert
        # renders Markdown, which passes raw HTML through, so the text is escaped
        notice = self.screen.notice
        self.results.notice_alert.object = html.escape(notice)
        self.results.notice_alert.visible = bool(notice)

    def _on_load(self) -> None:
        self._connected = True
        if self.controller.view is not None and self.controller.view is not self.screen.drawn:
            self._on_view(None)
        else:
            self.results.page_loaded()
        self.tabs.fill_when_idle()

    def _newest(self) -> ResultView | None:
        """What the page draws next: a preview while a held drag asks for one and one
        came, else the controller's result."""
        preview = self.controller.preview
        if self._previewing and preview is not None:
            return preview
        return self.controller.view

    def _on_view(self, event: Any) -> None:
        view = self._newest()
        if view is None or not (self._connected or self._initializing):
            return
        if self.loop.served:
            # results drawn at most every DRAW_EVERY_MS, the newest when the time comes: a
            # drag solved 20 steps a second, each patch took the page ~65 ms of its CPU,
            # and the queued patches kept coming 1.5 s after the release
            now = time.monotonic()
            wait = self._last_draw + DRAW_EVERY_MS / 1000.0 - now
            # after a release at most the answer in flight and the release's own come: a
            # wait only delays the last frame (up to DRAW_EVERY_MS of the time from the
            # release to it, whose goal is 200 ms)
            if now - self._released_at < AFTER_RELEASE_S:
                wait = 0.0
            if wait > 0:
                if not self._draw_due:
                    self._draw_due = True
                    self.loop.later(self._draw_due_view, 1000.0 * wait)
                return
        self._draw(view)

    def _draw_due_view(self) -> None:
        """The newest result, when the interval after the last draw is over."""
        self._draw_due = False
        view = self._newest()
        if view is not None and view is not self.screen.drawn \
                and view is not self._drawn_preview:
            self._draw(view)

    def _draw(self, view: ResultView) -> None:
        preview = view is self.controller.preview and view is not self.controller.view
        if preview:
            self._draw_preview(view)
            return
        self._last_draw = time.monotonic()
        n = len(view.times)
        old = self.screen.drawn
        # what the plots show now (a preview of another count of times may have clipped
        # the time and the player's range), and the time before the previews
        shown = self.results.on_screen()[0]
        before, self._index_before_preview = self._index_before_preview, None
        if old is None and self._wanted_index is not None:
            index = min(self._wanted_index, n - 1)  # the time the link was made at
        elif shown is not old and shown is not None and old is not None \
                and len(shown.times) == n:
            index = min(self.screen.time_index, n - 1)  # a time moved under the preview
        elif old is None or len(old.times) != n:
            index = n - 1
        elif (shown is not old and shown is not None and len(shown.times) != n
              and before is not None):
            index = min(before, n - 1)  # (a time moved under a same-count preview stays)
        else:
            index = min(self.screen.time_index, n - 1)
        self.screen.drawn = view
        self.pins.on_result(view)  # (the board pins a scene once: a redraw adds none)
        check = self._made("check")
        if check is not None:
            check.show_eccentricity()
        coating = self._made("coating")
        if coating is not None:
            coating.check.follow(view.scene)  # a report of another scene says so
        if not self._following:  # (a load's drag draws the answers solved meanwhile)
            self.results.say_held(False)
        with pn.io.hold():
            self.results.draw(view, index, new_range=shown is None or len(shown.times) != n)
            self.files_tab.name_files(view)
            mark("drawn")  # the patch goes out as the hold ends
        self.results.push()
        self.link.schedule()

    def _draw_preview(self, view: ResultView) -> None:
        """Draw a preview (:meth:`preview_step`) at the time on screen. The result on
        screen stays the last answer with creep (``screen.drawn``: pins, downloads and
        the page's link speak of it), which the release draws again."""
        self._last_draw = time.monotonic()
        shown = self.results.on_screen()[0]
        if self._drawn_preview is None:
            self._index_before_preview = self.screen.time_index
        index = min(self.screen.time_index, len(view.times) - 1)
        with pn.io.hold():
            self.results.draw(view, index, new_range=shown is None
                              or len(shown.times) != len(view.times), preview=True)
            self.results.say_held(True, self._last_cpu_seconds(), preview=True)
            mark("drawn")
        self.results.push()

    def _on_time(self, event: Any) -> None:
        self.tabs.touch()
        # the result the plots show: a preview stays on screen while the release's
        # answer solves, and the time moved meanwhile is the preview's
        view = self.results.on_screen()[0]
        if view is None:
            return
        index = min(max(int(event.new), 0), len(view.times) - 1)
        with pn.io.hold():
            self.figures.show_time(view, index, self.pins.board.pins)
            self.results.show_time_texts(view, index)
        self.results.push()
        self.link.schedule()


def _query_from_session() -> dict[str, str]:
    """The page's query arguments (first value of each, as text)."""
    out: dict[str, str] = {}
    for key, values in (pn.state.session_args or {}).items():
        if values:
            raw = values[0]
            out[key] = raw.decode("utf-8", "replace") if isinstance(raw, bytes) else str(raw)
    return out


def create_app(**kwargs: Any) -> ExplorerApp:
    """A new explorer session (serve this factory so each browser gets its own state).

    Served, it solves off the page's thread (in the server's worker processes when
    ``python -m explorer`` started them, else on a shared thread pool); inline in a
    notebook (no server session) it solves in the kernel, each change when it happens.
    """
    pn.extension("filedropper", notifications=False)
    served = bool(pn.state.curdoc is not None and pn.state.curdoc.session_context)
    kwargs.setdefault("executor", "shared" if served else None)
    if served:
        closed_pages.start_busy_cleanup()  # before this page can be busy
        gc_policy.pause_for_page()
        gc_policy.install()  # the collection for ended sessions is the policy's alone
        pn.state.on_session_destroyed(gc_policy.session_ended)
        idle_release.session_opened()
        pn.state.on_session_destroyed(idle_release.session_closed)
        bokeh_fixes.install(pn.state.curdoc)
        idle_painter.install(pn.state.curdoc)
        dropper_labels.install(pn.state.curdoc)
    if "query" not in kwargs:
        kwargs["query"] = _query_from_session()
    app = ExplorerApp(**kwargs)
    if served:
        pn.state.on_session_destroyed(closed_pages.page_releaser(app.page_parts))
        pn.state.on_session_destroyed(gc_policy.watch_page(app))
    return app
