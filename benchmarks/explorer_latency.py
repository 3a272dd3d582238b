"""Latency of the explorer as a user sees it, measured in a real browser.

Starts ``python -m explorer`` on a free port (or uses ``--url``), drives Debian's Chromium
with Playwright and reports medians of:

- first page load: navigation start -> the first frame painted after the pressure plot
  received its data (a fresh page, hence a fresh session, each time);
- load slider: key press on the force slider -> the second animation frame after the
  pressure plot's data changed (the frame that shows it);
- coating thickness, punch half-width, base thickness: the same, for sliders whose
  change re-solves on release (a key press is a release).

Every key press moves a slider to a value not seen before, so no result comes from the
explorer's result cache; the core's stage caches work as they do for a user.

Next to each wall-clock median it reports the page's own work per move: the CPU time of
the browser's main thread (Chrome's ``ThreadTime`` metric) from the key press to the
frame that shows the result. On a loaded machine the wall clock waits for other
processes; the main thread's CPU time does not. And where each move's time went: from
the key press to the page's first message, from there to the new data in the page (the
server's part: its event loop, the solve in a worker, the redraw, the message), and from
the data to the frame (the page's part).
Not part of the test suite. Usage::

    python benchmarks/explorer_latency.py [--repeats 9] [--loads 5] [--url URL]
"""

from __future__ import annotations

import argparse
import json
import re
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from explorer.views import FILL_TABS_AFTER_MS  # noqa: E402
from tests.support.serving import (  # noqa: E402
    CHROMIUM,
    CHROMIUM_ARGS,
    ExplorerProcess,
    ExplorerStartError,
)
from tests.support.trace_steps import STEPS, server_steps  # noqa: E402

READY = """() => {
  const doc = window.Bokeh && Bokeh.documents && Bokeh.documents[0];
  const src = doc && doc.get_model_by_name('q_source');
  if (!src || !src.data.q || src.data.q.length < 2) return null;
  return new Promise(r => requestAnimationFrame(() => requestAnimationFrame(
    () => r(performance.now()))));
}"""

# Records, for every change of the pressure plot's data, the time from the last key press
# to the second animation frame after the change, and where that time went: until the
# page's first message to the server, until the new data arrived (the server's part and
# the network), and from then to the frame (the page's part).
INSTRUMENT = """() => {
  const src = Bokeh.documents[0].get_model_by_name('q_source');
  window.__latencies = [];
  window.__parts = [];
  window.__keyTime = null;
  let sent = null;
  document.addEventListener('keydown', e => { window.__keyTime = performance.now();
                                              sent = null; }, true);
  const send = WebSocket.prototype.send;
  WebSocket.prototype.send = function (data) {
    if (window.__keyTime !== null && sent === null) sent = performance.now();
    return send.call(this, data);
  };
  src.change.connect(() => {
    const t0 = window.__keyTime;
    if (t0 === null) return;
    window.__keyTime = null;
    const arrived = performance.now(), out = sent === null ? arrived : sent;
    requestAnimationFrame(() => requestAnimationFrame(() => {
      const now = performance.now();
      window.__parts.push([out - t0, arrived - out, now - arrived]);
      window.__latencies.push(now - t0);
    }));
  });
}"""


def _main_thread_seconds(cdp) -> float:
    """CPU time [s] the page's main thread has spent in tasks so far."""
    metrics = cdp.send("Performance.getMetrics")["metrics"]
    return next(m["value"] for m in metrics if m["name"] == "ThreadTime")


def measure_slider(page, tab: str, css: str, presses: int, key: str,
                   cdp=None, cpu: list[float] | None = None,
                   parts: list[list[float]] | None = None) -> list[float]:
    """Press ``key`` on a slider's handle ``presses`` times; latency of each [ms] (and
    the main thread's CPU time of each [ms] into ``cpu``, and its parts [ms] into
    ``parts``: key to first message sent, sent to data arrived, arrived to frame)."""
    page.locator(".bk-tab", has_text=tab).first.click()
    handle = page.locator(f"{css} .noUi-handle").first
    handle.focus()
    out, solves = [], []
    for _ in range(presses):
        before = page.evaluate("() => window.__latencies.length")
        busy = _main_thread_seconds(cdp) if cdp is not None else 0.0
        handle.press(key)
        page.wait_for_function(f"() => window.__latencies.length > {before}", timeout=120_000)
        if cdp is not None and cpu is not None:
            cpu.append(1e3 * (_main_thread_seconds(cdp) - busy))
        out.append(page.evaluate("() => window.__latencies[window.__latencies.length - 1]"))
        if parts is not None:
            parts.append(page.evaluate("() => window.__parts[window.__parts.length - 1]"))
        time.sleep(0.3)
        status = page.locator(".solve-status").first.inner_text()
        found = re.search(r"Solved in (\d+) ms", status)
        solves.append(float(found.group(1)) if found else float("nan"))
    return out, solves


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--url", help="an explorer already running (default: start one)")
    parser.add_argument("--repeats", type=int, default=9, help="slider moves per control")
    parser.add_argument("--loads", type=int, default=5, help="page loads")
    parser.add_argument("--json", help="also write the numbers to this file")
    args = parser.parse_args()

    from playwright.sync_api import sync_playwright

    server = None
    url = args.url
    trace = Path(tempfile.mkdtemp()) / "trace.jsonl"
    windows: dict[str, tuple[float, float]] = {}
    if url is None:
        server = ExplorerProcess(ready_timeout=300, stop_timeout=20,
                                 env={"EXPLORER_TRACE": str(trace)})
        try:
            url = server.start().url
        except ExplorerStartError as err:
            raise SystemExit(str(err)) from None
    results: dict[str, list[float]] = {}
    solves: dict[str, list[float]] = {}
    cpu: dict[str, list[float]] = {}
    parts: dict[str, list[list[float]]] = {}
    try:
        with sync_playwright() as p, tempfile.TemporaryDirectory() as profile:
            context = p.chromium.launch_persistent_context(
                profile, executable_path=CHROMIUM, headless=True, args=CHROMIUM_ARGS,
                viewport={"width": 1500, "height": 1300})
            loads = []
            for _ in range(args.loads + 1):
                page = context.new_page()
                page.goto(url + "/app", wait_until="commit")
                handle = page.wait_for_function(READY, timeout=120_000, polling=20)
                loads.append(handle.json_value())
                page.close()
            results["first page load"] = loads[1:]  # the first warms the browser's cache

            page = context.new_page()
            page.goto(url + "/app")
            page.wait_for_function(READY, timeout=120_000)
            # the sidebar tabs not yet opened are filled a few seconds after the page
            # loads (explorer.views.tabs); measured during that, the first moves took
            # seconds: the steady state is what a user dragging a slider meets
            time.sleep(FILL_TABS_AFTER_MS / 1000 + 5)
            page.evaluate(INSTRUMENT)
            cdp = context.new_cdp_session(page)
            cdp.send("Performance.enable")
            for name, tab, css in (("load slider (force)", "Scene", ".load-0-value"),
                                   ("coating thickness", "Coating", ".coating-thickness"),
                                   ("punch half-width", "Punch", ".punch-half-width"),
                                   ("base thickness", "Base", ".base-thickness")):
                cpu[name], parts[name] = [], []
                since = time.monotonic()
                results[name], solves[name] = measure_slider(page, tab, css, args.repeats,
                                                             "ArrowRight", cdp, cpu[name],
                                                             parts[name])
                windows[name] = (since, time.monotonic())
            context.close()
    finally:
        if server is not None:
            server.stop()

    goals = {"first page load": 3000, "load slider (force)": 100, "coating thickness": 250,
             "punch half-width": 250, "base thickness": 400}
    print(f"{'control':24s} {'median':>9s} {'min':>9s} {'max':>9s} {'goal':>7s} "
          f"{'core solve':>11s} {'page CPU':>9s}  (ms; core solve: median of the "
          "server's own timing; page CPU: median of the main thread's)")
    for name, values in results.items():
        core, page_cpu = solves.get(name), cpu.get(name)
        core_text = f"{statistics.median(core):11.0f}" if core else f"{'':11s}"
        cpu_text = f"{statistics.median(page_cpu):9.0f}" if page_cpu else f"{'':9s}"
        print(f"{name:24s} {statistics.median(values):9.0f} {min(values):9.0f} "
              f"{max(values):9.0f} {goals[name]:7d} {core_text} {cpu_text}  n={len(values)}")
    print("\nwhere the time of a move went (medians, ms): key press -> first message sent; "
          "sent -> new data in the page (server, network); data -> frame shown (page)")
    for name, rows in parts.items():
        if rows:
            sent, server_part, page_part = (statistics.median(r[k] for r in rows)
                                            for k in range(3))
            print(f"{name:24s} {sent:6.0f} {server_part:9.0f} {page_part:9.0f}")
    steps: dict[str, list[dict[str, float]]] = {}
    server_cpu: dict[str, list[float]] = {}
    if trace.exists():
        print("\ninside the server (medians, ms after the websocket message in; "
              "explorer/solving/trace.py):")
        print(f"{'control':24s} " + " ".join(f"{s:>12s}" for s in STEPS[1:])
              + f" {'server CPU':>11s}")
        for name, (since, until) in windows.items():
            server_cpu[name] = used = []
            steps[name] = moves = server_steps(trace, since, until, used)
            if moves:
                cpu_text = f"{statistics.median(used):11.1f}" if used else f"{'':11s}"
                print(f"{name:24s} " + " ".join(
                    f"{statistics.median(m[s] for m in moves):12.1f}" for s in STEPS[1:])
                    + f" {cpu_text}  n={len(moves)}")
        print("(server CPU: the server process's CPU time from the websocket message in "
              "to the patch written, all its threads; the solve runs in a worker)")
    if args.json:
        Path(args.json).write_text(json.dumps(
            {"browser": results, "core_solve": solves, "page_cpu": cpu, "parts": parts,
             "server_steps": steps, "server_cpu": server_cpu}, indent=2))


if __name__ == "__main__":
    main()
