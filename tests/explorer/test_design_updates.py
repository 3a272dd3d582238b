"""A changed parameter reaches the page with the properties Panel sends, the theme worked
out only for a change of the style sheets (explorer/fixes/design_updates.py)."""

from __future__ import annotations

from typing import Any

import panel as pn
import param
import pytest
from bokeh.document import Document
from panel.io.state import set_curdoc
from panel.reactive import Reactive

from explorer.fixes import design_updates
from explorer.views.style import html_pane
from explorer.views.widgets import PromptFloatSlider


def _event(obj: Any, name: str, new: Any) -> param.parameterized.Event:
    return param.parameterized.Event(what="value", name=name, obj=obj, cls=type(obj),
                                     old=None, new=new, type="changed")


def _comparable(properties: dict[str, Any]) -> dict[str, Any]:
    # a style sheet model is new at each work-out: compare what it holds
    return {k: [getattr(s, "url", None) or getattr(s, "css", None) or s for s in v]
            if k == "stylesheets" else v for k, v in properties.items()}


@pytest.mark.parametrize("part, name, new", [
    ("slider", "value", 3.0), ("slider", "stylesheets", [".a {color: red;}"]),
    ("pane", "visible", False), ("pane", "styles", {"color": "blue"}),
    ("pane", "stylesheets", [".b {margin: 0;}"])])
def test_the_properties_sent_are_panels(part: str, name: str, new: Any) -> None:
    assert design_updates.install()  # a new Panel whose method differs fails here first
    slider, pane = PromptFloatSlider(start=0.0, end=10.0, value=1.0), html_pane("x")
    doc = Document()
    doc.add_root(pn.Column(slider, pane).get_root(doc))
    obj = slider if part == "slider" else pane
    with set_curdoc(doc):
        panels = Reactive._update_properties.__wrapped__(obj, _event(obj, name, new), doc=doc)
        ours = obj._update_properties(_event(obj, name, new), doc=doc)
    assert _comparable(ours) == _comparable(panels)
    if name == "stylesheets":  # the theme's sheets first, as Panel puts them
        assert len(ours["stylesheets"]) > 1


def test_a_value_change_leaves_the_design_alone(monkeypatch) -> None:
    assert design_updates.install()
    slider = PromptFloatSlider(start=0.0, end=10.0, value=1.0)
    doc = Document()
    doc.add_root(slider.get_root(doc))
    worked_out: list[object] = []
    design = type(slider._design)
    original = design.params
    monkeypatch.setattr(design, "params",
                        lambda self, *a, **k: worked_out.append(a) or original(self, *a, **k))
    with set_curdoc(doc):
        assert slider._update_properties(_event(slider, "value", 4.0), doc=doc) == {
            "value": 4.0}
    assert worked_out == []
