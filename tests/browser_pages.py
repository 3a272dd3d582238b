"""Helpers of the browser tests: a page of the served explorer, read as a user sees it.

Imported by the browser test modules only; each first calls :func:`require_browser`.
"""

from __future__ import annotations

import os
import time


def require_browser() -> None:
    """Skip the calling test module, saying why, when Chromium or Playwright is absent;
    under CI (where the test set-up installs both) their absence fails instead."""
    import pytest

    from tests.support.serving import browser_missing

    missing = browser_missing()
    if missing:
        if os.environ.get("CI"):
            pytest.fail(missing, pytrace=False)
        pytest.skip(missing, allow_module_level=True)


#: The most a wait on the page is stretched on a busy machine (see :func:`patience`).
MOST_PATIENCE = 5.0


def patience() -> float:
    """How many times longer than on a quiet machine the page may take now: the load
    average per core, from 1 to :data:`MOST_PATIENCE`.

    Every wait of these tests is on a condition of the page, so a longer limit costs
    nothing where the page is quick; on a shared machine at load ~10 (2 cores) a page
    load took 30 s and a study's last message came over 60 s after its chart, where a
    quiet machine takes 2-5 s.
    """
    per_core = os.getloadavg()[0] / (os.cpu_count() or 1)
    return min(MOST_PATIENCE, max(1.0, per_core))


# JavaScript helpers run in the page.
JS_DOC = "() => (window.Bokeh && Bokeh.documents && Bokeh.documents[0]) || null"
JS_READY = """() => {
  const doc = window.Bokeh && Bokeh.documents && Bokeh.documents[0];
  if (!doc) return false;
  const src = doc.get_model_by_name('q_source');
  return !!src && src.data.q && src.data.q.length > 1;
}"""
JS_Q = """() => Array.from(Bokeh.documents[0].get_model_by_name('q_source').data.q)"""
JS_TITLE = """(name) => Bokeh.documents[0].get_model_by_name(name).title.text"""
# Whether the sidebar's tab at index k has its widgets on the page.
JS_TAB_FILLED = """(k) => Array.from(Bokeh.index.all_views())
  .find(v => (v.model.css_classes || []).includes('sidebar-tabs'))
  .model.tabs[k].child.children.length > 0"""
# The titles of the sidebar's tabs, in their order.
JS_TAB_TITLES = """() => Array.from(Bokeh.index.all_views())
  .find(v => (v.model.css_classes || []).includes('sidebar-tabs')).model.tabs.map(t => t.title)"""


# Closing a page while the server still writes to its websocket makes tornado log a
# "Task exception was never retrieved" traceback: that is the test closing pages, not a
# failure of the explorer.
_CLOSED_SOCKET = ("WebSocketClosedError", "StreamClosedError")


def _app_tracebacks(output: str) -> list[str]:
    blocks = output.split("Traceback (most recent call last)")[1:]
    return [b for b in blocks if not any(name in b[:3000] for name in _CLOSED_SOCKET)]


class Page:
    """A page of the explorer with the console watched."""

    def __init__(self, context: object, url: str, path: str = "/app") -> None:
        self.page = context.new_page()
        self.url = url
        self.errors: list[str] = []
        self.page.on("console", lambda m: m.type == "error" and self.errors.append(m.text))
        # an uncaught error of the page with its stack (where BokehJS or Panel threw it)
        self.page.on("pageerror", lambda e: self.errors.append(f"{e}\n{e.stack}"))
        self.page.goto(url + path, timeout=30_000 * patience())
        self.page.wait_for_function(JS_READY, timeout=60_000 * patience())

    def q(self) -> list[float]:
        return self.page.evaluate(JS_Q)

    def title(self, figure: str) -> str:
        return self.page.evaluate(JS_TITLE, figure)

    def text(self, selector: str) -> str:
        return self.page.locator(selector).first.inner_text()

    def pane_text(self, selector: str) -> str:
        """Text of a Panel pane (its content lives in the element's shadow root)."""
        return self.page.locator(selector).first.evaluate(
            "e => (e.shadowRoot || e).textContent")

    def wait_text_change(self, selector: str, old: str, timeout: float = 60.0) -> str:
        deadline = time.monotonic() + timeout * patience()
        while time.monotonic() < deadline:
            new = self.text(selector)
            if new != old:
                return new
            time.sleep(0.05)
        raise AssertionError(f"{selector} stayed at {old!r}")

    def wait_complete(self, timeout: float = 60.0) -> None:
        """Wait until every sidebar tab has its widgets (the page's own signal,
        ``explorer.views.COMPLETE_CLASS``): no more background work of the page is due."""
        from explorer.views import COMPLETE_CLASS

        self.page.locator(f".{COMPLETE_CLASS}").first.wait_for(
            state="attached", timeout=1000 * timeout * patience())

    def open_tab(self, name: str) -> None:
        """Open a tab of the sidebar (its widgets arrive just after the page)."""
        self.page.locator(".bk-tab", has_text=name).first.click()

    def complete_by_hand(self, then: str) -> None:
        """Open every tab of the sidebar, as a user looking around would, then the tab
        ``then``, and wait until the page is complete: no background filling of tabs is
        left to come (it would come only after the page was left alone for
        ``explorer.views.FILL_TABS_AFTER_MS``)."""
        for k, title in enumerate(self.page.evaluate(JS_TAB_TITLES)):
            self.open_tab(title)
            # its widgets arrived before the next click: the page sends a tab's opening
            # once the server has taken the one before (clicks in a row reach it as one)
            self.page.wait_for_function(JS_TAB_FILLED, arg=k, timeout=30_000 * patience())
        self.open_tab(then)
        self.wait_complete()

    def type_into(self, css: str, value: str) -> None:
        """Type a value in the number box of a slider and confirm it with Enter."""
        box = self.page.locator(f"{css} input").first
        box.click()
        box.press("Control+a")
        box.type(value)
        box.press("Enter")

    def close(self) -> None:
        self.page.close()


# Whether some element of the page (shadow roots included) shows the text.
JS_SHOWN = """(text) => {
  const roots = [document];
  while (roots.length) {
    const r = roots.pop();
    for (const e of r.querySelectorAll('*')) {
      if (!e.shadowRoot) continue;
      if (e.shadowRoot.textContent.includes(text)) return true;
      roots.push(e.shadowRoot);
    }
  }
  return false;
}"""


#: Records every change of the pressure plot's data (``window.__changes``: page times
#: [ms]) and the page times of the mouse down and up (``window.__down``, ``window.__up``).
JS_WATCH_PRESSURE = """() => {
  const src = Bokeh.documents[0].get_model_by_name('q_source');
  window.__changes = [];
  window.__down = window.__up = null;
  src.change.connect(() => window.__changes.push(performance.now()));
  document.addEventListener('pointerdown', () => { window.__down = performance.now(); },
                            true);
  document.addEventListener('pointerup', () => { window.__up = performance.now(); }, true);
}"""
#: How many changes :data:`JS_WATCH_PRESSURE` has seen.
PRESSURE_CHANGES = "() => window.__changes.length"


def until(check, what: str, timeout: float = 60.0, describe=None) -> None:
    """Poll ``check`` (a look at the page) until it holds; fail after ``timeout`` [s] on a
    quiet machine, stretched by :func:`patience` on a busy one (saying what
    ``describe()``, if given, sees on the page then)."""
    timeout *= patience()
    deadline = time.monotonic() + timeout
    while not check():
        if time.monotonic() > deadline:
            seen = f" (the page shows: {describe()!r})" if describe is not None else ""
            raise AssertionError(f"not seen within {timeout:g} s: {what}{seen}")
        time.sleep(0.05)


def served_explorer(explorer):
    """The run's served explorer (``explorer``: the ``explorer_server`` fixture) for a test
    module: yields its address, then fails on a traceback of the page's code that the
    server wrote while the module ran."""
    if explorer.proc.poll() is not None:
        raise RuntimeError(f"the served explorer has exited:\n{explorer.output()[-3000:]}")
    start = len(explorer.output())
    yield explorer.url
    output = explorer.output()[start:]
    assert not _app_tracebacks(output), output


def chromium_context(width: int, height: int, **options):
    """A fresh Chromium profile (Debian's browser) with a window of ``width`` x ``height``
    [px]; yields the Playwright context, then removes the profile."""
    import shutil
    import tempfile

    import playwright.sync_api as playwright_api

    from tests.support.serving import CHROMIUM, CHROMIUM_ARGS

    profile = tempfile.mkdtemp(prefix="explorer-chromium-")
    with playwright_api.sync_playwright() as p:
        context = p.chromium.launch_persistent_context(
            profile, executable_path=CHROMIUM, headless=True, args=CHROMIUM_ARGS,
            viewport={"width": width, "height": height}, **options)
        # Playwright's own waits (a click, a download) get the same patience
        context.set_default_timeout(30_000 * patience())
        yield context
        context.close()
    shutil.rmtree(profile, ignore_errors=True)


def page_fixtures(width: int, height: int, **options):
    """The fixtures ``server``, ``browser_context`` (both per module) and ``page`` (per
    test) of a browser test module, its window ``width`` x ``height`` [px] and ``options``
    of the Playwright context (e.g. ``accept_downloads=True``). Use as
    ``server, browser_context, page = page_fixtures(1400, 900)`` at the module's top."""
    import pytest

    @pytest.fixture(scope="module", name="server")
    def server(explorer_server):
        yield from served_explorer(explorer_server)

    @pytest.fixture(scope="module", name="browser_context")
    def browser_context():
        yield from chromium_context(width, height, **options)

    @pytest.fixture(name="page")
    def page(server: str, browser_context: object):
        p = Page(browser_context, server)
        yield p
        p.close()

    return server, browser_context, page


def module_page_fixture(width: int, height: int, **options):
    """A fixture ``page``: one page of the run's served explorer for a whole test module
    (its tests build on each other's steps), in a window ``width`` x ``height`` [px] with
    ``options`` of the Playwright context. Use as ``page = module_page_fixture(1400, 900)``
    at the module's top."""
    import pytest

    @pytest.fixture(scope="module", name="page")
    def page(explorer_server):
        for url in served_explorer(explorer_server):
            for context in chromium_context(width, height, **options):
                shown = Page(context, url)
                yield shown
                shown.close()

    return page


# Width on the page of the view of a named Bokeh model [px] (0 or null: not shown).
JS_VIEW_WIDTH = """(name) => {
  const stack = Object.values(Bokeh.index);
  while (stack.length) {
    const v = stack.pop();
    if (v.model && v.model.name === name) return v.el.getBoundingClientRect().width;
    if (v.child_views) stack.push(...v.child_views);
    else if (v.renderer_views) stack.push(...v.renderer_views.values());
  }
  return null;
}"""
# Top [px] of a named figure in the viewport, or null while it is not drawn.
JS_VIEW_TOP = JS_VIEW_WIDTH.replace("getBoundingClientRect().width",
                                    "getBoundingClientRect().top")
