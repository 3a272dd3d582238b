"""A slider that updates on release, dragged while solves are slow: the page says that the
plots wait for the release, and stops saying it once the release applies."""

from __future__ import annotations

import param
import pytest


def test_a_held_drag_step_is_said_and_the_release_clears_it(monkeypatch, explorer_app) -> None:
    from explorer import app as page

    app = explorer_app("uniform_flat", solved=True)
    age = app.base_tab.age
    before = app.state.base.age_at_loading
    assert not app.results.held.visible
    monkeypatch.setitem(app.controller.view.info, "cpu_seconds", 3 * page.LIVE_SOLVE_S)
    age.value = before + 10.0               # a drag step, slow solves: held
    assert app.state.base.age_at_loading == before
    assert app.results.held.visible
    took = f"{1e3 * 3 * page.LIVE_SOLVE_S:.0f}"
    assert app.results.held.object == (
        f"Solves are too slow to follow a dragged slider (the last one took {took} ms): the "
        "plots show the last result and update when you release it.")
    with param.edit_constant(age):           # the release (set by the browser)
        age.value_throttled = before + 10.0
    assert app.state.base.age_at_loading == pytest.approx(before + 10.0)
    assert not app.results.held.visible


def test_fast_solves_and_values_shown_from_the_state_say_nothing(monkeypatch,
                                                                 explorer_app) -> None:
    from explorer import app as page

    app = explorer_app("uniform_flat", solved=True)
    with monkeypatch.context() as slow:     # every solve slow, the new one included
        slow.setattr(app.controller, "solved_within", lambda seconds: False)
        app.state.base.age_at_loading = 90.0     # the slider follows the state: no drag
        assert app.base_tab.age.value == 90.0 and not app.results.held.visible
    monkeypatch.setitem(app.controller.view.info, "cpu_seconds",
                        0.5 * page.LIVE_SOLVE_S)
    app.base_tab.age.value = 120.0           # fast solves: the step applies at once
    assert app.state.base.age_at_loading == 120.0 and not app.results.held.visible
