"""No slider of the page shows a tooltip over its handle: each shows its value in its
label or its text box, and a tooltip left on screen after a drag covered the label above
(a users' report)."""

from __future__ import annotations

import panel as pn


def test_no_slider_of_the_page_has_a_tooltip(explorer_app):
    app = explorer_app()
    for index in range(len(app.tabs.sidebar)):  # a served page fills its tabs later
        app.tabs.fill(index)
    sliders = [w for w in app.__panel__().select(pn.widgets.Widget)
               if isinstance(w, (pn.widgets.FloatSlider, pn.widgets.IntSlider,
                                 pn.widgets.EditableFloatSlider,
                                 pn.widgets.EditableIntSlider))]
    assert len(sliders) > 20
    shown = [w for w in sliders if w.tooltips]
    assert shown == []
