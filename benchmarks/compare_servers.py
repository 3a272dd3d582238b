"""The served explorer's CPU time per slider step in this tree against another tree, the
two servers driven in turn from one browser.

    python -m benchmarks.compare_servers OTHER_TREE [PRESET ...] [--steps 40]
        [--slider load|thickness] [--no-write]

A slider step costs the server far more CPU than its solve (Panel's and Bokeh's work on
the event loop, the figures, the messages), and on a shared machine that cost moves by
tens of per cent from one minute to the next: two runs of
``benchmarks/explorer_latency.py``, one per tree, cannot tell a 10 % change from the
noise. Here one server per tree (each importing ``explorer`` and ``core`` from its own
tree; ``python -m explorer`` on 127.0.0.1, its default solver processes) serves a page of the
preset in one headless Chromium, and the key steps of the slider alternate between the
two pages (the order swapped every step), so both see the same machine. Per step: the
server process's CPU time (user and system, from ``/proc``, its solver processes not
counted: the solve is the same) from the key press until 0.2 s after the page showed the
new pressure, and the latency from the key press to the second frame after the new data
(as ``explorer_latency`` measures it). Reported per preset and tree: the mean CPU per
step, the median latency, and the ratio of the CPU means (this / other). The table (both
commits, the date, the load) is written to ``benchmarks/results/compare_servers.md``
unless ``--no-write`` is given. Linux only (``/proc``); not part of the test suite.

The other tree must be a whole checkout (``git worktree add /tmp/old COMMIT``).
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

from benchmarks import ROOT, run_lines, tree_commit
from benchmarks.explorer_latency import INSTRUMENT, READY
from benchmarks.load_test import cpu_seconds
from tests.support.serving import CHROMIUM, CHROMIUM_ARGS, ExplorerProcess

#: Where :func:`main` writes its table.
RESULTS = Path(__file__).resolve().parent / "results" / "compare_servers.md"
#: The sliders measured: (sidebar tab, css class of the slider).
SLIDERS = {"load": ("Scene", ".load-0-value"), "thickness": ("Coating", ".coating-thickness")}
#: Seconds waited after each update before the next step (the server's work after the
#: message, e.g. the page's address, is counted with its step).
SETTLE_S = 0.2


def compare(other: Path, preset: str, slider: str, steps: int
            ) -> dict[str, tuple[float, float]]:
    """{"this"/"other": (mean server CPU per step [ms], median latency [ms])}."""
    from playwright.sync_api import sync_playwright

    tab, css = SLIDERS[slider]
    trees = {"this": ROOT, "other": other}
    # (``python -m explorer`` run in a tree imports that tree's packages)
    servers = {name: ExplorerProcess(host="127.0.0.1", cwd=tree,
                                     program=(sys.executable, "-m", "explorer"))
               for name, tree in trees.items()}
    spent = {name: 0.0 for name in trees}
    latency: dict[str, list[float]] = {name: [] for name in trees}
    try:
        for server in servers.values():
            server.start()
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=CHROMIUM, args=list(CHROMIUM_ARGS))
            pages = {}
            for name, server in servers.items():
                page = browser.new_page()
                page.goto(f"{server.url}/app?preset={preset}", wait_until="commit")
                page.wait_for_function(READY, timeout=180_000)
                page.evaluate(INSTRUMENT)
                page.locator(".bk-tab", has_text=tab).first.click()
                handle = page.locator(f"{css} .noUi-handle").first.element_handle()
                pages[name] = (page, handle)

            def step(name: str, key: str) -> float:
                page, handle = pages[name]
                page.bring_to_front()
                handle.focus()
                before = page.evaluate("() => window.__latencies.length")
                handle.press(key)
                page.wait_for_function(f"() => window.__latencies.length > {before}",
                                       timeout=120_000)
                time.sleep(SETTLE_S)
                return page.evaluate("() => window.__latencies.at(-1)")

            for name in trees:  # the first steps build what a step reuses: not counted
                for _ in range(3):
                    step(name, "ArrowRight")
            for i in range(steps):
                for name in (("this", "other") if i % 2 == 0 else ("other", "this")):
                    server = servers[name]
                    started = cpu_seconds(server.pid)
                    latency[name].append(step(name, "ArrowLeft"))
                    ended = cpu_seconds(server.pid)
                    if started is None or ended is None:
                        raise SystemExit(f"the server of the {name} tree ended; its log: "
                                         f"{server.output()[-2000:]}")
                    spent[name] += ended - started
            browser.close()
    finally:
        for server in servers.values():
            if server.proc is not None:
                server.stop()
    return {name: (1e3 * spent[name] / steps, statistics.median(latency[name]))
            for name in trees}


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("other", type=Path, help="the other tree (a checkout of a commit)")
    parser.add_argument("presets", nargs="*", help="preset names (default: uniform_flat)")
    parser.add_argument("--steps", type=int, default=40, help="key steps per tree")
    parser.add_argument("--slider", choices=sorted(SLIDERS), default="load")
    parser.add_argument("--no-write", action="store_true")
    args = parser.parse_args(argv)
    if not (args.other / "explorer" / "__init__.py").is_file():
        parser.error(f"other: {args.other} holds no explorer package (a checkout of the "
                     "repository is needed)")
    if not 1 <= args.steps <= 1000:
        parser.error("--steps: must be between 1 and 1000")
    return args


def main(argv: list[str] | None = None) -> None:
    from core.presets import preset_names

    args = parse_args(argv)
    names = args.presets or ["uniform_flat"]
    unknown = sorted(set(names) - set(preset_names()))
    if unknown:
        raise SystemExit(f"presets: unknown {', '.join(unknown)}")
    started = datetime.now(timezone.utc)
    load_before = os.getloadavg()[0]
    lines = ["| preset | this tree: CPU per step [ms] | latency p50 [ms] | other tree: CPU "
             "per step [ms] | latency p50 [ms] | CPU ratio |",
             "| --- | --- | --- | --- | --- | --- |"]
    for name in names:
        result = compare(args.other.resolve(), name, args.slider, args.steps)
        (mine, my_latency), (theirs, their_latency) = result["this"], result["other"]
        lines.append(f"| {name} | {mine:.1f} | {my_latency:.0f} | {theirs:.1f} | "
                     f"{their_latency:.0f} | {mine / theirs:.2f} |")
        print(lines[-1], flush=True)
    load_after = os.getloadavg()[0]
    text = "\n".join([
        "# The served explorer's CPU time per slider step against another tree", "",
        f"    python -m benchmarks.compare_servers OTHER {' '.join(args.presets)} "
        f"--steps {args.steps} --slider {args.slider}".replace("  ", " "), "",
        *run_lines(started, load_before, load_after,
                   "both servers driven in turn from one browser, so both see the same "
                   "load"),
        f"- the other tree: commit {tree_commit(args.other)}",
        f"- {args.steps} key steps of the {args.slider} slider per tree, alternating; the "
        "server process's CPU time per step (its solver processes not counted) and the "
        "median latency from the key press to the frame showing the new pressure", "",
        *lines, ""])
    if not args.no_write:
        RESULTS.write_text(text)
        print(f"written: {RESULTS}")


if __name__ == "__main__":
    main()
