"""The explorer in a real browser: Debian's Chromium driven by Playwright.

One server (``python -m explorer``) for the module, on a free port, and one fresh browser
profile. Each test opens its own page (its own session). The checks read what the user
sees: DOM text for readouts and messages, and the data of the named Bokeh sources for
the plots (a canvas has no text to read).
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import pytest

pytestmark = [pytest.mark.browser, pytest.mark.timeout(300)]

from tests.browser_pages import patience, require_browser  # noqa: E402

require_browser()

from tests.browser_pages import Page, page_fixtures, until  # noqa: E402

ARTIFACTS = Path(__file__).resolve().parent / "artifacts"


server, browser_context, page = page_fixtures(1500, 1300)


def test_page_loads_without_errors_and_screenshot(page: Page):
    body = page.page.content()
    assert "Traceback" not in body
    assert page.errors == []
    assert len(page.q()) > 100
    assert float(page.text(".readout-settlement")) > 0
    # the default scene: force and moment given, settlement and tilt computed
    assert page.title("settlement_figure").endswith("computed")
    assert page.title("force_figure").endswith("given")
    assert "full contact" in page.text(".ok-contact_lost")
    status = page.text(".solve-status")
    assert "Solved in" in status or "solved before" in status
    ARTIFACTS.mkdir(exist_ok=True)
    # the canvases paint in the next animation frames: wait for two of them
    page.page.evaluate("() => new Promise(done => requestAnimationFrame("
                       "() => requestAnimationFrame(done)))")
    page.page.screenshot(path=str(ARTIFACTS / "explorer.png"), full_page=True)
    assert (ARTIFACTS / "explorer.png").stat().st_size > 20_000


def test_moving_a_load_slider_changes_settlement_and_pressure(page: Page):
    settlement = page.text(".readout-settlement")
    force = page.text(".readout-force")
    q_before = page.q()
    handle = page.page.locator(".load-0-value .noUi-handle").first
    box = handle.bounding_box()
    assert box is not None
    # drag the force slider to the right, as a user would
    page.page.mouse.move(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
    page.page.mouse.down()
    for dx in range(10, 80, 10):
        page.page.mouse.move(box["x"] + box["width"] / 2 + dx, box["y"] + box["height"] / 2)
        time.sleep(0.05)
    page.page.mouse.up()
    new_settlement = page.wait_text_change(".readout-settlement", settlement)
    assert float(new_settlement) > float(settlement)
    assert float(page.text(".readout-force")) > float(force)
    page.page.wait_for_function(
        "(old) => { const q = Bokeh.documents[0].get_model_by_name('q_source').data.q;"
        " return q.length > 0 && Math.abs(q[Math.floor(q.length / 2)] -"
        " old[Math.floor(old.length / 2)]) > 1e-9; }", arg=q_before, timeout=60_000 * patience())
    assert page.errors == []


def test_switching_the_statement_changes_the_unknowns(page: Page):
    assert page.title("force_figure").endswith("given")
    page.page.locator(".statement-select select").first.select_option(
        "settlement + tilt given")
    page.page.wait_for_function(
        "() => Bokeh.documents[0].get_model_by_name('force_figure').title.text"
        ".endsWith('computed')", timeout=60_000 * patience())
    assert page.title("moment_figure").endswith("computed")
    assert page.title("settlement_figure").endswith("given")
    assert page.title("tilt_figure").endswith("given")
    assert "(computed)" in page.page.locator("tr:has(.readout-force)").first.inner_text()
    assert page.page.get_by_text("Given settlement δ").count() >= 1
    assert page.errors == []


def test_a_bad_value_shows_its_message_and_keeps_the_plots(page: Page):
    q_before = page.q()
    settlement = page.text(".readout-settlement")
    page.open_tab("Coating")
    page.type_into(".coating-thickness", "-2")
    alert = page.page.locator(".solve-error").first
    alert.wait_for(state="visible", timeout=60_000 * patience())
    message = page.pane_text(".solve-error")
    assert "coating[0].thickness" in message and "must be > 0" in message
    assert page.q() == q_before
    assert page.text(".readout-settlement") == settlement
    # the session keeps working
    page.type_into(".coating-thickness", "15")
    alert.wait_for(state="hidden", timeout=60_000 * patience())
    page.wait_text_change(".readout-settlement", settlement)
    assert "Traceback" not in page.page.content()
    assert page.errors == []


def test_a_tiny_coating_value_reads_in_its_box_as_solved(page: Page):
    """A coating 0.0001 mm thick was solved while its box read "0" (two decimals), and a
    modulus of 1e-6 MPa likewise: the boxes show significant digits."""
    settlement = page.text(".readout-settlement")
    page.open_tab("Coating")
    page.type_into(".coating-thickness", "0.0001")
    page.wait_text_change(".readout-settlement", settlement)
    box = page.page.locator(".coating-thickness input").first
    assert box.input_value() == "0.0001"
    page.type_into(".coating-thickness", "12.3456789")
    until(lambda: box.input_value() == "12.345679", "12.345679 in the thickness box",
          describe=box.input_value)
    page.type_into(".coating-thickness", "15")
    until(lambda: box.input_value() == "15", "15 in the thickness box",
          describe=box.input_value)
    assert page.errors == []


def test_a_bad_link_shows_a_message_and_the_default_scene(server: str, browser_context):
    p = Page(browser_context, server, "/app?scene=1.not-a-scene")
    try:
        notice = p.page.locator(".notice").first
        notice.wait_for(state="visible", timeout=30_000 * patience())
        text = p.pane_text(".notice")
        assert "link" in text and "default scene" in text
        assert len(p.q()) > 100
    finally:
        p.close()


def test_pin_link_and_downloads_match_the_screen(server: str, browser_context, page: Page):
    from explorer.files import parse_csv
    from explorer.model import decode_scene

    settlement = page.text(".readout-settlement")
    page.page.get_by_text("Pin this result").first.click()
    page.page.locator(".pinned-settlement").first.wait_for(timeout=30_000 * patience())
    assert page.page.evaluate(
        "() => Bokeh.documents[0].get_model_by_name('q_pin_source_0').data.q.length") > 1

    page.type_into(".load-0-value", "650")
    new = page.wait_text_change(".readout-settlement", settlement)
    assert page.text(".pinned-settlement") == settlement  # the pin stays as it was
    assert page.text(".readout-force") == "650"

    # the address bar follows the scene on screen (at most once a second)
    def linked() -> tuple[str, dict | None]:
        link = page.page.url
        if "scene=" not in link:
            return link, None
        return link, decode_scene(link.split("scene=", 1)[1].split("&", 1)[0])

    deadline = time.monotonic() + 30
    link, scene = linked()
    while (scene is None or scene["loading"]["force"] != 650e3) and \
            time.monotonic() < deadline:
        page.page.wait_for_timeout(100)
        link, scene = linked()
    assert scene is not None and scene["loading"]["force"] == 650e3

    # downloads hold the same scene and result
    page.open_tab("Files")
    with page.page.expect_download(timeout=60_000 * patience()) as info:
        page.page.get_by_text("Save scene (JSON)").first.click()
    saved = json.loads(Path(info.value.path()).read_text())
    assert saved == scene
    with page.page.expect_download(timeout=60_000 * patience()) as info:
        page.page.get_by_text("Results: histories (CSV)").first.click()
    meta, names, table = parse_csv(Path(info.value.path()).read_text())
    assert names[:3] == ["time_day", "settlement_mm", "tilt_mrad"]
    last = table[-1]
    assert last[3] == 650  # kN/m, as on screen
    assert f"{last[1]:.5g}" == new

    # the link reproduces the screen in a new session
    other = Page(browser_context, link.split("/app", 1)[0], "/app" + link.split("/app", 1)[1])
    try:
        assert other.text(".readout-settlement") == new
        assert other.text(".readout-force") == "650"
        assert other.errors == []
    finally:
        other.close()
    assert page.errors == []


def test_an_oversized_upload_is_refused_in_the_page_and_a_scene_file_loads(page: Page):
    """A file over the limit never leaves the browser (a plain file input sent it in one
    websocket message and a file over the server's message limit closed the session); a
    scene file then loads."""
    disconnected: list[str] = []
    page.page.on("console", lambda m: "Lost websocket" in m.text and disconnected.append(m.text))
    page.open_tab("Files")
    upload = page.page.locator(".scene-upload input[type=file]").first
    upload.wait_for(state="attached", timeout=30_000 * patience())
    # 5 MiB: over the limit of a scene file (1 MB) and over the largest websocket message
    # the server reads (4 MiB, explorer/__main__.py), which a file sent in one message
    # would exceed and lose the page's connection (25 MiB cost 20 s more to hand over)
    upload.set_input_files(files=[{"name": "big.json", "mimeType": "application/json",
                                   "buffer": b"{" + b" " * (5 * 2**20) + b"}"}])
    page.page.get_by_text("File is too large").first.wait_for(timeout=30_000 * patience())
    # a file of another type: the box says which it takes ("Expects  or application/json"
    # before, a teacher's audit)
    upload.set_input_files(files=[{"name": "notes.txt", "mimeType": "text/plain",
                                   "buffer": b"notes"}])
    page.page.get_by_text("Expects a file ending in .json").first.wait_for(
        timeout=30_000 * patience())
    root = Path(__file__).resolve().parents[2]
    scene = json.loads((root / "core" / "presets" / "scenes" / "stepped_punch.json").read_text())
    scene["name"] = "uploaded in the browser"
    settlement = page.text(".readout-settlement")
    upload.set_input_files(files=[{"name": "scene.json", "mimeType": "application/json",
                                   "buffer": json.dumps(scene).encode()}])
    page.wait_text_change(".readout-settlement", settlement)
    page.page.wait_for_function(
        "() => Bokeh.documents[0].get_model_by_name('scene_figure').title.text"
        ".includes('uploaded in the browser')", timeout=30_000 * patience())
    assert disconnected == [] and page.errors == []
