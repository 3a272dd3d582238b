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


def test_every_slider_box_shows_its_value_to_significant_digits(explorer_app):
    """A box of a fixed number of decimals showed a creep rate of 0.0002 /day, a C∞ of
    1e-5 /GPa or a coating 0.0001 mm thick as "0" while the value was solved (and a moment
    of 777.48 as "777.4800"); every box now shows SIGNIFICANT_DIGITS significant digits,
    trailing zeros dropped. The sliders of the punch shapes and variations are made when
    first shown."""
    import gc

    from bokeh.models import CustomJSTickFormatter

    from explorer.views.widgets import SIGNIFICANT_DIGITS, LazySlider

    app = explorer_app()
    for index in range(len(app.tabs.sidebar)):
        app.tabs.fill(index)
    for lazy in [o for o in gc.get_objects() if isinstance(o, LazySlider)]:
        lazy.visible = True
    boxes = [w for w in app.__panel__().select(pn.widgets.EditableFloatSlider)]
    made = [lazy.widget for lazy in gc.get_objects() if isinstance(lazy, LazySlider)]
    boxes += [w for w in made if w is not None]
    assert len(boxes) > 30
    fixed = [w.name for w in boxes if not (isinstance(w.format, CustomJSTickFormatter)
                                            and f"toPrecision({SIGNIFICANT_DIGITS})"
                                            in w.format.code)]
    assert fixed == []
