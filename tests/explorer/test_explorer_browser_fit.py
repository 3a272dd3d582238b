"""The Fit tab in a real browser (Debian's Chromium): a readings file made from a solved
scene is uploaded and drawn on the settlement history, Fit runs the back-analysis and the
tab shows the fitted value with its standard error, the histories the forecast band.
Every wait is on a condition in the page."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytestmark = [pytest.mark.browser, pytest.mark.timeout(600)]

from tests.browser_pages import require_browser  # noqa: E402

require_browser()

from core import solve  # noqa: E402
from core.back_analysis import readings_csv  # noqa: E402
from explorer.model import DEFAULT_PRESET, presets  # noqa: E402
from tests.browser_pages import JS_READY, Page, page_fixtures, patience, until  # noqa: E402

# The values of a named source of the page (null when it is not on the page).
JS_VALUES = """([name, column]) => {
  const src = Bokeh.documents[0].get_model_by_name(name);
  return src && src.data[column] ? Array.from(src.data[column]) : null;
}"""
#: Reading times [day after loading] within the default scene's output times.
TIMES = [5.0, 10.0, 20.0, 40.0, 80.0, 160.0, 300.0]


def _readings() -> bytes:
    """Settlements of the page's default scene with its coating 1.5 times as stiff, a
    deterministic scatter of 0.5 %."""
    scene = presets()[DEFAULT_PRESET]
    scene["times"] = TIMES
    scene["coating"][0]["modulus"] *= 1.5
    scatter = 1 + 0.005 * np.array([1, -1, 0.5, -0.5, 1, -1, 0.0])
    result = solve(scene)
    return readings_csv({"time": TIMES, "settlement": list(result.settlement * scatter)}
                        ).encode()


def values(page: Page, name: str, column: str = "v") -> list[float]:
    return page.page.evaluate(JS_VALUES, [name, column]) or []


def _linked_fields(url: str) -> list:
    """The fields to fit a page's address keeps ([] without readings in it)."""
    from urllib.parse import parse_qs, urlparse

    from explorer.model import decode_scene

    fit = parse_qs(urlparse(url).query).get("fit")
    return decode_scene(fit[0])["fields"] if fit else []


server, browser_context, page = page_fixtures(1400, 900)


def test_readings_are_uploaded_drawn_and_fitted(page: Page):
    page.open_tab("Fit")
    upload = page.page.locator(".fit-upload input[type=file]").first
    upload.wait_for(state="attached", timeout=60_000 * patience())
    upload.set_input_files(files=[{"name": "levelling.csv", "mimeType": "text/csv",
                                   "buffer": _readings()}])
    until(lambda: len(values(page, "readings_settlement")) == 7,
          "the readings on the settlement figure", 60,
          lambda: page.pane_text(".fit-readings"))
    assert "7 settlement readings" in page.pane_text(".fit-readings")
    page.page.locator(".fit-field-1 select").first.select_option(
        label="coating 1: Young's modulus [MPa]")
    # the page's address keeps the readings and the field (a link to this view)
    # (read from the page: Playwright's page.url does not follow history.replaceState)
    def href() -> str:
        return page.page.evaluate("() => window.location.href")

    until(lambda: _linked_fields(href())[:1] == ["coating[0].modulus"],
          "the readings and the field in the page's address",
          describe=lambda: _linked_fields(href()))
    link = href()
    run = page.page.locator(".fit-run button").first
    until(lambda: run.is_enabled(), "the Fit button enabled")
    run.click()
    until(lambda: "±" in page.pane_text(".fit-table"), "the fitted values", 240,
          lambda: page.pane_text(".fit-status"))
    table = page.pane_text(".fit-table")
    # no deviations in the readings: the noise estimated from the scatter, no chi^2
    assert "coating 1: Young's modulus" in table and "MPa" in table
    assert "noise estimated from the scatter about the fit, settlement " in table
    assert "χ²/dof" not in table
    assert "Done: fitted" in page.pane_text(".fit-status")
    until(lambda: len(values(page, "forecast_settlement", "upper")) > 0, "the forecast band")
    lower = values(page, "forecast_settlement", "lower")
    upper = values(page, "forecast_settlement", "upper")
    assert all(lo <= hi for lo, hi in zip(lower, upper, strict=True))
    # applied, the fitted scene is solved by the server's workers, and the report they
    # write of it carries the fit (sent to them by pickle)
    page.page.locator(".fit-apply button").first.click()
    page.open_tab("Files")

    def report() -> str:
        with page.page.expect_download(timeout=60_000 * patience()) as info:
            page.page.get_by_text("Printable report (HTML)").first.click()
        return Path(info.value.path()).read_text()

    text = ""

    def fitted_report() -> bool:
        nonlocal text
        text = report()
        return "<h2>Back-analysis</h2>" in text

    until(fitted_report, "the report of the applied fit", 120)
    assert "coating[0].modulus" in text and "7 (settlement [m])" in text

    # the link opens the readings on the histories with the field chosen, not yet fitted
    page.page.goto(link, timeout=30_000 * patience())
    page.page.wait_for_function(JS_READY, timeout=60_000 * patience())
    page.open_tab("Fit")
    until(lambda: len(values(page, "readings_settlement")) == 7,
          "the link's readings on the settlement figure", 60,
          lambda: page.pane_text(".fit-readings"))
    field = page.page.locator(".fit-field-1 select").first
    until(lambda: "modulus" in field.input_value(), "the link's field",
          describe=field.input_value)
    assert "±" not in page.pane_text(".fit-table")  # not fitted again
    assert page.errors == []
