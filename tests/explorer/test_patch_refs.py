"""The explorer's patch messages (explorer/fixes/patch_refs.py) are Bokeh's own, written
without listing every model of the page for each message."""

from __future__ import annotations

import json
from typing import Any

from bokeh.document import Document
from bokeh.models import Column, Div
from bokeh.protocol import Protocol
from bokeh.protocol.messages.patch_doc import patch_doc

from core.presets import read_preset
from explorer.fixes import patch_refs


def _plain(content: Any) -> str:
    """A message's content as text, each binary buffer by its bytes (a buffer's id is new
    in each message)."""
    return json.dumps(content, sort_keys=True,
                      default=lambda buffer: bytes(buffer.data).hex())


def _both(events: list[Any], doc: Document) -> tuple[Any, Any]:
    """The message Bokeh writes for ``events`` and the one the fix writes, each from the
    same state of the document (writing one marks the new models it sent as sent)."""
    new = set(doc.models._new_models)
    bokeh = patch_doc.create.__wrapped__(events)  # Bokeh's own create
    after_bokeh = set(doc.models._new_models)
    doc.models._new_models = set(new)
    ours = Protocol().create("PATCH-DOC", events)
    assert set(doc.models._new_models) == after_bokeh
    return bokeh, ours


def test_the_messages_are_bokehs(explorer_app) -> None:
    assert patch_refs.install() and hasattr(patch_doc.create, "__wrapped__")
    app = explorer_app()
    doc = Document()
    app.__panel__().server_doc(doc)
    doc.models.flush_synced()  # the page has every model now
    events: list[Any] = []
    doc.on_change(events.append)
    compared = 0
    sent: list[str] = []

    def compare() -> None:
        nonlocal compared
        batch = [e for e in events if hasattr(e, "to_serializable")]
        events.clear()
        for k in range(0, len(batch), 7):  # messages of a few events, as the page sends
            bokeh, ours = _both(batch[k:k + 7], doc)
            assert _plain(ours.content) == _plain(bokeh.content)
            assert len(ours.buffers) == len(bokeh.buffers)
            compared += 1
            sent.append(_plain(ours.content))

    # a load step: new data in the figures
    force = app.state.loading.histories["force"]
    force.value = force.value * 1.1
    assert app.controller.wait(60) and app.controller.error == ""
    compare()
    # another preset: a layered drawing, new widgets; and a model the page has not had
    assert app.load_scene(read_preset("stepped_punch"))
    assert app.controller.wait(120) and app.controller.error == ""
    column = next(m for m in doc.models if isinstance(m, Column) and m.children)
    column.children = [*column.children, Div(text="a new part")]
    compare()
    assert compared >= 3
    assert any("a new part" in text for text in sent)  # a model the page had not had went out whole



def _page_doc() -> tuple[Document, dict[str, str]]:
    """A document as a page has it (a column of two texts, every model sent), and the ids
    of its column and texts."""
    doc = Document()
    first, second = Div(text="a"), Div(text="b")
    column = Column(children=[first, second])
    doc.add_root(column)
    doc.models.flush_synced()
    return doc, {"c1": column.id, "d1": first.id, "d2": second.id}


def _state(doc: Document) -> Any:
    """What the document holds: its column's texts, its texts, the texts not yet sent."""
    [column] = doc.roots
    texts = sorted(m.text for m in doc.models if isinstance(m, Div))
    return ([m.text for m in column.children], texts,
            sorted(m.text for m in doc.models._new_models if isinstance(m, Div)))


def test_the_pages_messages_are_read_as_bokeh_reads_them() -> None:
    """What the page sends: a changed property, a model new to the server (its whole
    object), a change of a model the server has just removed (dropped), of one it never
    had (an error): the same document after each, read either way."""
    from bokeh.core.serialization import UnknownReferenceError
    from bokeh.document.document import Document as Doc

    assert patch_refs.install() and hasattr(Doc.apply_json_patch, "__wrapped__")
    read = {"bokeh": Doc.apply_json_patch.__wrapped__, "ours": Doc.apply_json_patch}
    states: dict[str, list[Any]] = {"bokeh": [], "ours": []}
    for way in read:
        doc, ids = _page_doc()
        text = {"kind": "ModelChanged", "model": {"id": ids["d1"]}, "attr": "text",
                "new": "A"}
        added = {"kind": "ModelChanged", "model": {"id": ids["c1"]}, "attr": "children",
                 "new": [{"id": ids["d1"]}, {"type": "object", "name": "Div",
                                             "id": "from-the-page",
                                             "attributes": {"text": "new"}}]}
        gone = {"kind": "ModelChanged", "model": {"id": ids["d2"]}, "attr": "text",
                "new": "B"}
        never = {"kind": "ModelChanged", "model": {"id": "never-had"}, "attr": "text",
                 "new": "?"}
        for event in (text, added, gone):
            read[way](doc, {"events": [event]})
            states[way].append(_state(doc))
        try:
            read[way](doc, {"events": [never]})
        except UnknownReferenceError:
            states[way].append("refused")
    assert states["ours"] == states["bokeh"]
    assert states["ours"][1] == (["A", "new"], ["A", "new"], [])
    assert states["ours"][-1] == "refused"
