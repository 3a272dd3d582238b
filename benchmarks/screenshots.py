"""Screenshots of the explorer for the README: 1400x900, and 1024x768 in presentation mode.

Starts ``python -m explorer`` on a free port, drives Debian's Chromium and writes
``assets/explorer.png`` (the eccentric creep preset with two pinned results and the
classical solutions) and ``assets/explorer_presentation_1024.png`` (a lesson at its third
step, its first two steps pinned, in presentation mode). Usage::

    python benchmarks/screenshots.py
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from tests.support.serving import CHROMIUM, CHROMIUM_ARGS, ExplorerProcess  # noqa: E402

READY = """() => {
  const doc = window.Bokeh && Bokeh.documents && Bokeh.documents[0];
  const src = doc && doc.get_model_by_name('q_source');
  return !!src && src.data.q && src.data.q.length > 1;
}"""
# two animation frames after a condition: the canvases have painted what it waited for
PAINTED = "() => new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))"


# the readout shows ``value`` for a quantity: [quantity, value]
_READOUT = """([q, v]) => {
  const roots = [document];
  while (roots.length) {
    const r = roots.pop();
    const cell = r.querySelector('.readout-' + q);
    if (cell) return cell.textContent.trim() === v;
    for (const e of r.querySelectorAll('*')) if (e.shadowRoot) roots.push(e.shadowRoot);
  }
  return false;
}"""


def _pins_shown(page, count: int) -> None:
    page.wait_for_function(
        "(n) => Bokeh.documents[0].get_model_by_name('q_pin_source_' + (n - 1))"
        "?.data.q.length > 1", arg=count, timeout=60_000)  # a pin's lines come with it


def _pin(page, count: int) -> None:
    page.get_by_text("Pin this result").first.click()
    _pins_shown(page, count)


def _type(page, css: str, value: str) -> None:
    box = page.locator(f"{css} input").first
    box.click()
    box.press("Control+a")
    box.type(value)
    box.press("Enter")


def main() -> int:
    """Write the two screenshots into ``assets/``."""
    import playwright.sync_api as pw

    assets = ROOT / "assets"
    with ExplorerProcess(ready_timeout=300) as server, pw.sync_playwright() as p:
        profile = tempfile.mkdtemp(prefix="explorer-shots-")
        context = p.chromium.launch_persistent_context(
            profile, executable_path=CHROMIUM, headless=True, args=list(CHROMIUM_ARGS),
            viewport={"width": 1400, "height": 900})
        page = context.new_page()
        page.goto(server.url + "/app?preset=eccentric_creep")
        page.wait_for_function(READY, timeout=120_000)
        page.locator(".classical-toggle input").first.check()
        page.wait_for_function("() => Bokeh.documents[0].get_model_by_name("
                               "'classical_source').data.x.length > 0", timeout=60_000)
        _pin(page, 1)
        _type(page, ".load-1-value", "60")        # the moment: e = 0.075 m
        page.wait_for_function(_READOUT, arg=["moment", "60"], timeout=60_000)
        _pin(page, 2)
        _type(page, ".load-1-value", "0")         # centred: the curve between the pins
        page.wait_for_function(_READOUT, arg=["moment", "0"], timeout=60_000)
        page.evaluate("() => window.scrollTo(0, 0)")
        page.evaluate(PAINTED)
        page.screenshot(path=str(assets / "explorer.png"))
        page.goto(server.url + "/app")
        page.wait_for_function(READY, timeout=120_000)
        page.set_viewport_size({"width": 1024, "height": 768})
        page.locator(".bk-tab", has_text="Lessons").first.click()
        page.locator(".lesson-select select").first.select_option(
            label="Force, eccentricity and tilt")
        for step, (quantity, value) in ((2, ("force", "1000")), (3, ("moment", "200"))):
            page.locator(".lesson-next button").first.click()
            page.wait_for_function(_READOUT, arg=[quantity, value], timeout=60_000)
            _pins_shown(page, step - 1)
        page.locator(".presentation-toggle button").first.click()
        page.wait_for_function("() => Bokeh.documents[0].get_model_by_name('pressure_figure')"
                               ".left[0].major_label_text_font_size === '18px'",
                               timeout=60_000)
        page.evaluate("() => window.scrollTo(0, 0)")
        page.evaluate(PAINTED)
        page.screenshot(path=str(assets / "explorer_presentation_1024.png"))
        context.close()
    print("wrote assets/explorer.png and assets/explorer_presentation_1024.png")
    return 0


if __name__ == "__main__":
    from benchmarks import help_requested

    help_requested(__doc__)
    sys.exit(main())
