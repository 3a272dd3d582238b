"""The value axes kept while the data fit, the legends' columns and the page's BokehJS fix."""

from __future__ import annotations

import numpy as np
import pytest
from bokeh.document import Document
from bokeh.models import Range1d

from explorer.fixes import bokeh_fixes
from explorer.plots.bokeh_data import KEEP_SHARE, MARGIN_SHARE, steady_range


def test_a_value_axis_is_kept_while_the_data_fit_and_refitted_when_not() -> None:
    rng = Range1d(0, 1)
    assert steady_range(rng, np.array([200.0, 520.0]))
    span = 320.0
    assert (rng.start, rng.end) == pytest.approx((200 - MARGIN_SHARE * span,
                                                  520 + MARGIN_SHARE * span))
    # the reset tool returns to it
    assert (rng.reset_start, rng.reset_end) == (rng.start, rng.end)
    # a load step of 1 %: the axis stays (no message, no new ticks)
    assert not steady_range(rng, np.array([202.0, 525.2]))
    # out of the range: refitted
    assert steady_range(rng, np.array([200.0, 600.0]))
    assert rng.end == pytest.approx(600 + MARGIN_SHARE * 400)
    # the data shrink below half of the range: refitted to them
    assert steady_range(rng, np.array([0.0, 0.3 * (rng.end - rng.start)]))
    assert rng.end - rng.start < 1 / KEEP_SHARE * 0.3 * 400 * 1.5
    # nothing finite: left alone
    before = (rng.start, rng.end)
    assert not steady_range(rng, np.array([np.nan]))
    assert (rng.start, rng.end) == before


def test_a_constant_history_gets_room_around_its_value() -> None:
    rng = Range1d(0, 1)
    steady_range(rng, np.full(40, 500.0))
    assert rng.start < 500 < rng.end and rng.end - rng.start == pytest.approx(120.0)
    # a force step of 1.2 %: kept
    assert not steady_range(rng, np.full(40, 506.0))
    zero = Range1d(5, 6)
    steady_range(zero, np.zeros(40))   # a tilt of zero throughout: -1.2 .. 1.2
    assert (zero.start, zero.end) == pytest.approx((-1.2, 1.2))


def test_the_style_fix_is_sent_with_a_served_document() -> None:
    doc = Document()
    assert bokeh_fixes.install(doc)
    callbacks = doc.callbacks._js_event_callbacks["document_ready"]
    flags = ("__same_text_skipped", "__once_per_frame", "__layout_once",
             "__no_css_variables", "__inline_position", "__read_once", "__whole",
             "__shown_only")
    # each fix carries its own flag; the re-render fix (third) asks for the deferred
    # layout of the second, which must come before it
    assert [[flag in c.code for flag in flags] for c in callbacks] == [
        [i == j or (i, j) == (2, 1) for j in range(len(flags))] for i in range(len(flags))]
    assert not bokeh_fixes.install(None)


def test_no_style_sheet_of_the_page_defines_bokeh_css_variables() -> None:
    """The page's BokehJS no longer reads ``--bk-`` CSS variables for colours and line
    styles (explorer/fixes/bokeh_fixes.py): right only while nothing on the page defines
    one. Its styles come from Bokeh, Panel and the explorer: their style sheets, page
    templates, and the styles their code writes (a ``styles`` dict, ``setProperty``, a
    registered ``@property``). No file of Bokeh or Panel names such a variable (the prefix
    itself stands in BokehJS, where it is read), nor does the explorer but for the fix's
    own module; a version that starts to, fails here, and the fix must then go."""
    import re
    from pathlib import Path

    import bokeh
    import panel

    import explorer

    named = re.compile(rb"%s[\w-]" % re.escape(bokeh_fixes.BOKEH_CSS_VARIABLE_PREFIX.encode()))
    fix = Path(bokeh_fixes.__file__).resolve()
    found, read = [], 0
    for package in (bokeh, panel, explorer):
        for path in Path(package.__file__).resolve().parent.rglob("*"):
            if not path.is_file() or path == fix or path.suffix in {".pyc", ".png", ".ico"}:
                continue
            read += 1
            match = named.search(path.read_bytes())
            if match:
                found.append(f"{path}: {match.group().decode()}")
    assert read > 1000 and found == []


def test_lines_and_text_columns_are_resent_only_when_they_change() -> None:
    """The punches' histories are one multi-line source (a column of lines, a column of
    colours and labels): the same lines again are not resent, a changed row is."""
    from bokeh.models import ColumnDataSource

    from explorer.plots.bokeh_data import set_data

    line = np.linspace(0.0, 1.0, 200, dtype=np.float32)
    data = {"xs": [line, line], "ys": [line, 2 * line], "label": ["punch 1", "punch 2"]}
    src = ColumnDataSource({"xs": [], "ys": [], "label": []})
    assert set_data(src, data)
    same = {"xs": [line.copy(), line.copy()], "ys": [line.copy(), 2 * line],
            "label": ["punch 1", "punch 2"]}
    assert not set_data(src, same)
    assert set_data(src, dict(same, ys=[line, 3 * line]))
    assert set_data(src, dict(same, label=["punch 1", "punch 3"]))
    assert set_data(src, {"xs": [], "ys": [], "label": []})
    assert not set_data(src, {"xs": [], "ys": [], "label": []})


def test_only_the_columns_that_changed_are_sent() -> None:
    """A slider step changes the pressure, not the points it is drawn at: the page gets
    the changed column alone (one message and buffer fewer a column kept), and all of
    them when the lengths change."""
    from bokeh.document.events import ColumnDataChangedEvent
    from bokeh.models import ColumnDataSource

    from explorer.plots.bokeh_data import set_data

    x = np.linspace(-1.0, 1.0, 201, dtype=np.float32)
    src = ColumnDataSource({"x": x, "q": x * x})
    doc = Document()
    doc.add_root(src)
    events: list = []
    doc.on_change(events.append)
    assert set_data(src, {"x": x.copy(), "q": 2 * x * x})
    assert len(events) == 1 and isinstance(events[0], ColumnDataChangedEvent)
    assert events[0].cols == ["q"]
    np.testing.assert_array_equal(src.data["x"], x)
    np.testing.assert_array_equal(src.data["q"], 2 * x * x)
    shorter = np.linspace(-1.0, 1.0, 101, dtype=np.float32)
    assert set_data(src, {"x": shorter, "q": shorter})
    # the whole data (cols None: every column), of one length
    assert isinstance(events[-1], ColumnDataChangedEvent) and events[-1].cols is None
    assert len(src.data["x"]) == len(src.data["q"]) == 101
