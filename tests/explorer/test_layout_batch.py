"""Many layout changes of a page walk its models once (explorer/fixes/layout_batch.py).

Each change of a layout's children made Bokeh recompute the document's models and Panel
run the page's preprocessing hooks, both walks over the whole page; a preset switch that
makes new sliders changed several layouts. Inside ``layout_batch.batch`` both run once at
the end, and the page comes out the same: the same models, and the links of the new
sliders' text boxes set up.
"""

from __future__ import annotations

import contextlib
from collections import Counter
from collections.abc import Iterator
from typing import Any

import panel as pn
import pytest
from bokeh.document import Document
from panel.io.state import set_curdoc, state
from panel.layout.base import Panel
from panel.viewable import Renderable

from core.presets import read_preset
from explorer.fixes import layout_batch
from explorer.views import PageLoop
from explorer.views.widgets import slider


@contextlib.contextmanager
def counted_walks(doc: Document, monkeypatch: pytest.MonkeyPatch) -> Iterator[Counter]:
    """Count the document's model recomputes and the pages' preprocessing runs."""
    counts: Counter = Counter()
    recompute = doc.models.recompute
    preprocess = Renderable._preprocess

    def counted_recompute() -> None:
        counts["recompute"] += 1
        recompute()

    def counted_preprocess(self: Any, *args: Any, **kwargs: Any) -> None:
        counts["preprocess"] += 1
        preprocess(self, *args, **kwargs)

    with monkeypatch.context() as patch:
        patch.setattr(doc.models, "recompute", counted_recompute)
        patch.setattr(Renderable, "_preprocess", counted_preprocess)
        yield counts


def _page(doc: Document) -> tuple[pn.Column, list[pn.Column], Any]:
    """A served-like page: a column of three empty holders and a slider, its root model
    in ``doc`` and known to Panel's views (as a served page's is)."""
    holders = [pn.Column() for _ in range(3)]
    page = pn.Column(*holders, slider("kept", 0.0, 1.0, 0.1))
    root = page.get_root(doc)
    doc.add_root(root)
    state._views[root.ref["id"]] = (page, root, doc, None)
    return page, holders, root


def _fill(holders: list[pn.Column], batched: bool, doc: Document) -> None:
    with layout_batch.batch(doc) if batched else contextlib.nullcontext():
        for k, holder in enumerate(holders):
            holder.objects = [slider(f"new {k}", 0.0, 1.0, 0.1)]


@pytest.mark.parametrize("batched", [False, True])
def test_new_sliders_in_a_batch_walk_the_page_once(batched: bool, monkeypatch) -> None:
    doc = Document()
    page, holders, root = _page(doc)
    try:
        with set_curdoc(doc), counted_walks(doc, monkeypatch) as counts:
            _fill(holders, batched, doc)
        # without the batch: a recompute and a preprocessing run per holder changed
        expected = 1 if batched else len(holders)
        assert counts == {"recompute": expected, "preprocess": expected}
        # each new slider's text box has its link (it widens the slider's range when a
        # typed value is beyond it), and every new model is the document's
        for holder in holders:
            box = holder.objects[0]._value_edit._models[root.ref["id"]][0]
            assert len(box.js_property_callbacks.get("change:value", [])) == 1
            assert box.id in doc.models
            assert box.js_property_callbacks["change:value"][0].id in doc.models
        assert not Panel._batch_update and doc.models._freeze_count == 0
    finally:
        state._views.pop(root.ref["id"], None)


def test_a_batch_makes_the_page_an_unbatched_change_makes(monkeypatch) -> None:
    kinds = []
    for batched in (False, True):
        doc = Document()
        _, holders, root = _page(doc)
        try:
            with set_curdoc(doc):
                _fill(holders, batched, doc)
            kinds.append(Counter(type(m).__name__ for m in doc.models))
        finally:
            state._views.pop(root.ref["id"], None)
    assert kinds[0] == kinds[1]


def test_a_nested_or_frozen_block_runs_as_it_is(monkeypatch) -> None:
    doc = Document()
    _, holders, root = _page(doc)
    try:
        with set_curdoc(doc), counted_walks(doc, monkeypatch) as counts:
            with layout_batch.batch(doc):
                with layout_batch.batch(doc):  # nested: the outer one walks
                    holders[0].objects = [slider("a", 0.0, 1.0, 0.1)]
                assert Panel._batch_update and counts["recompute"] == 0
            assert counts == {"recompute": 1, "preprocess": 1}
            with doc.models.freeze():  # frozen by someone else: left to them
                with layout_batch.batch(doc):
                    assert not Panel._batch_update
    finally:
        state._views.pop(root.ref["id"], None)


def test_an_error_inside_leaves_panel_and_the_document_as_they_were() -> None:
    doc = Document()
    _, holders, root = _page(doc)
    try:
        with set_curdoc(doc), pytest.raises(RuntimeError, match="inside"):
            with layout_batch.batch(doc):
                holders[0].objects = [slider("a", 0.0, 1.0, 0.1)]
                raise RuntimeError("inside")
        assert not Panel._batch_update and doc.models._freeze_count == 0
        assert "_push_freeze" not in vars(doc.models)
        # the slider made before the error is on the page, its link set up
        box = holders[0].objects[0]._value_edit._models[root.ref["id"]][0]
        assert box.id in doc.models and box.js_property_callbacks
    finally:
        state._views.pop(root.ref["id"], None)


def test_a_preset_switch_walks_the_page_once(explorer_app, monkeypatch) -> None:
    """The default page switched to a preset whose crown radius and graded coating
    sliders the page has not made yet: one recompute (three or more without the batch)."""
    app = explorer_app()
    doc = Document()
    app.__panel__().server_doc(doc)
    assert app.controller.wait(60) and app.controller.error == ""
    with set_curdoc(doc), counted_walks(doc, monkeypatch) as counts:
        assert app.load_scene(read_preset("rounded_graded"))
    assert counts["recompute"] == 1 and counts["preprocess"] <= 1, counts
    assert app.controller.wait(120) and app.controller.error == ""
    # back and forth between presets whose sliders are made: no model added or dropped,
    # no walk, and the document's models are still those of its roots (served: outside
    # a server the time player is made anew for each range, see ResultsView._set_range)
    monkeypatch.setattr(PageLoop, "served", property(lambda self: True))
    monkeypatch.setattr(app.loop, "later", lambda *args, **kwargs: None)
    for name in ("uniform_flat", "rounded_graded"):
        with set_curdoc(doc), counted_walks(doc, monkeypatch) as counts:
            assert app.load_scene(read_preset(name))
        assert counts["recompute"] == 0, (name, counts)
        assert app.controller.wait(120) and app.controller.error == ""
    reachable = set().union(*(root.references() for root in doc.roots))
    assert set(doc.models) == reachable


def test_a_block_that_changes_no_models_walks_nothing(monkeypatch) -> None:
    """Bokeh recomputes when its last freeze ends, changed or not: a batch that adds or
    drops no model ends without the walk; one that sets a property holding a model
    (Bokeh's ``models.invalidate``, no freeze of Panel's) still walks once."""
    from bokeh.models import Div

    doc = Document()
    page, holders, root = _page(doc)
    try:
        with set_curdoc(doc), counted_walks(doc, monkeypatch) as counts:
            with layout_batch.batch(doc):
                page.objects[-1].value = 0.5
            assert counts["recompute"] == 0 and doc.models._freeze_count == 0
            div = Div(text="added by Bokeh alone")
            with layout_batch.batch(doc):
                root.children[0].children = [div]
            assert counts["recompute"] == 1 and div.id in doc.models
        assert "invalidate" not in vars(doc.models)
    finally:
        state._views.pop(root.ref["id"], None)


def test_a_document_without_bokehs_freeze_is_left_as_it_is() -> None:
    """Bokeh's model manager as checked (3.9.2) has ``_push_freeze``; another one is not
    batched, and nothing of it or of Panel is touched."""

    class OtherModels:
        _freeze_count = 0

    class OtherDocument:
        models = OtherModels()

    with layout_batch.batch(OtherDocument()):
        assert not Panel._batch_update
    assert not vars(OtherDocument.models)
