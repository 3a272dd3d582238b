"""Bokeh's property defaults worked out once per class (explorer/fixes/property_defaults.py):
the page is the same document, built with far fewer defaults; what is mutable, built per
instance or themed is still Bokeh's own."""

from __future__ import annotations

import json
import re
from typing import Any

import pytest
from bokeh.core.property.bases import ParameterizedProperty
from bokeh.core.property.descriptors import PropertyDescriptor
from bokeh.document import Document
from bokeh.models import Div
from bokeh.settings import settings
from bokeh.themes import Theme

from core.cache import clear_caches
from explorer.fixes import property_defaults


def bokehs_own(patch: pytest.MonkeyPatch) -> None:
    """Put Bokeh's three functions back (inside ``patch``'s context)."""
    patch.setattr(PropertyDescriptor, "_get_default", property_defaults.get_default.__wrapped__)
    patch.setattr(PropertyDescriptor, "has_unstable_default",
                  property_defaults.has_unstable_default.__wrapped__)
    patch.setattr(ParameterizedProperty, "__str__", property_defaults.type_name.__wrapped__)


def page_json(explorer_app, patch: pytest.MonkeyPatch) -> tuple[str, int]:
    """The JSON of a new page (model ids numbered in order of appearance, addresses and
    timings blanked) and how many defaults Bokeh's ``instance_default`` built meanwhile."""
    built = [0]
    default = PropertyDescriptor.instance_default

    def counted(self: PropertyDescriptor, obj: Any) -> Any:
        built[0] += 1
        return default(self, obj)

    patch.setattr(PropertyDescriptor, "instance_default", counted)
    clear_caches()  # (the explorer's results too) both pages solve afresh: the same status
    app = explorer_app()
    doc = Document()
    app.__panel__().server_doc(doc)
    text = json.dumps(doc.to_json(), sort_keys=True, default=str)
    ids: dict[str, str] = {}
    text = re.sub(r"'p\d+'", lambda m: ids.setdefault(m.group(0), f"'m{len(ids)}'"), text)
    # Panel's counted names (six digits and more after ~1e5 objects of one process: the
    # rest of the suite run before this test)
    text = re.sub(r"\b([A-Z][A-Za-z]*)\d{5,}\b", r"\1NNNNN", text)
    text = re.sub(r"0x[0-9a-f]+|\b\d{12,}\b", "ADDRESS", text)  # ids of Python objects
    text = re.sub(r"\d+(\.\d+)? ms", "TIME", text)
    return text, built[0]


def test_the_page_is_the_same_document_with_far_fewer_defaults_built(
        explorer_app, monkeypatch) -> None:
    assert property_defaults.install()  # installed with the explorer: installs once
    with monkeypatch.context() as patch:
        bokehs_own(patch)
        theirs, theirs_built = page_json(explorer_app, patch)
    with monkeypatch.context() as patch:
        ours, ours_built = page_json(explorer_app, patch)
    assert len(ours) > 100_000
    # (not ``ours == theirs``: pytest's diff of two 0.4 MB texts takes minutes)
    first = next((k for k, (a, b) in enumerate(zip(ours, theirs, strict=False)) if a != b), None)
    assert first is None and len(ours) == len(theirs), (
        None if first is None else (ours[first - 60:first + 60], theirs[first - 60:first + 60]))
    # measured: 33,035 defaults built by Bokeh's own, 13,964 here (those built per
    # instance or themed, every mutable one, and each class's constants once)
    assert ours_built < theirs_built / 2, (ours_built, theirs_built)


def test_a_mutable_default_is_still_one_per_read() -> None:
    first, second = Div(), Div()
    assert first.css_classes == second.css_classes == []
    assert first.css_classes is not second.css_classes
    assert not property_defaults.immutable([]) and not property_defaults.immutable((1, []))
    assert property_defaults.immutable((1, "a", None, (2.0, True)))


def test_a_themed_default_reads_its_theme_after_the_class_constant_was_shared() -> None:
    plain = Div()
    constant = plain.margin  # the class's constant (5), now shared
    assert constant is Div().margin
    doc = Document()
    doc.theme = Theme(json={"attrs": {"Div": {"margin": 7}}})
    themed = Div()
    doc.add_root(themed)
    assert themed.margin == 7 != constant
    assert plain.margin == Div().margin == constant


def test_the_server_turns_off_bokehs_developer_diagnostics() -> None:
    from explorer.__main__ import quiet_bokeh_diagnostics

    try:
        assert settings.perform_error_diagnostics()  # on in the tests: they check the code
        quiet_bokeh_diagnostics()
        assert not settings.perform_error_diagnostics()
    finally:
        settings.perform_error_diagnostics.unset_value()
    assert settings.perform_error_diagnostics()
