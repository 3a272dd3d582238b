"""The Study tab's contact width in a real browser (Debian's Chromium): on the lift-off
preset a study of the eccentricity from 0.6 m writes into its CSV the width the page's
readout gives at e = 0.6 m, 1.349 m of the 2 m (the length of the contact set), not the
2 m where q >= 0. Every wait is on a condition in the page."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest

pytestmark = [pytest.mark.browser, pytest.mark.timeout(600)]

from tests.browser_pages import require_browser  # noqa: E402

require_browser()

from tests.browser_pages import (  # noqa: E402
    JS_SHOWN,
    Page,
    page_fixtures,
    patience,
    until,
)

KEY = "eccentric_footing_liftoff"
JS_STUDY_Y = """() => {
  const src = Bokeh.documents[0].get_model_by_name('study_source');
  return src && src.data.y ? Array.from(src.data.y) : null;
}"""

server, browser_context, page = page_fixtures(1400, 900, accept_downloads=True)


def test_the_study_csv_holds_the_width_the_readout_gives(page: Page):
    from explorer.model import preset_label, presets

    page.page.locator(".preset-select select").first.select_option(
        label=preset_label(KEY, presets()[KEY]))
    # the scene on screen (e = 0.6 m) at its last time, 1000 days
    until(lambda: page.page.evaluate(JS_SHOWN, "contact 1.349 m of 2 m"), "the readout",
          timeout=120)
    page.open_tab("Study")
    page.page.locator(".study-run button").first.wait_for(timeout=60_000 * patience())
    page.page.locator(".study-p1-field select").first.select_option(
        label="loading: eccentricity e = M/P [m]")
    # the server answers a new field with its first range (0 to 2e = 1.2 m, 9 points): a
    # value typed before that answer arrives is overwritten by it, so wait for it first
    boxes = {css: page.page.locator(f"{css} input").first
             for css in (".study-p1-from", ".study-p1-to", ".study-p1-count")}
    until(lambda: (float(boxes[".study-p1-to"].input_value() or "nan") == 1.2
                   and boxes[".study-p1-count"].input_value() == "9"),
          "the eccentricity's first range", describe=lambda: {
              css: box.input_value() for css, box in boxes.items()})
    typed = {".study-p1-from": "0.6", ".study-p1-to": "0.8", ".study-p1-count": "2"}
    for css, value in typed.items():
        page.type_into(css, value)
    until(lambda: all(float(boxes[css].input_value() or "nan") == float(value)
                      for css, value in typed.items()), "the range typed",
          describe=lambda: {css: box.input_value() for css, box in boxes.items()})
    page.page.locator(".study-run button").first.click()
    until(lambda: len(page.page.evaluate(JS_STUDY_Y) or []) == 2, "the chart of 2 points",
          240, lambda: page.pane_text(".study-status"))
    # the CSV is written on a thread when the result comes: its button is offered then
    csv_button = page.page.locator(".study-csv button").first
    until(lambda: csv_button.is_enabled(), "the study's CSV offered")
    with page.page.expect_download(timeout=60_000 * patience()) as info:
        csv_button.click()
    lines = [line for line in Path(info.value.path()).read_text().splitlines()
             if not line.startswith("#")]
    header, *rows = csv.reader(lines)
    assert header[0] == "loading_eccentricity_e_m"
    width = header.index("contact_width_m")
    assert sorted({float(row[0]) for row in rows}) == [0.6, 0.8]
    at_06 = [row for row in rows if float(row[0]) == 0.6]
    assert len(at_06) == 20  # the preset's output times
    assert f"{float(at_06[-1][width]):.3f}" == "1.349"  # at 1000 days, as the readout
    assert f"{float(at_06[0][width]):.3f}" == "1.306"   # at loading
    assert page.errors == []
