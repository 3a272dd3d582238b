"""A load slider's move reaches the state before the slider's text box follows it
(explorer/views/widgets.py, ``EditableSlider.watch_drag_first``), and every way of setting the
value still ends with the state, the slider and the text box agreeing."""

from __future__ import annotations

import param

from explorer.views.widgets import Binding, slider


class _Target(param.Parameterized):
    value = param.Number(0.0)


def _bound() -> tuple[_Target, object, list[tuple[float, float]]]:
    target = _Target()
    binding = Binding()
    widget = binding.add("value", slider("v", 0.0, 10.0, 0.1), live=True)
    binding.bind(target)
    seen: list[tuple[float, float]] = []  # (state, text box) when the state changed
    target.param.watch(lambda e: seen.append((e.new, widget._value_edit.value)), "value")
    return target, widget, seen


def test_a_drag_step_reaches_the_state_before_the_text_box() -> None:
    target, widget, seen = _bound()
    widget._slider.value = 3.0  # a step of the slider in the page
    assert seen == [(3.0, 0.0)]  # the text box had not followed yet: the solve goes first
    assert target.value == widget.value == widget._value_edit.value == 3.0


def test_typed_and_programmatic_values_keep_everything_in_line() -> None:
    target, widget, seen = _bound()
    widget._value_edit.value = 5.0  # typed into the box
    assert target.value == widget.value == widget._slider.value == 5.0
    target.value = 7.0  # a preset, a file, a link
    assert widget.value == widget._slider.value == widget._value_edit.value == 7.0
    assert [state for state, _ in seen] == [5.0, 7.0]  # each change once
