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
For every preset scene (``--presets``, default all of ``core.presets.preset_names()``)
the page is switched to it with the sidebar's preset selector, as a user does (the time
from the choice to the frame showing the new scene's pressure is reported), and every
slider kind the preset shows is measured twice: by key presses as above (p50 and p95),
and by a drag (mouse down on the handle, 20 small moves over about a second, mouse up),
counting the pressure plot's updates during the drag (live: the plots follow the handle)
and after the release, and the time from the release to the last update. Each slider
starts from the preset as loaded (the Scene tab's reset, waited for, between rows). A
slider the preset hides is said so. The table is written as Markdown to ``--markdown`` (default
``benchmarks/results/explorer_latency_presets.md``) with the commit, the date, the load
average and the command line.
Not part of the test suite. Usage::

    python benchmarks/explorer_latency.py [--repeats 9] [--loads 5] [--url URL]
        [--presets all|NAME,...] [--quick] [--json FILE] [--markdown FILE]

``--switches-only [--rounds 3]`` measures the preset switches alone, each preset chosen
``--rounds`` times in turn (one switch is one sample: a single one said "ok" or "missed"
by chance), and writes their median, least and largest to
``benchmarks/results/explorer_preset_switch.md`` (unless ``--markdown``).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from datetime import datetime, timezone
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

try:
    from playwright.sync_api import Error as PlaywrightError
    from playwright.sync_api import TimeoutError as PlaywrightTimeout
except ImportError:  # the pure parts (tables, arguments) work without a browser
    PlaywrightError = PlaywrightTimeout = TimeoutError

#: The Markdown table of the presets run (the older explorer_latency.md is history).
RESULTS = ROOT / "benchmarks" / "results" / "explorer_latency_presets.md"
#: The table of ``--switches-only``.
SWITCH_RESULTS = ROOT / "benchmarks" / "results" / "explorer_preset_switch.md"

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
  // every update of the pressure plot (for drags and preset switches): the second
  // animation frame after its data changed, and the times of the mouse down and up
  window.__updates = [];
  window.__down = null;
  window.__up = null;
  src.change.connect(() => requestAnimationFrame(() => requestAnimationFrame(
    () => window.__updates.push(performance.now()))));
  document.addEventListener('pointerdown', () => { window.__down = performance.now(); },
                            true);
  document.addEventListener('pointerup', () => { window.__up = performance.now(); }, true);
}"""


def _main_thread_seconds(cdp) -> float:
    """CPU time [s] the page's main thread has spent in tasks so far."""
    metrics = cdp.send("Performance.getMetrics")["metrics"]
    return next(m["value"] for m in metrics if m["name"] == "ThreadTime")


def measure_slider(page, tab: str, css: str, presses: int, key: str,
                   cdp=None, cpu: list[float] | None = None,
                   parts: list[list[float]] | None = None, handle=None,
                   timeout_ms: float = 120_000) -> tuple[list[float], list[float]]:
    """Press ``key`` on a slider's handle ``presses`` times; latency of each [ms] (and
    the main thread's CPU time of each [ms] into ``cpu``, and its parts [ms] into
    ``parts``: key to first message sent, sent to data arrived, arrived to frame), and the
    server's solve time of each [ms] from the status line. ``handle``: the slider's noUi
    handle when not found by ``css``. A press whose update does not come within
    ``timeout_ms`` ends the series (the latencies so far are returned)."""
    page.locator(".bk-tab", has_text=tab).first.click()
    if handle is None:
        handle = page.locator(f"{css} .noUi-handle").first
    handle.focus()
    # resolved once: a locator is looked up again at each press, through every shadow root
    # of the page (~30 ms of the page's main thread on the complete page, which the page's
    # CPU per step then counted)
    located, handle = handle, handle.element_handle()
    out, solves = [], []
    for _ in range(presses):
        before = page.evaluate("() => window.__latencies.length")
        busy = _main_thread_seconds(cdp) if cdp is not None else 0.0
        try:
            handle.press(key)
        except PlaywrightError:  # the page made the slider anew: find it again
            handle = located.element_handle()
            handle.press(key)
        try:
            page.wait_for_function(f"() => window.__latencies.length > {before}",
                                   timeout=timeout_ms)
        except PlaywrightTimeout:
            print(f"  no update within {timeout_ms / 1e3:.0f} s of a key press",
                  file=sys.stderr)
            break
        if cdp is not None and cpu is not None:
            cpu.append(1e3 * (_main_thread_seconds(cdp) - busy))
        out.append(page.evaluate("() => window.__latencies[window.__latencies.length - 1]"))
        if parts is not None:
            parts.append(page.evaluate("() => window.__parts[window.__parts.length - 1]"))
        time.sleep(0.3)
        solves.append(_solve_ms(page))
    return out, solves


def _solve_ms(page) -> float:
    """The server's solve time [ms] the status line reports (nan: none said)."""
    status = page.locator(".solve-status").first.inner_text()
    found = re.search(r"Solved in (\d+) ms", status)
    return float(found.group(1)) if found else float("nan")


# --------------------------------------------------------------------------------------
# every preset, every slider kind


#: Goals of the issue [ms]: p95 of a key step of a load or geometry slider, the last
#: update after a drag's release, a preset switch, the first page.
GOALS = {"load": 100.0, "geometry": 100.0, "release": 200.0, "preset": 500.0,
         "first page": 2000.0}


@dataclass(frozen=True)
class SliderKind:
    """A slider measured on every preset that shows it: its name in the table, the
    sidebar tab, the css class of the slider (or labels, the first one shown is used),
    and which goal it has (``load`` or ``geometry``)."""

    name: str
    tab: str
    css: str = ""
    labels: tuple[str, ...] = ()
    goal: str = "geometry"


#: The slider kinds, in the order measured (explorer/views: scene.py, eccentricity.py,
#: coating.py, punch.py, base.py). The modulus and shape sliders carry no css class:
#: they are found by their label.
SLIDER_KINDS = (
    SliderKind("load", "Scene", css=".load-0-value", goal="load"),
    SliderKind("eccentricity e", "Scene", css=".eccentricity-slider", goal="load"),
    SliderKind("coating thickness", "Coating", css=".coating-thickness"),
    SliderKind("coating modulus", "Coating", labels=("Young's modulus [MPa]",)),
    SliderKind("punch half-width", "Punch", css=".punch-half-width"),
    SliderKind("punch shape", "Punch", labels=(
        "crown radius R", "slope of each face", "step height", "step position",
        "land height", "land width", "wave amplitude", "wavelength")),
    SliderKind("base thickness", "Base", css=".base-thickness"),
)

#: Drag: moves of the mouse, pixels per move, seconds between moves (~1 s in all).
DRAG_MOVES, DRAG_PX, DRAG_PAUSE_S = 20, 2, 0.05
#: After a release the updates are waited for until none came for this long [s] (a live
#: drag's updates come well under 0.5 s apart: live needs solves under 30 ms of CPU).
QUIET_S = 0.8


def percentile(values: list[float], q: float) -> float:
    """The ``q``-th percentile (0-100) of ``values``, linear between order statistics
    (numpy's default); nan for no values."""
    data = sorted(v for v in values if not math.isnan(v))
    if not data:
        return float("nan")
    pos = (len(data) - 1) * q / 100
    lo = math.floor(pos)
    hi = min(lo + 1, len(data) - 1)
    return data[lo] + (data[hi] - data[lo]) * (pos - lo)


def drag_summary(updates: list[float], down: float, up: float,
                 previewed: bool = False) -> dict[str, float]:
    """What a drag showed, from the page times [ms] of the pressure plot's updates (frames
    drawn), of the mouse down and up: updates during the drag, after the release, and the
    time from the release to the last update [ms] (0 when none came after it);
    ``previewed``: the updates during the drag were previews (the page said so before
    the release), not the scene's answers."""
    during = [t for t in updates if down < t <= up]
    after = [t for t in updates if t > up]
    return {"during": len(during), "after": len(after),
            "last_after_ms": (max(after) - up) if after else 0.0,
            "drag_ms": up - down, "previewed": bool(previewed and during)}


def drag_kind(drag: dict[str, float]) -> str:
    """``live`` (the answers follow the handle), ``preview`` (previews do: the base
    elastic at loading, the answer with creep on release) or ``release`` (nothing until
    the release) for a :func:`drag_summary`; "" for none."""
    if not drag:
        return ""
    if drag["during"] == 0:
        return "release"
    return "preview" if drag.get("previewed") else "live"


#: Whether the page says that it previews a held drag (any shadow root's text).
JS_PREVIEWING = """() => {
  const roots = [document];
  while (roots.length) {
    const r = roots.pop();
    for (const e of r.querySelectorAll('*')) {
      if (!e.shadowRoot) continue;
      if (e.shadowRoot.textContent.includes('Preview while you drag')) return true;
      roots.push(e.shadowRoot);
    }
  }
  return false;
}"""


def parse_presets(text: str, known: tuple[str, ...]) -> list[str]:
    """``all`` or comma-separated preset names -> the names, in the order given.
    Raises ValueError naming an unknown preset."""
    if text.strip() == "all":
        return list(known)
    names = [n.strip() for n in text.split(",") if n.strip()]
    unknown = [n for n in names if n not in known]
    if unknown or not names:
        raise ValueError(f"unknown preset {', '.join(unknown) or '(none given)'}; "
                         f"known: all, {', '.join(known)}")
    return names


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    """The command line (``--quick``: 3 key steps, 2 page loads, unless given: p95 is
    then the largest of 3, a first look rather than a figure to quote)."""
    from core.presets import preset_names

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--url", help="an explorer already running (default: start one)")
    parser.add_argument("--repeats", type=int, default=None,
                        help="key steps per slider (default 9, 3 with --quick)")
    parser.add_argument("--loads", type=int, default=None,
                        help="page loads (default 5, 2 with --quick)")
    parser.add_argument("--presets", default="all",
                        help="'all' (default) or preset names separated by commas")
    parser.add_argument("--quick", action="store_true",
                        help="fewer steps and page loads: all presets in ~6 min on 2 cores")
    parser.add_argument("--json", help="also write the numbers to this file")
    parser.add_argument("--from-json", metavar="FILE",
                        help="write the Markdown table from the --json of a run, no browser")
    parser.add_argument("--markdown", default=None,
                        help=f"the table's Markdown file (default {RESULTS.relative_to(ROOT)}"
                             f", {SWITCH_RESULTS.relative_to(ROOT)} with --switches-only)")
    parser.add_argument("--switches-only", action="store_true",
                        help="measure the preset switches alone, --rounds times each")
    parser.add_argument("--rounds", type=int, default=3,
                        help="with --switches-only: switches to each preset (default 3)")
    args = parser.parse_args(argv)
    if args.markdown is None:
        args.markdown = str(SWITCH_RESULTS if args.switches_only else RESULTS)
    try:
        args.presets = parse_presets(args.presets, preset_names())
    except ValueError as err:
        parser.error(f"--presets: {err}")
    if args.repeats is None:
        args.repeats = 3 if args.quick else 9
    if args.loads is None:
        args.loads = 2 if args.quick else 5
    for name in ("repeats", "loads", "rounds"):
        if getattr(args, name) < 1:
            parser.error(f"--{name}: must be at least 1, not {getattr(args, name)}")
    if Path(args.markdown).is_dir():
        parser.error(f"--markdown: {args.markdown} is a folder, not a file name")
    return args


def _fmt(value: float | None, digits: int = 0) -> str:
    return "" if value is None or math.isnan(value) else f"{value:.{digits}f}"


def _run_header(title: str, meta: dict[str, str]) -> list[str]:
    """The first lines of a run's Markdown page: its title, the commit, the date, the load
    averages and the command."""
    return [f"# {title}", "",
            f"Commit `{meta['commit']}`, {meta['date']}, load average {meta['load_before']} "
            f"before, {meta['load_after']} after (2 cores, shared).", "",
            f"    {meta['command']}", ""]


def markdown_report(rows: list[dict], switches: dict[str, float | None],
                    first_page: list[float], meta: dict[str, str]) -> str:
    """The Markdown page of a run: ``rows`` one per (preset, slider) (see
    :func:`measure_row`), ``switches`` preset -> switch time [ms] (None: on the page
    already), ``first_page`` the page load times [ms], ``meta`` commit, date, load
    averages before and after, command."""
    first = _fmt(statistics.median(first_page)) if first_page else ""
    lines = [
        *_run_header("Explorer: latency of every slider kind on every preset", meta),
        "Headless Chromium through Playwright. Key step: ArrowRight (or Left near the end "
        "of the range) on the slider's handle -> the second animation frame after the "
        "pressure plot's data changed (p50, p95 over the steps). Drag: mouse down on the "
        f"handle, {DRAG_MOVES} moves of {DRAG_PX} px {1e3 * DRAG_PAUSE_S:.0f} ms apart, "
        "mouse up; *live* when the pressure plot updated during the drag, *preview* when "
        "those updates were previews (the base elastic at loading, said on the page: the "
        "answer with creep comes on release); *drag took*: "
        "mouse down to up in the page, longer than ~1 s when the page was too busy to "
        "take the moves at once. Page CPU: "
        "median CPU time of the page's main thread per key step. Solve: median of the "
        "server's \"Solved in N ms\". Times in ms.",
        "",
        f"Goals: load and geometry key step p95 <= {GOALS['load']:.0f} ms, no update "
        f"more than {GOALS['release']:.0f} ms after the release, preset switch <= "
        f"{GOALS['preset']:.0f} ms, first page <= {GOALS['first page']:.0f} ms.",
        "",
        f"First page (median of {len(first_page)}): {first} ms (goal "
        f"{GOALS['first page']:.0f}).",
        "",
        "| preset | switch | goal |",
        "| --- | --- | --- |",
    ]
    for preset, ms in switches.items():
        text = "on the page already" if ms is None else _fmt(ms)
        ok = "" if ms is None else (" ok" if ms <= GOALS["preset"] else " **missed**")
        lines.append(f"| {preset} | {text} | {GOALS['preset']:.0f}{ok} |")
    lines += [
        "",
        "| preset | slider | key p50 | key p95 | goal | page CPU | solve | drag | "
        "updates during drag | after release | last after release | drag took | n |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for r in rows:
        name = r["slider"] + (f" ({r['label']})" if r.get("label") else "")
        if r.get("hidden"):
            lines.append(f"| {r['preset']} | {name} | hidden on this preset "
                         "| | | | | | | | | | |")
            continue
        keys = r["key_ms"]
        p95 = percentile(keys, 95)
        goal = GOALS[r["goal"]]
        mark = "" if math.isnan(p95) else (" ok" if p95 <= goal else " **missed**")
        drag = r.get("drag") or {}
        live = drag_kind(drag)
        last = drag.get("last_after_ms")
        last_text = _fmt(last) + ("" if last is None else
                                  " ok" if last <= GOALS["release"] else " **missed**")
        lines.append(
            f"| {r['preset']} | {name} | {_fmt(percentile(keys, 50))} | {_fmt(p95)} | "
            f"{goal:.0f}{mark} | {_fmt(percentile(r['page_cpu'], 50))} | "
            f"{_fmt(percentile(r['solve_ms'], 50))} | {live} | {drag.get('during', '')} | "
            f"{drag.get('after', '')} | {last_text} | {_fmt(drag.get('drag_ms'))} | "
            f"{len(keys)} |")
    lines += ["", "Per preset: the worst key step p95, the sliders whose drag is live, "
              "previewed or on release, and the latest update after a release.", "",
              "| preset | switch | worst key p95 | live | previewed | on release | latest after "
              "release |",
              "| --- | --- | --- | --- | --- | --- | --- |"]
    for preset, summary in preset_summary(rows, switches).items():
        lines.append(f"| {preset} | {summary['switch']} | {summary['worst_p95']} | "
                     f"{summary['live']} | {summary.get('preview', '')} | {summary['release']} | "
                     f"{summary['latest']} |")
    notes = [r for r in rows if r.get("note")]
    if notes:
        lines += ["", "Notes:", ""]
        lines += [f"- {r['preset']}, {r['slider']}: {r['note']}" for r in notes]
    return "\n".join(lines) + "\n"


def switch_report(samples: dict[str, list[float]], first_page: list[float],
                  meta: dict[str, str]) -> str:
    """The Markdown page of ``--switches-only``: per preset its switch times [ms] (one per
    round; a switch to the preset already on the page is no sample)."""
    lines = [
        *_run_header("Explorer: preset switches, each measured several times", meta),
        "Headless Chromium through Playwright: the preset chosen in the sidebar's selector "
        "-> the second animation frame after the pressure plot's last data change "
        "(updates waited for until none came for "
        f"{1e3 * QUIET_S:.0f} ms). The presets are chosen in turn, round after round, so "
        "each switch comes from another preset, as a user's would. Times in ms; the goal "
        f"is {GOALS['preset']:.0f} ms.",
        "",
        f"First page (median of {len(first_page)}): "
        f"{_fmt(statistics.median(first_page)) if first_page else ''} ms.",
        "",
        "| preset | median | least | largest | n | goal |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for preset, values in samples.items():
        kept = [v for v in values if not math.isnan(v)]
        if not kept:
            lines.append(f"| {preset} | | | | 0 | {GOALS['preset']:.0f} |")
            continue
        median = statistics.median(kept)
        mark = " ok" if median <= GOALS["preset"] else " **missed**"
        lines.append(f"| {preset} | {_fmt(median)} | {_fmt(min(kept))} | {_fmt(max(kept))} "
                     f"| {len(kept)} | {GOALS['preset']:.0f}{mark} |")
    return "\n".join(lines) + "\n"


def preset_summary(rows: list[dict], switches: dict[str, float | None]
                   ) -> dict[str, dict[str, str]]:
    """Per preset, as text: its switch time [ms], the slider with the worst key step p95
    [ms], the sliders live on a drag and those that wait for the release, and the latest
    update after a release [ms] (with its slider)."""
    out: dict[str, dict[str, str]] = {}
    for preset in dict.fromkeys([*switches, *(r["preset"] for r in rows)]):
        mine = [r for r in rows if r["preset"] == preset and not r.get("hidden")]
        worst = max(mine, key=lambda r: _nan_low(percentile(r["key_ms"], 95)), default=None)
        dragged = [r for r in mine if r.get("drag")]
        latest = max(dragged, key=lambda r: r["drag"]["last_after_ms"], default=None)
        ms = switches.get(preset)
        out[preset] = {
            "switch": "on the page already" if ms is None else _fmt(ms),
            "worst_p95": "" if worst is None else
            f"{_fmt(percentile(worst['key_ms'], 95))} ({worst['slider']})",
            "live": ", ".join(r["slider"] for r in dragged if drag_kind(r["drag"]) == "live"),
            "preview": ", ".join(r["slider"] for r in dragged
                                 if drag_kind(r["drag"]) == "preview"),
            "release": ", ".join(r["slider"] for r in dragged if r["drag"]["during"] == 0),
            "latest": "" if latest is None else
            f"{_fmt(latest['drag']['last_after_ms'])} ({latest['slider']})"}
    return out


def _nan_low(value: float) -> float:
    return -math.inf if math.isnan(value) else value


def _find_handle(page, kind: SliderKind):
    """The handle of ``kind`` shown on the page (its tab open) and the label that found
    it, or (None, '') when the preset hides it."""
    if kind.css:
        handle = page.locator(f"{kind.css} .noUi-handle").first
        return (handle, "") if handle.count() and handle.is_visible() else (None, "")
    for label in kind.labels:
        # the innermost layout holding the label and a slider: the slider of that label
        handle = page.locator(
            "div.bk-panel-models-layout-Column, div.bk-Slider", has_text=label
        ).filter(has=page.locator(".noUi-handle")).last.locator(".noUi-handle").first
        if handle.count() and handle.is_visible():
            return handle, label if len(kind.labels) > 1 else ""
    return None, ""


def _direction(handle) -> tuple[str, int]:
    """Key and pixel sign that move the handle away from the nearer end of its range."""
    now, lo, hi = (float(handle.get_attribute(a) or "nan")
                   for a in ("aria-valuenow", "aria-valuemin", "aria-valuemax"))
    if hi > lo and (now - lo) / (hi - lo) > 0.6:
        return "ArrowLeft", -1
    return "ArrowRight", 1


#: Whether the page's busy spinner turns (``explorer/views/busy.py``: a solve running for
#: more than its 250 ms, newer than the result on screen).
JS_BUSY = """() => {
  for (const m of Bokeh.documents[0].all_models)
    if (m.css_classes && m.css_classes.includes('busy-spinner'))
      return (m.text || '').includes('cp-spinner');
  return false;
}"""


def _wait_quiet(page, since: float, need_one: bool, timeout_s: float) -> None:
    """Wait until no update of the pressure plot came for ``QUIET_S`` after the page time
    ``since`` [ms] (and, with ``need_one``, at least one came after it) while the page
    says no solve is running. Quiet alone ended the wait for a solve of more than
    ``QUIET_S``: the stepped punch's coating-modulus drag ends where the outer steps lift
    off, and its last answer came 1-3 s after the release, unseen ("none after")."""
    until = time.monotonic() + timeout_s
    while time.monotonic() < until:
        last, now, busy = page.evaluate(
            "() => [window.__updates.length ? window.__updates[window.__updates.length - 1]"
            " : -1, performance.now(), (" + JS_BUSY + ")()]")
        if need_one and last <= since:
            time.sleep(0.1)
            continue
        if now - max(last, since) > 1e3 * QUIET_S and not busy:
            return
        time.sleep(0.1)


def measure_drag(page, handle, sign: int, timeout_s: float) -> dict[str, float]:
    """Drag ``handle`` by ``DRAG_MOVES`` moves of ``sign * DRAG_PX`` pixels; the pressure
    plot's updates during the drag and after the release (:func:`drag_summary`)."""
    page.evaluate("() => { window.__updates = []; window.__down = window.__up = null; }")
    handle.scroll_into_view_if_needed()
    box = handle.bounding_box()
    x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    page.mouse.move(x, y)
    page.mouse.down()
    start = time.monotonic()
    for k in range(1, DRAG_MOVES + 1):
        # on a schedule, not a pause after each move: a move's own round trip to the
        # browser (tens of ms on a loaded machine) would stretch the drag to 2-3 s
        time.sleep(max(0.0, start + k * DRAG_PAUSE_S - time.monotonic()))
        page.mouse.move(x + sign * DRAG_PX * k, y)
    previewed = bool(page.evaluate(JS_PREVIEWING))
    page.mouse.up()
    down, up, during = page.evaluate(
        "() => [window.__down, window.__up, window.__updates.length]")
    _wait_quiet(page, up, need_one=during == 0, timeout_s=timeout_s)
    return drag_summary(page.evaluate("() => window.__updates"), down, up, previewed)


def switch_preset(page, label: str, timeout_s: float) -> float | None:
    """Choose ``label`` in the preset selector; the time [ms] from the choice to the last
    frame showing the new scene's pressure (None: the preset is on the page already)."""
    page.locator(".bk-tab", has_text="Scene").first.click()
    select = page.locator(".preset-select select").first
    select.wait_for(state="visible", timeout=60_000)
    if select.evaluate("s => s.options[s.selectedIndex].text") == label:
        return None
    page.evaluate("() => { window.__updates = []; }")
    select.evaluate("s => s.addEventListener('change', "
                    "() => { window.__switched = performance.now(); }, {once: true})")
    select.select_option(label=label)
    t0 = page.evaluate("() => window.__switched || performance.now()")
    _wait_quiet(page, t0, need_one=True, timeout_s=timeout_s)
    updates = [t for t in page.evaluate("() => window.__updates") if t > t0]
    return (max(updates) - t0) if updates else float("nan")


def reset_scene(page, timeout_s: float) -> None:
    """Back to the preset as loaded (the Scene tab's reset button), its answer on screen:
    each row starts from the preset, not from where the last row's drag left it (on
    ``stepped_punch`` the coating-modulus drag ends in a stiffer coating whose outer parts
    lift off beside the steps, 5-12 s a solve, which the next rows then measured)."""
    page.locator(".bk-tab", has_text="Scene").first.click()
    page.evaluate("() => { window.__updates = []; }")
    t0 = page.evaluate("() => performance.now()")
    page.locator(".reset-button button").first.click()
    _wait_quiet(page, t0, need_one=True, timeout_s=timeout_s)


def measure_row(page, preset: str, kind: SliderKind, repeats: int, cdp,
                timeout_s: float) -> dict:
    """Key steps and a drag of ``kind``'s slider on the page (the preset on it)."""
    page.locator(".bk-tab", has_text=kind.tab).first.click()
    time.sleep(0.3)
    row = {"preset": preset, "slider": kind.name, "goal": kind.goal, "key_ms": [],
           "page_cpu": [], "solve_ms": [], "parts": [], "drag": None}
    handle, label = _find_handle(page, kind)
    if handle is not None and kind.css == ".load-0-value":
        # the first given quantity of the statement on screen ("tilt + force given")
        statement = page.locator(".statement-select select").first.evaluate(
            "s => s.options[s.selectedIndex].text")
        label = statement.split(" + ")[0]
    row["label"] = label
    if handle is None:
        row["hidden"] = True
        return row
    key, sign = _direction(handle)
    since = time.monotonic()
    row["key_ms"], row["solve_ms"] = measure_slider(
        page, kind.tab, kind.css, repeats, key, cdp, row["page_cpu"], row["parts"],
        handle=handle, timeout_ms=1e3 * timeout_s)
    row["window"] = (since, time.monotonic())
    if len(row["key_ms"]) < repeats:
        row["note"] = (f"{len(row['key_ms'])} of {repeats} key steps updated the plot "
                       f"within {timeout_s:.0f} s")
    _wait_quiet(page, page.evaluate("() => performance.now()"), False, timeout_s)
    row["drag"] = measure_drag(page, handle, sign, timeout_s)
    return row


def _git_commit() -> str:
    try:
        return subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, text=True,
                              capture_output=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def _load_average() -> str:
    return " / ".join(f"{v:.2f}" for v in os.getloadavg())


def main(argv: list[str] | None = None) -> None:
    args = parse_args(argv)
    if args.from_json:
        # the table again from a run's numbers (e.g. after a change of its layout)
        data = json.loads(Path(args.from_json).read_text())
        Path(args.markdown).write_text(markdown_report(
            data["rows"], data["preset_switch"], data["first_page"], data["meta"]))
        return
    from playwright.sync_api import sync_playwright

    from explorer.model.presets import preset_label, presets

    scenes = presets()
    meta = {"commit": _git_commit(),
            "date": datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
            "load_before": _load_average(),
            "command": "OPENBLAS_NUM_THREADS=" + os.environ.get("OPENBLAS_NUM_THREADS", "")
                       + " python -m benchmarks.explorer_latency "
                       + " ".join(sys.argv[1:] if argv is None else argv)}
    server = None
    url = args.url
    trace = Path(tempfile.mkdtemp()) / "trace.jsonl"
    if url is None:
        server = ExplorerProcess(ready_timeout=300, stop_timeout=20,
                                 env={"EXPLORER_TRACE": str(trace)})
        try:
            url = server.start().url
        except ExplorerStartError as err:
            raise SystemExit(str(err)) from None
    loads: list[float] = []
    rows: list[dict] = []
    switches: dict[str, float | None] = {}
    samples: dict[str, list[float]] = {}
    timeout_s = 60.0
    try:
        with sync_playwright() as p, tempfile.TemporaryDirectory() as profile:
            context = p.chromium.launch_persistent_context(
                profile, executable_path=CHROMIUM, headless=True, args=CHROMIUM_ARGS,
                viewport={"width": 1500, "height": 1300})
            for _ in range(args.loads + 1):
                page = context.new_page()
                page.goto(url + "/app", wait_until="commit")
                handle = page.wait_for_function(READY, timeout=120_000, polling=20)
                loads.append(handle.json_value())
                page.close()
            loads = loads[1:]  # the first warms the browser's cache

            page = context.new_page()
            page.goto(url + "/app")
            page.wait_for_function(READY, timeout=120_000)
            # the sidebar tabs not yet opened are filled once the page has been left
            # alone for a while (explorer.views.tabs); measured during that, the first
            # moves took seconds: the steady state is what a user dragging a slider meets
            time.sleep(FILL_TABS_AFTER_MS / 1000 + 5)
            page.evaluate(INSTRUMENT)
            cdp = context.new_cdp_session(page)
            cdp.send("Performance.enable")
            if args.switches_only:
                for _ in range(args.rounds):
                    for preset in args.presets:
                        ms = switch_preset(page, preset_label(preset, scenes[preset]),
                                           timeout_s)
                        if ms is not None:
                            samples.setdefault(preset, []).append(ms)
                        print(f"{preset}: switch {_fmt(ms) or 'none'} ms", file=sys.stderr)
            for preset in [] if args.switches_only else args.presets:
                switches[preset] = switch_preset(page, preset_label(preset, scenes[preset]),
                                                 timeout_s)
                print(f"{preset}: switch {_fmt(switches[preset]) or 'none'} ms",
                      file=sys.stderr)
                moved = False
                for kind in SLIDER_KINDS:
                    if moved:
                        reset_scene(page, timeout_s)
                    row = measure_row(page, preset, kind, args.repeats, cdp, timeout_s)
                    rows.append(row)
                    moved = not row.get("hidden")
                    print(f"  {kind.name}: "
                          + ("hidden" if row.get("hidden") else
                             f"p50 {_fmt(percentile(row['key_ms'], 50))} "
                             f"p95 {_fmt(percentile(row['key_ms'], 95))} drag {row['drag']}"),
                          file=sys.stderr)
            context.close()
    finally:
        if server is not None:
            server.stop()
    meta["load_after"] = _load_average()
    if args.switches_only:
        text = switch_report({p: samples.get(p, []) for p in args.presets}, loads, meta)
        Path(args.markdown).parent.mkdir(parents=True, exist_ok=True)
        Path(args.markdown).write_text(text)
        print("\n" + text)
        if args.json:
            Path(args.json).write_text(json.dumps(
                {"meta": meta, "first_page": loads, "preset_switch_samples": samples,
                 "goals": GOALS}, indent=2, default=str))
        return

    measured = [r for r in rows if not r.get("hidden")]
    print(f"{'control':44s} {'median':>9s} {'p95':>9s} {'max':>9s} {'goal':>7s} "
          f"{'core solve':>11s} {'page CPU':>9s}  (ms; core solve: median of the "
          "server's own timing; page CPU: median of the main thread's)")
    if loads:
        print(f"{'first page load':44s} {statistics.median(loads):9.0f} "
              f"{percentile(loads, 95):9.0f} {max(loads):9.0f} {GOALS['first page']:7.0f}"
              f" {'':11s} {'':9s}  n={len(loads)}")
    for r in measured:
        name, values = f"{r['preset']}: {r['slider']}", r["key_ms"]
        if values:
            print(f"{name:44s} {statistics.median(values):9.0f} {percentile(values, 95):9.0f} "
                  f"{max(values):9.0f} {GOALS[r['goal']]:7.0f} "
                  f"{_fmt(percentile(r['solve_ms'], 50)):>11s} "
                  f"{_fmt(percentile(r['page_cpu'], 50)):>9s}  n={len(values)}")
    print("\nwhere the time of a move went (medians, ms): key press -> first message sent; "
          "sent -> new data in the page (server, network); data -> frame shown (page)")
    for r in measured:
        if r["parts"]:
            sent, server_part, page_part = (statistics.median(p[k] for p in r["parts"])
                                            for k in range(3))
            print(f"{r['preset'] + ': ' + r['slider']:44s} {sent:6.0f} {server_part:9.0f} "
                  f"{page_part:9.0f}")
    if trace.exists():
        print("\ninside the server (medians, ms after the websocket message in; "
              "explorer/solving/trace.py):")
        print(f"{'control':44s} " + " ".join(f"{s:>12s}" for s in STEPS[1:])
              + f" {'server CPU':>11s}")
        for r in measured:
            if "window" not in r:
                continue
            r["server_cpu"] = used = []
            r["server_steps"] = moves = server_steps(trace, *r["window"], used)
            if moves:
                cpu_text = f"{statistics.median(used):11.1f}" if used else f"{'':11s}"
                print(f"{r['preset'] + ': ' + r['slider']:44s} " + " ".join(
                    f"{statistics.median(m[s] for m in moves):12.1f}" for s in STEPS[1:])
                    + f" {cpu_text}  n={len(moves)}")
        print("(server CPU: the server process's CPU time from the websocket message in "
              "to the patch written, all its threads; the solve runs in a worker)")
    text = markdown_report(rows, switches, loads, meta)
    Path(args.markdown).parent.mkdir(parents=True, exist_ok=True)
    Path(args.markdown).write_text(text)
    print("\n" + text)
    if args.json:
        Path(args.json).write_text(json.dumps(
            {"meta": meta, "first_page": loads, "preset_switch": switches, "rows": rows,
             "goals": GOALS}, indent=2, default=str))


if __name__ == "__main__":
    main()
