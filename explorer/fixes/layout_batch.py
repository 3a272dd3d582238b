"""Many layout changes of a page at once: the document's models walked once, not per change.

Panel (checked with 1.9.4) handles each change of a layout's children
(``Panel._update_model``) by two walks over the whole page: Bokeh recomputes the
document's models from its roots (``DocumentModelManager.recompute``), and Panel runs
the root's preprocessing hooks (``Renderable._preprocess``), which find the JS links of
every widget by walking every Panel object and every Bokeh model of the page (each
slider with a text box carries such a link, so the search never ends early). A preset
switch that shows sliders the page has not made before (a profile's amplitude, centre
and width, a shape's parameters, the section of several punches) changes a layout per
slider: py-spy found about half of the server's CPU of such a switch in these walks.

Panel itself defers the hooks while a layout builds its children (``Panel._batch_update``)
and Bokeh defers the recompute while its model manager is frozen. :func:`batch` uses both
for everything done inside it and walks once at the end: the root's hooks once, if a
change inside may have added models (as Panel runs them when a page is first made),
then one recompute. Measured (first switches to six presets with sliders not made yet,
one server per tree, four rounds alternated, quiet 2-core machine): the server's CPU per
switch 357 -> 284 ms, the switch 934 -> 844 ms.

Bokeh recomputes when the last freeze ends whether or not the models changed; a block
that neither froze them (Panel freezes around each change that may add or drop models)
nor told Bokeh of a change of a property that holds models (``models.invalidate``) left
the page's models as they were, and ends without the recompute: a switch between presets
whose sliders the page has made already (~23 ms of the server's CPU a walk of the
complete page, 968 models).
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any


@contextmanager
def batch(doc: Any = None) -> Iterator[None]:
    """Defer the walks of Panel's layout changes on ``doc`` (default: the current
    document) to the end of the block (see the module notes).

    Nested in another batch, in a block where the document's models are frozen already,
    without a document, or with Panel or Bokeh changed from the versions checked, the
    block runs as it would without it.
    """
    from panel.io.state import state
    from panel.layout.base import Panel

    doc = state.curdoc if doc is None else doc
    models = getattr(doc, "models", None)
    # (Panel's and Bokeh's internals as checked; if they changed, nothing is batched)
    usable = (isinstance(getattr(Panel, "_batch_update", None), bool)
              and all(hasattr(models, name) for name in ("_push_freeze", "_pop_freeze",
                                                          "_freeze_count", "invalidate")))
    if not usable or Panel._batch_update or models._freeze_count:
        yield
        return
    # Panel freezes the models around each change that may add or drop models (a
    # layout's children, a property holding models): counted here, so that the hooks
    # run only after such a change
    changes = invalidated = 0
    push, invalidate = models._push_freeze, models.invalidate

    def counted_push() -> None:
        nonlocal changes
        changes += 1
        push()

    def counted_invalidate() -> None:
        nonlocal invalidated
        invalidated += 1
        invalidate()

    Panel._batch_update = True
    push()
    models._push_freeze, models.invalidate = counted_push, counted_invalidate
    try:
        yield
    finally:
        del models._push_freeze, models.invalidate
        Panel._batch_update = False
        try:
            if changes:
                # still frozen: the callbacks the new widgets' links add are new models
                # too, taken in by the one recompute below
                for view, root, view_doc, _comm in list(state._views.values()):
                    if view_doc is doc:
                        view._preprocess(root)
        finally:
            if changes or invalidated:
                models._pop_freeze()  # the one recompute
            else:
                models._freeze_count -= 1  # the models as they were: nothing to walk
