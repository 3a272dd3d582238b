"""What a slider step costs the server around the solve: two pieces of Panel's work that
the page does not need are left out (explorer/views/widgets.py and style.py).

- Panel counts every change from the browser as a busy event of its global state
  (``pn.state.busy``), which nothing in the explorer follows (it has a busy indicator of
  its own): the sliders, their text boxes and the time player are left out of that count.
- A text pane's new text reaches its model alone, not with every other property worked
  out again (styles, style sheets, the theme's modifiers).
- A slider that applies every step (a load) does not hear the page's release of its
  handle, which carries nothing new and cost as much as the step's own event.
"""

from __future__ import annotations

import panel as pn
import param
import pytest
from bokeh.document import Document

from explorer.views.style import CSS, TextPane, html_pane
from explorer.views.widgets import (
    Binding,
    EditableIntSlider,
    EditableSlider,
    TimePlayer,
    slider,
)


def _prompt_parts() -> list[pn.widgets.Widget]:
    float_slider = EditableSlider(start=0.0, end=10.0, step=0.5, value=1.0)
    int_slider = EditableIntSlider(start=0, end=10, step=1, value=1)
    return [float_slider._slider, float_slider._value_edit, int_slider._slider,
            int_slider._value_edit, TimePlayer(start=0, end=10, value=1)]


@pytest.mark.parametrize("index", range(5))
def test_a_value_from_the_page_leaves_panels_busy_count_alone(index: int) -> None:
    widget = _prompt_parts()[index]
    counted: list[object] = []
    watchers = [pn.state.param.watch(lambda e: counted.append(e.new), "busy"),
                pn.state.param.watch(lambda e: counted.append(e.new), "_busy_counter")]
    try:
        widget._process_events({"value": 3})  # as a change from the browser arrives
    finally:
        for watcher in watchers:
            pn.state.param.unwatch(watcher)
    assert widget.value == 3
    assert counted == []


def test_the_page_has_no_slider_that_panel_counts_as_busy(explorer_app) -> None:
    app = explorer_app()
    for index in range(len(app.tabs.sidebar)):  # a served page fills its tabs later
        app.tabs.fill(index)
    moved = [w for w in app.__panel__().select(pn.widgets.Widget)
             if isinstance(w, (pn.widgets.FloatSlider, pn.widgets.IntSlider,
                               pn.widgets.Player))]
    assert len(moved) > 20
    counted = [type(w).__name__ for w in moved if "value" not in w._busy__ignore]
    assert counted == []


TEXTS = ["", "<b>P</b> = 508 kN/m & e = 0 m", "x < y \"q\" 'r'", "$$x$$<script>1</script>",
         None]


@pytest.mark.parametrize("options", [{}, {"sanitize_html": True},
                                     {"styles": {"color": "red"}, "css_classes": ["a"]}])
def test_a_text_pane_sends_the_text_panel_would_and_nothing_else(options, monkeypatch):
    ours, panels = TextPane("start", stylesheets=[CSS], **options), \
        pn.pane.HTML("start", stylesheets=[CSS], **options)
    doc = Document()
    model, reference = ours.get_root(doc), panels.get_root(doc)
    worked_out: list[object] = []
    original = TextPane._get_properties
    monkeypatch.setattr(TextPane, "_get_properties",
                        lambda self, d: worked_out.append(self) or original(self, d))
    for text in TEXTS:
        ours.object = panels.object = text
        assert model.text == reference.text
    assert worked_out == []  # Panel's pane works out all its properties at each text
    # the other parameters reach the model as before
    ours.styles = panels.styles = {"color": "blue"}
    ours.visible = panels.visible = False
    assert (model.styles, model.visible) == (reference.styles, reference.visible)


def test_html_panes_of_the_page_are_text_panes() -> None:
    assert isinstance(html_pane("x"), TextPane)


class _Target(param.Parameterized):
    value = param.Number(0.0)


def _heard(widget: EditableSlider) -> set[str]:
    """The properties of the page's slider whose changes reach Python."""
    root = widget.get_root(Document())
    model = widget._slider._models[root.ref["id"]][0]
    return set(model._callbacks)


def test_a_slider_that_applies_every_step_does_not_hear_the_release() -> None:
    live, on_release = Binding(), Binding()
    steps = live.add("value", slider("load", 0.0, 10.0, 0.1), live=True)
    releases = on_release.add("value", slider("thickness", 0.0, 10.0, 0.1))
    live.bind(_Target())
    on_release.bind(_Target())
    assert "value" in _heard(steps) and "value_throttled" not in _heard(steps)
    assert {"value", "value_throttled"} <= _heard(releases)
