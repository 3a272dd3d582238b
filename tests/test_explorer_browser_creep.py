"""The design-code creep inputs and the phi(t, t0) plot in a real browser (Chromium)."""

from __future__ import annotations

import shutil
import tempfile
from collections.abc import Iterator

import pytest

from benchmarks.serving import CHROMIUM, CHROMIUM_ARGS, ExplorerProcess

pytestmark = [pytest.mark.browser, pytest.mark.timeout(300)]

from tests.browser_pages import require_browser  # noqa: E402

require_browser()

import playwright.sync_api as playwright_api  # noqa: E402

from tests.browser_pages import Page, _app_tracebacks  # noqa: E402

JS_PHI_COUNT = ("() => Bokeh.documents[0].get_model_by_name('creep_phi_source')"
                ".data.phi.length")


@pytest.fixture(scope="module")
def page() -> Iterator[Page]:
    profile = tempfile.mkdtemp(prefix="explorer-chromium-")
    with ExplorerProcess(ready_timeout=180) as explorer, \
            playwright_api.sync_playwright() as p:
        context = p.chromium.launch_persistent_context(
            profile, executable_path=CHROMIUM, headless=True, args=CHROMIUM_ARGS,
            viewport={"width": 1400, "height": 900})
        page = Page(context, explorer.url)
        yield page
        page.close()
        context.close()
    shutil.rmtree(profile, ignore_errors=True)
    output = explorer.output()
    assert not _app_tracebacks(output), output


def test_a_code_model_shows_its_inputs_and_phi_curve_and_names_a_bad_field(page: Page):
    page.open_tab("Base")
    select = page.page.locator(".creep-select select").first
    select.wait_for(timeout=30_000)
    select.select_option(label="concrete, Eurocode 2")
    page.page.wait_for_function(f"() => ({JS_PHI_COUNT})() > 100", timeout=60_000)
    assert "Eurocode 2" in page.title("creep_phi_figure")
    page.type_into(".code-rh", "20")
    page.page.wait_for_function(f"() => ({JS_PHI_COUNT})() === 0", timeout=60_000)
    # the refusal names the field beside the emptied plot (locators pierce shadow roots)
    page.page.locator(".code-creep-error", has_text="base.creep.relative_humidity").first \
        .wait_for(timeout=60_000)
    assert not page.errors
