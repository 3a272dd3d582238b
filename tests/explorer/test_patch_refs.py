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
