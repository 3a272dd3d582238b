"""The explorer's walk over a page's models (explorer/fixes/model_walk.py) finds what
Bokeh's own walk finds, in the same order, building far fewer defaults."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

import pytest
from bokeh.core.properties import Instance, List
from bokeh.core.property.descriptors import PropertyDescriptor
from bokeh.document import Document
from bokeh.model import Model, util
from bokeh.models import Div

from core.presets import read_preset
from explorer.fixes import model_walk

BOKEH_WALK = getattr(util.visit_immediate_value_references, "__wrapped__",
                     util.visit_immediate_value_references)


def walk(roots: list[Model], visit: Callable[..., None], monkeypatch: pytest.MonkeyPatch
         ) -> tuple[list[str], int]:
    """The ids of the models reachable from ``roots`` (Bokeh's collection, with ``visit``
    as its walk over one model's properties) and the defaults built meanwhile."""
    built = [0]
    default = PropertyDescriptor.instance_default

    def counted(self: PropertyDescriptor, obj: Any) -> Any:
        built[0] += 1
        return default(self, obj)

    with monkeypatch.context() as patch:
        patch.setattr(util, "visit_immediate_value_references", visit)
        patch.setattr(PropertyDescriptor, "instance_default", counted)
        ids = [model.id for model in util.collect_models(*roots)]
    return ids, built[0]


@pytest.fixture
def page(explorer_app) -> Iterator[tuple[Any, Document]]:
    """A complete page (every tab filled, as outside a server) in a document."""
    app = explorer_app()
    doc = Document()
    app.__panel__().server_doc(doc)
    yield app, doc


def test_the_walk_finds_bokehs_models_in_bokehs_order(page, monkeypatch) -> None:
    app, doc = page
    # the page as served, a pin drawn, then another preset's (a layered drawing)
    app.pins.pin()
    assert app.controller.wait(60) and app.controller.error == ""
    for step in ("page", "preset"):
        if step == "preset":
            assert app.load_scene(read_preset("stepped_punch"))
            assert app.controller.wait(120) and app.controller.error == ""
        ours, ours_built = walk(doc.roots, model_walk.visit_immediate_value_references,
                                monkeypatch)
        bokehs, bokehs_built = walk(doc.roots, BOKEH_WALK, monkeypatch)
        assert ours == bokehs, step
        assert len(ours) > 500, (step, len(ours))
        # measured here: 1,009 and 1,067 models; Bokeh's walk built 1,467 and 1,538
        # defaults, this one none (on a served page, whose document has a theme, 3,580
        # and 854: the themed properties are read as Bokeh reads them)
        assert ours_built < bokehs_built / 3, (step, ours_built, bokehs_built)


def test_a_constant_default_that_refers_to_a_model_is_still_read() -> None:
    shared = Div(text="shared by every holder")

    class Holder(Model):
        kids = List(Instance(Model), default=[shared])

    assert "kids" not in model_walk.skippable(Holder)
    found: list[Model] = []
    model_walk.visit_immediate_value_references(Holder(), found.append)
    assert shared in found


def test_the_explorer_installs_the_walk() -> None:
    import explorer.app  # noqa: F401 - installs it

    assert util.visit_immediate_value_references is model_walk.visit_immediate_value_references
    assert model_walk.install()
