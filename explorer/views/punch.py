"""The Punch tab: half-width and base shape of the punch, and a shape table upload; for a
scene of several punches, their section (:mod:`explorer.views.punches`) instead."""

from __future__ import annotations

import html
from collections.abc import Callable
from typing import Any

import panel as pn

from core.profiles import MAX_TABLE_BYTES, profile_from_csv

from ..model import ExplorerState, Screen
from ..solving import format_error
from .punches import PunchesSection
from .style import NOTE_STYLE, TAB_COLUMN, html_pane
from .widgets import Binding, BoundedUpload, LazySlider, PromptSelect, slider

SHAPES = {
    "flat": "flat", "crowned (parabolic, radius R)": "parabolic",
    "wedge (slope of each face)": "wedge", "single step (height, position)": "stepped",
    "central land (raised middle)": "land", "wavy / rough (amplitude, wavelength)": "wavy",
    "custom table (CSV upload or file)": "custom"}


class PunchView:
    """Widgets of ``state.punch``: the half-width a and the base shape f(x)."""

    title = "Punch"

    def __init__(self, state: ExplorerState, screen: Screen,
                 live_when: Callable[[], bool]) -> None:
        """``screen``: where a refused value or shape table is said; ``live_when``: whether
        a slider applies each drag step (else its release)."""
        self.state = s = state
        self.screen = screen
        self.punch = Binding(screen.reject, live_when=live_when)
        pb = self.punch
        self.half_width = pb.add("half_width", slider("half-width a [m]", 0.1, 5.0, 0.01,
                                                      css_classes=["punch-half-width"]))
        self.shape = pb.add("shape", PromptSelect(label="base shape", options=SHAPES,
                                                  sizing_mode="stretch_width"))
        # each shape's sliders are made when the shape is first chosen (LazySlider)
        self.radius = LazySlider(pb, "radius", "crown radius R [km]", 1.0, 500.0, 0.5,
                                 css_classes=["punch-crown-radius"])
        self.slope = LazySlider(pb, "slope", "slope of each face [µrad]", 0.0, 200.0, 0.5)
        self.step_height = LazySlider(pb, "step_height",
                                      "step height [µm] (right part raised)", -100.0, 100.0,
                                      0.5)
        self.step_position = LazySlider(pb, "step_position", "step position x [m]", -1.0,
                                        1.0, 0.01)
        self.land_height = LazySlider(pb, "land_height", "land height [µm] (middle protrudes)",
                                      0.0, 100.0, 0.5)
        self.land_width = LazySlider(pb, "land_width", "land width [m]", 0.05, 2.0, 0.01)
        self.wave_amplitude = LazySlider(pb, "wave_amplitude", "wave amplitude [µm]", 0.0,
                                         50.0, 0.1)
        self.wave_length = LazySlider(pb, "wave_length", "wavelength [m]", 0.02, 5.0, 0.01)
        self.shape_file = BoundedUpload(accept=(".csv", ".txt"), max_bytes=MAX_TABLE_BYTES)
        self.shape_file.param.watch(self._on_shape_file, "value")
        self.shape_note = html_pane("", styles=NOTE_STYLE)
        pb.bind(s.punch)
        s.punch.param.watch(lambda *e: self.refresh(), ["shape", "half_width",
                                                       "custom_label"])
        # the section of several punches is made when a scene of several first shows: a
        # page of one punch (most pages) does not pay for its widgets (~25 ms a page)
        self._section: PunchesSection | None = None
        self._section_args = (screen.reject, live_when)
        self.section_holder = pn.Column(margin=0, sizing_mode="stretch_width", visible=False)
        self.single = pn.Column(
            self.half_width, self.shape, *(lazy.holder for lazy in (
                self.radius, self.slope, self.step_height, self.step_position,
                self.land_height, self.land_width, self.wave_amplitude, self.wave_length)),
            self.shape_note,
            html_pane("<small>Upload a shape table: CSV with two columns, x [m] and "
                      "f(x) [m], f the height of the punch base above its lowest point."
                      "</small>"),
            self.shape_file, margin=0, sizing_mode="stretch_width")
        s.param.watch(lambda *e: self._follow_punches(), "n_punches")
        self._follow_punches()
        self.refresh()

    def content(self) -> pn.Column:
        """The tab's column."""
        return pn.Column(self.single, self.section_holder, **TAB_COLUMN)

    @property
    def punches(self) -> PunchesSection:
        """The section of several punches (made on first use)."""
        if self._section is None:
            self._section = PunchesSection(self.state, *self._section_args)
            self.section_holder.objects = [self._section.panel]
        return self._section

    def _follow_punches(self) -> None:
        """The one punch's widgets, or the section of several punches."""
        several = self.state.n_punches > 0
        self.single.visible = not several
        if several or self._section is not None:
            self.punches.panel.visible = several
        self.section_holder.visible = several

    def refresh(self) -> None:
        """Show the sliders of the chosen shape only."""
        p = self.state.punch
        a = p.half_width
        # strictly inside the punch, as the step must be (the ends were refused), and the
        # land no wider than it
        margin = min(0.01, 0.1 * a)
        self.step_position.update(start=-a + margin, end=a - margin)
        self.land_width.update(start=min(0.05, a), end=2.0 * a - 2.0 * margin)
        shape = p.shape
        self.radius.visible = shape == "parabolic"
        self.slope.visible = shape == "wedge"
        self.step_height.visible = self.step_position.visible = shape == "stepped"
        self.land_height.visible = self.land_width.visible = shape == "land"
        self.wave_amplitude.visible = self.wave_length.visible = shape == "wavy"
        if shape == "custom":
            source = p.custom_label or "a file"
            self.shape_note.object = (f"Custom shape from {html.escape(source)}." if p.custom
                                      is not None else "Upload a CSV table below.")
        else:
            self.shape_note.object = ""
        self.shape_note.visible = bool(self.shape_note.object)
        self.shape_file.visible = True

    def _on_shape_file(self, event: Any) -> None:
        data = event.new
        if data is None:  # (an empty file is said: "file is empty")
            return
        a = self.state.punch.half_width
        try:
            profile = profile_from_csv(data, field="punch.shape", variable="x",
                                       domain=(-a, a))
        except ValueError as exc:
            self.screen.notice = f"The shape table was not used: {format_error(str(exc))}"
            return
        finally:
            self.shape_file.clear()
        self.screen.notice = ""
        self.state.punch.param.update(custom=profile.spec, shape="custom",
                                      custom_label=self.shape_file.filename or "a CSV file")
