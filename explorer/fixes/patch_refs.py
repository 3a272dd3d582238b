"""Bokeh's patch messages, written and read without listing every model the page has.

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

The page's own messages (a slider's value, its release) are read the same way round:
``Document.apply_json_patch`` first makes a dict of every model of the document by its id
(``Deserializer(list(doc.models))``, a property read per model), ~1.1 ms for the page's
~850 models in the served explorer, twice a key step (measured in the server around each
call). Here the dict is a copy of the document's own (ids to models, the same pairs), made
without visiting the models; the rest is Bokeh's method as written (its body is checked
before it is replaced; a test reads the same messages both ways). Sampled with py-spy
over 40 force key steps of the default scene in Chromium: the reading's share of the
server's samples 10 % (58 of ~580) -> 2.5 % (9 of 364).
"""

from __future__ import annotations

import ast
import hashlib
import importlib
import inspect
import logging
from typing import Any

log = logging.getLogger(__name__)

_INSTALLED = False
#: Whether the reading of messages was replaced too (see :func:`install`).
_READING = False


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


#: sha256 of the body of ``Document.apply_json_patch`` as Bokeh 3.9.2 has it (docstring
#: left out, each statement as ``ast.unparse`` writes it).
_CHECKED_APPLY = "9b93b0a23e45da4f9b121828c6514f4965e73de40edb98032e864f624fb58356"


def _method_body_digest(module: Any, class_name: str, name: str) -> str | None:
    """sha256 of method ``name`` of class ``class_name`` in ``module``, as for
    :data:`_CHECKED_APPLY`; None when it cannot be read."""
    try:
        tree = ast.parse(inspect.getsource(module))
    except (OSError, TypeError, SyntaxError):
        return None
    for node in tree.body:
        if isinstance(node, ast.ClassDef) and node.name == class_name:
            for item in node.body:
                if isinstance(item, ast.FunctionDef) and item.name == name:
                    body = item.body
                    if (body and isinstance(body[0], ast.Expr)
                            and isinstance(body[0].value, ast.Constant)):
                        body = body[1:]
                    text = "\n".join(ast.unparse(statement) for statement in body)
                    return hashlib.sha256(text.encode()).hexdigest()
    return None


def _install_reading() -> bool:
    """Replace ``Document.apply_json_patch`` with Bokeh's method reading the references
    from a copy of the document's dict of models; False (nothing replaced, a warning) if
    Bokeh's method or its model registry differ from the ones checked."""
    from bokeh.core.serialization import Deserializer, UnknownReferenceError
    from bokeh.document.events import DocumentPatchedEvent

    # (the package's name document is the class's module, as bokeh.document re-exports it)
    module = importlib.import_module("bokeh.document.document")

    Document = module.Document
    if hasattr(Document.apply_json_patch, "__wrapped__"):
        return True  # replaced already
    models = Document().models
    if (_method_body_digest(module, "Document", "apply_json_patch") != _CHECKED_APPLY
            or not isinstance(getattr(models, "_models", None), dict)
            or not isinstance(getattr(Deserializer(), "_references", None), dict)):
        log.warning("Bokeh's reading of patch messages has changed; it lists every model of "
                    "the page for each message, as Bokeh does")
        return False
    original = Document.apply_json_patch

    class DocumentDeserializer(Deserializer):
        """A deserializer whose references are those of a document's models (a copy of
        its registry's dict: decoding adds the models a message brings)."""

        def __init__(self, models: Any, *, setter: Any = None) -> None:
            super().__init__(None, setter=setter)
            self._references = dict(models._models)

    def apply_json_patch(self: Any, patch_json: Any, *, setter: Any = None) -> None:
        # Bokeh's apply_json_patch (3.9.2) with the references copied, not rebuilt
        deserializer = DocumentDeserializer(self.models, setter=setter)
        try:
            patch = deserializer.deserialize(patch_json)
        except UnknownReferenceError as error:
            if self.models.seen(error.id):
                log.debug("Dropping a patch because it contains a previously known "
                          "reference (id=%r): a model updated on one side while it was "
                          "being removed on the other", error.id)
                return
            raise
        events = patch["events"]
        assert isinstance(events, list)
        for event in events:
            DocumentPatchedEvent.handle_event(self, event, setter)
        self.models.flush_synced(lambda model: not deserializer.has_ref(model))

    apply_json_patch.__wrapped__ = original  # type: ignore[attr-defined]
    Document.apply_json_patch = apply_json_patch
    return True


def install() -> bool:
    """Replace Bokeh's ``PATCH-DOC`` message creation and reading once per process; False
    if Bokeh's internals differ (what differs is left as it is, and a warning says so)."""
    global _INSTALLED, _READING
    if _INSTALLED:
        return _READING
    _READING = _install_reading()

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
    return _READING
