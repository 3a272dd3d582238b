"""CPU an idle explorer page costs the browser, measured in a real browser.

Starts ``python -m explorer`` on a free port (or uses ``--url``), opens the page in
Debian's Chromium (headless, through Playwright), waits until it has drawn its plots and
filled its sidebar tabs, then leaves it alone for ``--seconds`` and reports the CPU time
the browser spent meanwhile, as a share of one core:

- the page's renderer process (all its threads), from the operating system's count;
- the page's main thread (Chrome's ``ThreadTime`` metric);
- the whole browser (every process of it: renderer, GPU/compositor, network, browser).

The page is measured twice: on the first tab shown (Scene), then with the Files tab open
(where the file dropper is on screen). Not part of the test suite. Usage::

    python -m benchmarks.explorer_idle [--seconds 30] [--url URL]
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import psutil

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from benchmarks.explorer_latency import READY  # noqa: E402
from explorer.views import FILL_TABS_AFTER_MS  # noqa: E402
from tests.support.serving import (  # noqa: E402
    CHROMIUM,
    CHROMIUM_ARGS,
    ExplorerProcess,
    ExplorerStartError,
)


def _browser_processes() -> list[psutil.Process]:
    """The Chromium processes this benchmark started (through Playwright's driver)."""
    return [p for p in psutil.Process(os.getpid()).children(recursive=True)
            if "chrom" in p.name().lower()]


def _cpu_seconds(processes: list[psutil.Process]) -> dict[int, float]:
    out = {}
    for proc in processes:
        try:
            times = proc.cpu_times()
            out[proc.pid] = times.user + times.system
        except psutil.Error:  # ended meanwhile
            pass
    return out


def _is_renderer(proc: psutil.Process) -> bool:
    try:
        cmdline = proc.cmdline()
    except psutil.Error:
        return False
    return "--type=renderer" in cmdline and not any("extension" in a for a in cmdline)


def idle_share(page, cdp, seconds: float) -> dict[str, float]:
    """Share of one core [%] the browser spent while ``page`` sat idle for ``seconds``."""
    processes = _browser_processes()
    renderers = {p.pid for p in processes if _is_renderer(p)}
    before = _cpu_seconds(processes)
    thread_before = _thread_time(cdp)
    start = time.monotonic()
    time.sleep(seconds)
    wall = time.monotonic() - start
    after = _cpu_seconds(processes)
    thread = _thread_time(cdp) - thread_before
    used = {pid: after[pid] - before[pid] for pid in after if pid in before}
    # the busiest renderer is the page's (an idle helper renderer costs nothing)
    renderer = max((used[pid] for pid in used if pid in renderers), default=0.0)
    return {"renderer": 100 * renderer / wall, "main thread": 100 * thread / wall,
            "browser": 100 * sum(used.values()) / wall}


def _thread_time(cdp) -> float:
    metrics = cdp.send("Performance.getMetrics")["metrics"]
    return next(m["value"] for m in metrics if m["name"] == "ThreadTime")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--url", help="an explorer already running (default: start one)")
    parser.add_argument("--seconds", type=float, default=30.0, help="idle time measured")
    args = parser.parse_args()

    from playwright.sync_api import sync_playwright

    server, url = None, args.url
    if url is None:
        server = ExplorerProcess(ready_timeout=300, stop_timeout=20)
        try:
            url = server.start().url
        except ExplorerStartError as err:
            raise SystemExit(str(err)) from None
    rows = {}
    try:
        with sync_playwright() as p, tempfile.TemporaryDirectory() as profile:
            context = p.chromium.launch_persistent_context(
                profile, executable_path=CHROMIUM, headless=True, args=CHROMIUM_ARGS,
                viewport={"width": 1400, "height": 900})
            page = context.new_page()
            page.goto(url + "/app")
            page.wait_for_function(READY, timeout=120_000)
            time.sleep(FILL_TABS_AFTER_MS / 1000 + 5)  # every tab filled, the page still
            cdp = context.new_cdp_session(page)
            cdp.send("Performance.enable")
            rows["Scene tab shown"] = idle_share(page, cdp, args.seconds)
            page.locator(".bk-tab", has_text="Files").first.click()
            time.sleep(5)  # the click's own work done
            rows["Files tab shown"] = idle_share(page, cdp, args.seconds)
            context.close()
    finally:
        if server is not None:
            server.stop()
    print(f"idle page, {args.seconds:.0f} s each; CPU time as % of one core")
    print(f"{'page':20s} {'renderer':>9s} {'main thread':>12s} {'browser':>9s}")
    for name, row in rows.items():
        print(f"{name:20s} {row['renderer']:9.1f} {row['main thread']:12.1f} "
              f"{row['browser']:9.1f}")


if __name__ == "__main__":
    main()
