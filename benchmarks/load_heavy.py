"""The ``--heavy`` variant of ``benchmarks/load_test.py``: heavy work beside the movers,
and a liveness probe that times the server's event loop.

While the crowd of ``--sessions`` movers moves sliders, three more sessions, real
Chromium pages (Playwright, one browser, in a process of their own so that their driver
does not share the movers' interpreter), do the heavy things a page can ask for:

- **study**: opens a view link holding the Study tab's settings, a 20 x 20 study of the
  default preset (its base creeps) over the base thickness H and the punch half-width a:
  :data:`explorer.model.study.MAX_POINTS` points, each a new geometry with its own
  kernel. It presses "Run study", waits for "Done", downloads the study's CSV, and runs
  it again while the movers move (a later run still going when they stop is cancelled);
- **FE check**: opens the Coating tab and presses "check the coating model" (the
  resolved finite-element check, one at a time per server), again and again;
- **files**: opens a heavy view link (the default preset at
  :data:`core.limits.MAX_SCENE_TIMES` output times, with three pinned variants, solved
  again when the link opens), downloads the q(x, t) CSV (~15 MB) and reloads the link,
  again and again.

The pages open before the crowd arrives; their work starts when the last mover is ready
and stops when the movers stop (the first study is awaited to its end). A probe, also a
process of its own, GETs the server's liveness URL (:data:`LIVENESS_PATH`, answered by
the event loop without building a page) every :data:`PROBE_PERIOD_S` from the server's
start to the end of the run, and records each answer's latency; when ``py-spy`` is
installed, a wait over :data:`DUMP_AFTER_S` has the server's stacks dumped, which say
what its event loop was doing meanwhile. The report (:func:`heavy_lines`) gives the
goals of issue "Reliability" (movers' p95 at most 2x the single session, no answer lost,
the probe under :data:`PROBE_GOAL_S`, the memory after all sessions closed within
:data:`MEMORY_GOAL` of its level before the heavy pages and the crowd opened), the heavy
sessions' outcomes, the movers' and the probe's latencies by what ran beside them, and
the dumps grouped by the project's code the loop was in.
"""

from __future__ import annotations

import asyncio
import contextlib
import copy
import json
import multiprocessing
import os
import re
import tempfile
import threading
import time
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

#: The server's liveness endpoint (``liveness=True`` of ``python -m explorer``'s server:
#: Panel's handler, which answers from the event loop without building a document).
LIVENESS_PATH = "/liveness"
#: The probe's period [s] and the most it waits for one answer [s].
PROBE_PERIOD_S = 0.1
PROBE_TIMEOUT_S = 30.0
#: With py-spy installed: a probe unanswered after DUMP_AFTER_S [s] has the server's
#: stacks dumped (what its event loop is doing), at most one per DUMP_EVERY_S [s] and
#: MOST_DUMPS in all (a dump stops the server for a few ms).
DUMP_AFTER_S = 0.5
DUMP_EVERY_S = 1.0
MOST_DUMPS = 400
#: Frames kept of a thread's stack (Bokeh's validation of a page recurses deep: 40
#: frames lost the project's frames below it).
MOST_FRAMES = 400
#: Goals of issue "Reliability": the probe's answer under this [s] while heavy work runs;
#: the movers' p95 at most this many times the single session's; the server's memory
#: after all sessions closed within this fraction of its level before them (the single
#: session closed, the heavy pages and the crowd not yet opened).
PROBE_GOAL_S = 0.2
P95_GOAL = 2.0
MEMORY_GOAL = 0.10
#: Sidebar tabs by their index in a link (``explorer.app.ExplorerApp._build_sidebar``).
COATING_TAB, FILES_TAB, STUDY_TAB = 2, 6, 8
#: The study: 20 x 20 values of the base thickness H [m] and the punch half-width a [m]
#: around the default preset's 4 m and 1 m (every point a new kernel: ~0.08 s of CPU on
#: a quiet core, measured with core.study.sweep, so ~35 s for the 400).
STUDY_AXES = (["base.thickness", 2.0, 6.0, 20, "linear"],
              ["punch.half_width", 0.5, 1.5, 20, "linear"])
#: The heavy link's pinned variants: the force [N/m] of each.
PIN_FORCES = (400e3, 600e3, 700e3)
#: Longest wait for one heavy action (a study may wait for others' turns and run up to
#: explorer.solving.study_runner.STUDY_TIMEOUT_S = 600 s) [s].
ACTION_TIMEOUT_S = 660.0
#: Pause between two heavy actions of a session [s].
HEAVY_PAUSE_S = 2.0


# ------------------------------------------------------------------------------- links


def _preset() -> dict[str, Any]:
    from explorer.model.presets import DEFAULT_PRESET, presets

    return presets()[DEFAULT_PRESET]


def study_link(url: str) -> str:
    """A link to the default preset with the Study tab open and :data:`STUDY_AXES` typed."""
    from explorer.model.links import encode_scene

    settings = {"axes": [list(axis) for axis in STUDY_AXES], "output": "settlement"}
    return f"{url}/app?tab={STUDY_TAB}&study={encode_scene(settings)}"


def check_link(url: str) -> str:
    """A link to the default preset with the Coating tab open."""
    return f"{url}/app?tab={COATING_TAB}"


def files_link(url: str) -> str:
    """The heavy view link: the default preset at the most output times a scene may have,
    three pinned variants, the Files tab open."""
    from core.limits import MAX_SCENE_TIMES
    from explorer.model.links import encode_scene

    scene = _preset()
    scene["times"]["count"] = MAX_SCENE_TIMES
    pins = []
    for force in PIN_FORCES:
        pin = copy.deepcopy(scene)
        pin["loading"]["force"] = force
        pins.append(pin)
    return (f"{url}/app?tab={FILES_TAB}&scene={encode_scene(scene)}"
            f"&pin={encode_scene({'pins': pins})}")


# ------------------------------------------------------------------------------- probe


def _dump_stacks(py_spy: str, pid: int) -> dict[str, Any] | None:
    """The server's main thread (its event loop) and, if another thread holds the GIL,
    that thread: status and frames (innermost first), from ``py-spy dump``."""
    import subprocess

    try:
        out = subprocess.run([py_spy, "dump", "--pid", str(pid)], capture_output=True,
                             text=True, timeout=20).stdout
    except (OSError, subprocess.SubprocessError):
        return None
    threads: list[dict[str, Any]] = []
    for line in out.splitlines():
        found = re.match(r'Thread \S+ \(([^)]*)\): "(.*)"', line)
        if found:
            threads.append({"status": found.group(1), "name": found.group(2), "frames": []})
        elif threads and line.startswith("    ") and len(threads[-1]["frames"]) < MOST_FRAMES:
            threads[-1]["frames"].append(line.strip())
    main = next((t for t in threads if t["name"] == "MainThread"), None)
    if main is None:
        return None
    holder = next((t for t in threads if "gil" in t["status"] and t is not main), None)
    return {"main": main, "holder": holder}


def _probe_main(url: str, path: str, stop: Any, period: float, timeout: float,
                py_spy: str | None, pid: int) -> None:
    """The probe's process: GET ``url`` every ``period`` s until ``stop``; one line per
    request to ``path``: monotonic start [s], latency [s], 1 if answered 200 else 0.

    With ``py_spy`` (the program's path), a request unanswered after
    :data:`DUMP_AFTER_S` has the server ``pid``'s stacks dumped (at most one a
    :data:`DUMP_EVERY_S`, :data:`MOST_DUMPS` in all), one JSON line each to
    ``path + ".stacks"``: what the event loop was doing while the probe waited."""
    import urllib.request

    opener = urllib.request.build_opener(urllib.request.ProxyHandler({}))  # loopback only
    pending: list[float | None] = [None]  # when the request in flight was sent

    def watch() -> None:
        dumps, last = 0, 0.0
        with open(path + ".stacks", "w", encoding="utf-8") as fh:
            while not stop.is_set() and dumps < MOST_DUMPS:
                sent = pending[0]
                now = time.monotonic()
                if sent is not None and now - sent > DUMP_AFTER_S and now - last > DUMP_EVERY_S:
                    last = now
                    stacks = _dump_stacks(py_spy, pid)
                    if stacks is not None:
                        dumps += 1
                        fh.write(json.dumps({"t": now, "sent": sent, **stacks}) + "\n")
                        fh.flush()
                stop.wait(0.05)

    if py_spy:
        threading.Thread(target=watch, name="stall-dumps", daemon=True).start()
    due = time.monotonic()
    with open(path, "w", encoding="ascii") as fh:
        while not stop.is_set():
            start = time.monotonic()
            pending[0] = start
            ok = 0
            try:
                with opener.open(url, timeout=timeout) as answer:
                    answer.read()
                    ok = int(answer.status == 200)
            except Exception:  # noqa: BLE001 - a failed probe is a sample, not an error
                ok = 0
            pending[0] = None
            fh.write(f"{start:.4f} {time.monotonic() - start:.5f} {ok}\n")
            fh.flush()
            # a late answer delays the next request, it does not pile them up
            due = max(due + period, time.monotonic())
            stop.wait(max(0.0, due - time.monotonic()))


class Probe:
    """The liveness probe in a process of its own (the driver's threads do not delay
    it); :meth:`samples` reads what it recorded, :meth:`stacks` the server's stacks
    dumped during its long waits (when ``py-spy`` is installed)."""

    def __init__(self, url: str, server_pid: int, period: float = PROBE_PERIOD_S,
                 timeout: float = PROBE_TIMEOUT_S) -> None:
        import shutil

        ctx = multiprocessing.get_context("spawn")
        self._dir = tempfile.TemporaryDirectory(prefix="load-probe-")
        self.path = Path(self._dir.name) / "probe.txt"
        self.py_spy = shutil.which("py-spy")
        self._stop = ctx.Event()
        self.process = ctx.Process(target=_probe_main, name="liveness-probe", daemon=True,
                                   args=(url + LIVENESS_PATH, str(self.path), self._stop,
                                         period, timeout, self.py_spy, server_pid))
        self.process.start()

    def stop(self) -> None:
        self._stop.set()
        self.process.join(PROBE_TIMEOUT_S + 5)
        if self.process.is_alive():
            self.process.kill()
            self.process.join(5)

    def samples(self) -> list[tuple[float, float, bool]]:
        """(monotonic start [s], latency [s], answered) of each request."""
        out = []
        if self.path.exists():
            for line in self.path.read_text(encoding="ascii").splitlines():
                parts = line.split()
                if len(parts) == 3:
                    out.append((float(parts[0]), float(parts[1]), parts[2] == "1"))
        return out

    def stacks(self) -> list[dict[str, Any]]:
        """The dumps: ``t`` (monotonic [s]), ``sent`` (the waiting request's start),
        ``main`` and ``holder`` (threads: ``status``, ``name``, ``frames``)."""
        path = Path(str(self.path) + ".stacks")
        if not path.exists():
            return []
        return [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines()
                if line.strip()]

    def close(self) -> None:
        self._dir.cleanup()


# ---------------------------------------------------------------------- heavy sessions


class _Log:
    """The heavy sessions' actions, one JSON line each in a file (kept if the process
    dies): kind, session, monotonic start and end [s], ok, detail, bytes."""

    def __init__(self, path: str) -> None:
        self.path = path

    def add(self, kind: str, session: str, start: float, end: float, ok: bool,
            detail: str = "", size: int = 0) -> None:
        with open(self.path, "a", encoding="utf-8") as fh:
            fh.write(json.dumps({"kind": kind, "session": session, "start": start,
                                 "end": end, "ok": ok, "detail": detail[:300],
                                 "bytes": size}) + "\n")


# The text of a Panel pane as shown: its shadow root's, without its style sheets.
JS_PANE_TEXT = """e => {
  const root = e.shadowRoot || e;
  let text = root.textContent;
  for (const style of root.querySelectorAll('style')) text = text.replace(style.textContent, '');
  return text.trim();
}"""


async def _text(page: Any, css: str) -> str:
    try:
        return str(await page.locator(css).first.evaluate(JS_PANE_TEXT))
    except Exception:  # noqa: BLE001 - not on the page (yet)
        return ""


async def _until(check: Callable[[], Any], timeout: float, period: float = 0.2) -> bool:
    """Poll the coroutine function ``check`` until it is true; False after ``timeout``."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if await check():
            return True
        await asyncio.sleep(period)
    return False


async def _open(page: Any, link: str) -> None:
    from benchmarks.load_test import READY

    await page.goto(link, wait_until="commit", timeout=120_000)
    await page.wait_for_function(READY, timeout=180_000, polling=200)


async def _wait_go(go: Any, stop: Any) -> bool:
    while not go.is_set():
        if stop.is_set():
            return False
        await asyncio.sleep(0.1)
    return not stop.is_set()


async def _download(page: Any, button: Any) -> tuple[int, float]:
    """Press a download button; (bytes, seconds to the saved file)."""
    start = time.monotonic()
    async with page.expect_download(timeout=1e3 * ACTION_TIMEOUT_S) as info:
        await button.click()
    download = await info.value
    path = await download.path()
    return os.path.getsize(path), time.monotonic() - start


# A study's status while it waits or runs, and once it has ended ("Done: ...", or why not).
_STUDY_BUSY = ("starting", "waiting", "running", "paused")
_STUDY_ENDED = ("Done:", "Not run", "cancelled", "fail", "stopped", "could not")


async def _logged_page(context: Any, name: str, log: _Log) -> Any:
    """A new page of ``context`` whose script errors go to ``log`` under ``name``."""
    page = await context.new_page()
    page.on("pageerror", lambda e: log.add("page error", name, time.monotonic(),
                                           time.monotonic(), False, str(e)))
    return page


async def _study_session(context: Any, url: str, log: _Log, ready: Callable[[], None],
                         go: Any, stop: Any) -> None:
    name = "study"
    page = await _logged_page(context, name, log)
    try:
        await _open(page, study_link(url))
        run = page.locator(".study-run button").first
        await run.wait_for(timeout=120_000)
        counts = [page.locator(f".study-p{n}-count input").first for n in (1, 2)]

        async def typed() -> bool:
            return [await c.input_value() for c in counts] == ["20", "20"]

        if not await _until(typed, 120):
            log.add("study", name, time.monotonic(), time.monotonic(), False,
                    "the link's study settings did not show")
            return
    finally:
        ready()
    if not await _wait_go(go, stop):
        await page.close()
        return
    first = True
    while not stop.is_set():
        start = time.monotonic()
        await run.click()

        async def busy() -> bool:
            status = await _text(page, ".study-status")
            return status.startswith(_STUDY_BUSY) or not await run.is_enabled()

        async def ended() -> bool:
            status = await _text(page, ".study-status")
            return any(s in status for s in _STUDY_ENDED) and await run.is_enabled()

        async def ended_or_stop(first: bool = first) -> bool:
            return (not first and stop.is_set()) or await ended()

        seen = await _until(busy, 60, period=0.05)
        done = seen and await _until(ended_or_stop, ACTION_TIMEOUT_S)
        status = " ".join((await _text(page, ".study-status")).split())
        if done and not await ended():
            # a repeat still running when the movers stopped: cancelled, not awaited
            await page.locator(".study-cancel button").first.click()
            await _until(ended, 60)
            log.add("study", name, start, time.monotonic(), False,
                    "cancelled when the movers stopped: " + status)
            break
        ok = done and status.startswith("Done:")
        log.add("study", name, start, time.monotonic(), ok,
                status if done else "the press was not seen within 60 s: " + status
                if not seen else f"not ended within {ACTION_TIMEOUT_S:g} s: {status}")
        if not ok:
            break
        first = False
        button = page.locator(".study-csv button").first

        async def offered(button: Any = button) -> bool:
            return await button.is_enabled()

        if await _until(offered, 120):
            start = time.monotonic()
            try:
                size, _ = await _download(page, button)
                log.add("study CSV", name, start, time.monotonic(), True, size=size)
            except Exception as exc:  # noqa: BLE001 - recorded
                log.add("study CSV", name, start, time.monotonic(), False, repr(exc))
        else:
            log.add("study CSV", name, time.monotonic(), time.monotonic(), False,
                    "the CSV was not offered within 120 s")
        await asyncio.sleep(HEAVY_PAUSE_S)
    await page.close()


# The FE check's result while it waits or solves, and once it has ended.
_CHECK_BUSY = ("Solving", "Waiting")
_CHECK_ENDED = ("model error: measured", "Not checked", "check failed")


async def _check_session(context: Any, url: str, log: _Log, ready: Callable[[], None],
                         go: Any, stop: Any) -> None:
    name = "FE check"
    page = await _logged_page(context, name, log)
    try:
        await _open(page, check_link(url))
        button = page.locator(".coating-check-button button").first
        await button.wait_for(timeout=120_000)
    finally:
        ready()
    if not await _wait_go(go, stop):
        await page.close()
        return
    while not stop.is_set():
        start = time.monotonic()
        await button.click()

        async def busy() -> bool:
            now = await _text(page, ".coating-check-result")
            return any(s in now for s in _CHECK_BUSY) or not await button.is_enabled()

        async def ended() -> bool:
            now = await _text(page, ".coating-check-result")
            return (not any(s in now for s in _CHECK_BUSY)
                    and any(s in now for s in _CHECK_ENDED) and await button.is_enabled())

        seen = await _until(busy, 60, period=0.05)
        done = seen and await _until(ended, ACTION_TIMEOUT_S)
        text = " ".join((await _text(page, ".coating-check-result")).split())
        ok = done and "model error: measured" in text
        # the report's size, time and errors; its table left out
        found = re.search(r"\(([\d,]+ unknowns, [\d.]+ s)\).*?(model error: measured "
                          r"[^%]*%, estimated [^%]*%)", text)
        brief = f"{found.group(2)} ({found.group(1)})" if found else text[:200]
        log.add("FE check", name, start, time.monotonic(), ok,
                brief if done else "the press was not seen within 60 s" if not seen
                else f"not ended within {ACTION_TIMEOUT_S:g} s")
        if not done:
            break
        await asyncio.sleep(HEAVY_PAUSE_S)
    await page.close()


async def _files_session(context: Any, url: str, log: _Log, ready: Callable[[], None],
                         go: Any, stop: Any) -> None:
    name = "files"
    link = files_link(url)
    page = await _logged_page(context, name, log)
    try:
        await _open(page, link)
    finally:
        ready()
    if not await _wait_go(go, stop):
        await page.close()
        return
    while not stop.is_set():
        start = time.monotonic()
        try:
            size, _ = await _download(page, page.get_by_text("Results: q(x, t) (CSV)").first)
            log.add("q(x,t) CSV", name, start, time.monotonic(), True, size=size)
        except Exception as exc:  # noqa: BLE001 - recorded, and the link opened again
            log.add("q(x,t) CSV", name, start, time.monotonic(), False, repr(exc)[:200])
        if stop.is_set():
            break
        start = time.monotonic()
        try:
            await _open(page, link)  # the same address again: a new session
            log.add("view link", name, start, time.monotonic(), True)
        except Exception as exc:  # noqa: BLE001 - recorded; the session ends
            log.add("view link", name, start, time.monotonic(), False, repr(exc)[:200])
            break
    await page.close()


async def _heavy_sessions(url: str, log_path: str, ready: Any, go: Any, stop: Any) -> None:
    from playwright.async_api import async_playwright

    from benchmarks.load_test import CHROMIUM, CHROMIUM_ARGS

    log = _Log(log_path)
    sessions = (_study_session, _check_session, _files_session)
    left = [len(sessions)]

    def one_ready() -> None:
        left[0] -= 1
        if left[0] == 0:
            ready.set()

    with tempfile.TemporaryDirectory(prefix="load-heavy-chromium-") as profile:
        async with async_playwright() as p:
            context = await p.chromium.launch_persistent_context(
                profile, executable_path=CHROMIUM, headless=True, args=CHROMIUM_ARGS,
                viewport={"width": 1400, "height": 900}, accept_downloads=True)
            try:
                tasks = [asyncio.create_task(s(context, url, log, one_ready, go, stop))
                         for s in sessions]
                for task, session in zip(tasks, ("study", "FE check", "files"), strict=True):
                    try:
                        await task
                    except Exception as exc:  # noqa: BLE001 - recorded; the others go on
                        now = time.monotonic()
                        log.add("session failed", session, now, now, False,
                                f"{type(exc).__name__}: {exc}")
            finally:
                await context.close()


def _heavy_main(url: str, log_path: str, ready: Any, go: Any, stop: Any) -> None:
    asyncio.run(_heavy_sessions(url, log_path, ready, go, stop))


class HeavyRun:
    """The probe (from construction) and the heavy sessions (from :meth:`open`), each in
    a process of its own; ``mark`` records events on the load test's clock."""

    def __init__(self, url: str, server_pid: int, mark: Callable[[str], None]) -> None:
        self.url = url
        self.mark = mark
        self.probe = Probe(url, server_pid)
        ctx = multiprocessing.get_context("spawn")
        self._ctx = ctx
        self._dir = tempfile.TemporaryDirectory(prefix="load-heavy-")
        self.log_path = Path(self._dir.name) / "actions.jsonl"
        self._ready, self._go, self._stop = ctx.Event(), ctx.Event(), ctx.Event()
        self.process: Any = None
        self.window: tuple[float, float] | None = None  # monotonic go and stop [s]
        self._timer: threading.Timer | None = None
        self.start_failed = ""

    def open(self, timeout: float = 400.0) -> None:
        """Open the three pages and wait until they are ready (before the crowd)."""
        self.mark("heavy: 3 pages opening")
        self.process = self._ctx.Process(target=_heavy_main, name="heavy-sessions",
                                         daemon=True, args=(self.url, str(self.log_path),
                                                            self._ready, self._go,
                                                            self._stop))
        self.process.start()
        if not self._ready.wait(timeout):
            self.start_failed = f"the heavy pages were not ready within {timeout:g} s"
        self.mark("heavy: pages ready")

    def go(self, clock: Any) -> None:
        """Start the heavy work now and stop it when the movers stop (``clock.end``)."""
        now = time.monotonic()
        end = clock.end if clock.end is not None else clock.hard_end
        self.window = (now, end)
        self._go.set()
        self.mark("heavy: work starts")
        self._timer = threading.Timer(max(end - now, 0.0), self._stopping)
        self._timer.daemon = True
        self._timer.start()

    def _stopping(self) -> None:
        self._stop.set()
        self.mark("heavy: no new work")

    def finish(self, timeout: float = ACTION_TIMEOUT_S + 120) -> None:
        """Wait for the heavy sessions to end their work and close their pages."""
        self._stop.set()
        if self.process is not None:
            self.process.join(timeout)
            if self.process.is_alive():
                self.process.terminate()
                self.process.join(10)
        self.mark("heavy: pages closed")

    def close(self) -> None:
        """Stop everything still running (also after a failure)."""
        if self._timer is not None:
            self._timer.cancel()
        self._stop.set()
        if self.process is not None and self.process.is_alive():
            self.process.terminate()
            self.process.join(10)
            if self.process.is_alive():
                self.process.kill()
        self.probe.stop()

    def actions(self) -> list[dict[str, Any]]:
        if not self.log_path.exists():
            return []
        return [json.loads(line) for line in
                self.log_path.read_text(encoding="utf-8").splitlines() if line.strip()]

    def cleanup(self) -> None:
        self.probe.close()
        self._dir.cleanup()


# ------------------------------------------------------------------------------ report


def _pct(values: list[float]) -> dict[str, float]:
    from benchmarks.load_test import percentiles

    return percentiles(values)


def _overlaps(a0: float, a1: float, spans: Iterable[tuple[float, float]]) -> bool:
    return any(a0 <= s1 and s0 <= a1 for s0, s1 in spans)


def _ms(values: dict[str, float], keys: tuple[str, ...] = ("p50", "p95", "p99")) -> str:
    return " / ".join(f"{values[k]:.0f}" for k in keys)


def heavy_lines(single: Any, crowd: Any, sampler: Any, heavy: HeavyRun) -> tuple[list[str],
                                                                                   dict[str, Any]]:
    """The report's lines on the heavy run, and its figures for the summary (goals)."""
    t0 = sampler.t0
    marks = {label: t for t, label in sampler.marks}
    actions = heavy.actions()
    probe = heavy.probe.samples()
    window = heavy.window or (float("nan"), float("nan"))
    spans: dict[str, list[tuple[float, float]]] = {}
    for action in actions:
        spans.setdefault(action["kind"], []).append((action["start"], action["end"]))
    kinds = ("study", "FE check", "view link", "q(x,t) CSV", "study CSV")
    names = {"study": "a study running", "FE check": "an FE check running",
             "view link": "the heavy view link loading",
             "q(x,t) CSV": "a q(x, t) CSV downloading",
             "study CSV": "a study CSV downloading"}

    def beside(start: float, end: float) -> list[str]:
        return [k for k in kinds if _overlaps(start, end, spans.get(k, []))]

    # the movers: each move spans from its sending to its answer
    moves = [(t - ms / 1e3, t, ms) for t, ms, _ in crowd.moves]
    in_window = [m for m in moves if window[0] <= m[1] <= window[1]]
    s95 = _pct(single.data)["p95"]
    c_all = _pct(crowd.data)
    c_win = _pct([ms for _, _, ms in in_window])
    lost = len(single.lost) + len(crowd.lost)
    sent = single.requests + crowd.requests
    # a lost move waited at least the timeout: counted so, the crowd's p95 with them
    from benchmarks.load_test import UPDATE_TIMEOUT

    c_lost = _pct(crowd.data + [1e3 * UPDATE_TIMEOUT] * len(crowd.lost))

    def move_row(label: str, chosen: list[tuple[float, float, float]]) -> str:
        p = _pct([ms for _, _, ms in chosen])
        return f"| {label} | {len(chosen)} | {_ms(p)} | {p['p95'] / s95:.2f} |"

    # the probe, by phase and by what ran beside it
    def probe_in(a: float, b: float) -> list[tuple[float, float, bool]]:
        return [s for s in probe if a <= s[0] <= b]

    def probe_row(label: str, chosen: list[tuple[float, float, bool]]) -> str:
        ms = [1e3 * s[1] for s in chosen]
        if not ms:
            return f"| {label} | 0 | - | - | - |"
        p = _pct(ms) if len(ms) > 1 else {"p50": ms[0], "p95": ms[0]}
        over = sum(v > 1e3 * PROBE_GOAL_S for v in ms)
        return (f"| {label} | {len(ms)} | {p['p50']:.0f} / {p['p95']:.0f} / {max(ms):.0f} | "
                f"{over} | {sum(not s[2] for s in chosen)} |")

    arrive = t0 + _crowd_arriving(sampler)
    single_span = (t0 + marks["single: all sessions ready"],
                   t0 + marks["single: sessions closed"])
    closed = t0 + marks.get("heavy: pages closed", marks["crowd: sessions closed"])
    heavy_probe = probe_in(*window)
    probe_ms = [1e3 * s[1] for s in heavy_probe]
    probe_p = _pct(probe_ms) if len(probe_ms) > 1 else {"p50": float("nan"),
                                                        "p95": float("nan")}
    probe_max = max(probe_ms, default=float("nan"))

    # memory of the server tree: before any session of the load (the single session
    # closed, the heavy pages and the crowd not yet there), peak, after all closed
    samples = sampler.samples
    opening = marks.get("heavy: 3 pages opening", _crowd_arriving(sampler))
    before_rss = [s[1] for s in samples if s[0] <= opening]
    before = before_rss[-1] if before_rss else samples[0][1]
    # the server's own process apart from its solver and study processes
    own_before = sampler.server_rss[max(len(before_rss) - 1, 0)]
    own_after = sampler.server_rss[-1]
    idle = samples[0][1]
    peak_sample = max(samples, key=lambda s: s[1])
    after = samples[-1][1]
    growth = after / before - 1

    figures = {"p95_ratio": c_all["p95"] / s95, "p95_ratio_lost": c_lost["p95"] / s95,
               "p95_ratio_window": c_win["p95"] / s95,
               "lost": lost, "probe_p50": probe_p["p50"], "probe_p95": probe_p["p95"],
               "probe_max": probe_max, "peak": peak_sample[1], "before": before,
               "after": after, "growth": growth}
    study_runs = [a for a in actions if a["kind"] == "study"]
    checks = [a for a in actions if a["kind"] == "FE check"]

    def took(items: list[dict[str, Any]]) -> str:
        good = [a["end"] - a["start"] for a in items if a["ok"]]
        if not good:
            return "none completed"
        return (f"{len(good)} of {len(items)} completed, "
                + ", ".join(f"{v:.1f}" for v in good) + " s")

    def met(ok: bool) -> str:
        return "met" if ok else "**not met**"

    lines = [
        "",
        "### Heavy sessions beside the movers (`--heavy`)",
        "",
        "Three more sessions, real Chromium pages (Playwright, one browser, in a process "
        "of their own), opened before the crowd; their work ran from the moment the last "
        f"mover was ready (t = {window[0] - t0:.0f} s) until the movers stopped "
        f"(t = {window[1] - t0:.0f} s), the first study awaited to its end, and their pages "
        f"closed at t = {closed - t0:.0f} s:",
        "",
        f"- study: the Study tab of the default preset (its base creeps), "
        f"{STUDY_AXES[0][3]} x {STUDY_AXES[1][3]} points over the base thickness "
        f"{STUDY_AXES[0][1]:g}-{STUDY_AXES[0][2]:g} m and the punch half-width "
        f"{STUDY_AXES[1][1]:g}-{STUDY_AXES[1][2]:g} m (every point a new kernel), run, its "
        "CSV downloaded, run again;",
        "- FE check: the Coating tab's \"check the coating model\", pressed again "
        f"{HEAVY_PAUSE_S:g} s after each answer;",
        "- files: a view link of the default preset at 2000 output times with three pinned "
        "variants (all solved when the link opens), the q(x, t) CSV downloaded, the link "
        "opened again, and so on.",
        "",
        f"A probe (a process of its own) GETs `{LIVENESS_PATH}` every "
        f"{1e3 * PROBE_PERIOD_S:.0f} ms from the server's start and times each answer "
        "(the answer comes from the server's event loop, no page is built).",
        "",
        "| goal | measured | |",
        "| --- | --- | --- |",
        f"| movers' p95 <= {P95_GOAL:g}x the single session | {c_all['p95']:.0f} ms against "
        f"{s95:.0f} ms: **{figures['p95_ratio']:.2f}x** (the whole crowd); "
        f"{figures['p95_ratio_window']:.2f}x for the {len(in_window)} moves answered while "
        f"the heavy sessions worked; with each lost move counted as {UPDATE_TIMEOUT:g} s: "
        f"{c_lost['p95']:.0f} ms, {figures['p95_ratio_lost']:.2f}x | "
        f"{met(max(figures['p95_ratio'], figures['p95_ratio_lost']) <= P95_GOAL)} |",
        f"| no answer lost | **{lost}** of {sent} moves without their update within "
        f"30 s | {met(lost == 0)} |",
        f"| probe < {1e3 * PROBE_GOAL_S:.0f} ms while the heavy sessions work | "
        f"p50 / p95 / max **{probe_p['p50']:.0f} / {probe_p['p95']:.0f} / "
        f"{probe_max:.0f} ms** over {len(heavy_probe)} requests, "
        f"{sum(v > 1e3 * PROBE_GOAL_S for v in probe_ms)} over "
        f"{1e3 * PROBE_GOAL_S:.0f} ms | {met(probe_max < 1e3 * PROBE_GOAL_S)} |",
        f"| server memory after all closed within {100 * MEMORY_GOAL:.0f} % of before "
        f"| {before / 2**20:.0f} MiB before (the single session closed, neither the heavy "
        f"pages nor the crowd there yet), peak {peak_sample[1] / 2**20:.0f} MiB "
        f"(t = {peak_sample[0]:.0f} s), **{after / 2**20:.0f} MiB** after "
        f"(**{100 * growth:+.0f} %**; idle server at its start: {idle / 2**20:.0f} MiB; "
        f"the server's own process {own_before / 2**20:.0f} -> {own_after / 2**20:.0f} MiB, "
        f"its solver and study processes {(before - own_before) / 2**20:.0f} -> "
        f"{(after - own_after) / 2**20:.0f} MiB) | {met(growth <= MEMORY_GOAL)} |",
        "",
        f"Heavy outcomes: studies {took(study_runs)}; FE checks {took(checks)}; "
        f"q(x, t) CSV downloads {took([a for a in actions if a['kind'] == 'q(x,t) CSV'])}; "
        f"heavy view link reloads "
        f"{took([a for a in actions if a['kind'] == 'view link'])}.",
        "",
        "Latency of the movers by what ran beside them (a move counts under every heavy "
        "action that overlapped it), ms:",
        "",
        "| moves | count | p50 / p95 / p99 | p95 / single |",
        "| --- | --- | --- | --- |",
        move_row("single session (reference)", [(0, 0, ms) for ms in single.data]),
        move_row("all of the crowd", moves),
        move_row("crowd arriving, before the heavy work", [m for m in moves
                                                           if m[1] < window[0]]),
        move_row("while the heavy sessions worked", in_window),
        *[move_row(f"... beside {names[k]}", [m for m in in_window if k in beside(m[0], m[1])])
          for k in kinds if spans.get(k)],
        move_row("... beside none of them", [m for m in in_window if not beside(m[0], m[1])]),
        move_row("after the heavy work (the last moves)", [m for m in moves
                                                           if m[1] > window[1]]),
        "",
        "The liveness probe by phase, ms:",
        "",
        "| phase | requests | p50 / p95 / max | over 200 ms | failed |",
        "| --- | --- | --- | --- | --- |",
        probe_row("server idle, then the single session", probe_in(probe[0][0] if probe
                                                                    else 0, single_span[1])),
        probe_row("the heavy pages opening", probe_in(single_span[1], arrive)),
        probe_row("crowd arriving", probe_in(arrive, window[0])),
        probe_row("heavy sessions working", heavy_probe),
        *[probe_row(f"... beside {names[k]}", [s for s in heavy_probe
                                              if k in beside(s[0], s[0] + s[1])])
          for k in kinds if spans.get(k)],
        probe_row("... beside none of them", [s for s in heavy_probe
                                             if not beside(s[0], s[0] + s[1])]),
        probe_row("after the movers stopped, to the end", probe_in(window[1], float("inf"))),
        "",
        "Heavy actions (t from the server's start):",
        "",
        "| session | action | t [s] | took [s] | outcome |",
        "| --- | --- | --- | --- | --- |",
    ]
    for a in actions:
        outcome = ("ok" if a["ok"] else "**failed**") + (
            f", {a['bytes'] / 2**20:.1f} MiB" if a["bytes"] else "") + (
            f": {a['detail']}" if a["detail"] else "")
        lines.append(f"| {a['session']} | {a['kind']} | {a['start'] - t0:.0f} | "
                     f"{a['end'] - a['start']:.1f} | {outcome.replace('|', '/')} |")
    stalls = [s for s in probe if s[1] > PROBE_GOAL_S]
    if stalls:
        lines += ["", f"Probe answers over {1e3 * PROBE_GOAL_S:.0f} ms: {len(stalls)}. When "
                  "(s from the server's start), how long (ms), what ran beside it (first 60):",
                  "", "    " + ", ".join(
                      f"{s[0] - t0:.1f} s {1e3 * s[1]:.0f}"
                      + (f" [{'; '.join(beside(s[0], s[0] + s[1]))}]"
                         if beside(s[0], s[0] + s[1]) else "")
                      for s in stalls[:60])]
    lines += stall_lines(heavy.probe, t0, beside)
    if crowd.lost or single.lost:
        lines += ["", "Moves whose update never came (s from the server's start, slider, "
                  "what ran beside it):", "", "    " + ", ".join(
                      f"{t - t0:.0f} s {name} [{'; '.join(beside(t, t + 30))}]"
                      for t, name in (single.lost + crowd.lost)[:40])]
    if heavy.start_failed:
        lines += ["", f"Heavy sessions: {heavy.start_failed}."]
    return lines, figures


_LIBRARIES = ("bokeh/", "panel/", "tornado/", "param/", "pyviz_comms/")


def _frame(line: str) -> tuple[str, str]:
    """(function, file) of a py-spy frame line ``func (path/file.py:123)``."""
    found = re.match(r"(.*) \((.*?):\d+\)$", line)
    return (found.group(1), found.group(2)) if found else (line, "")


def _own(path: str) -> bool:
    """Whether a frame's file is the project's (explorer/ or core/, not a library's)."""
    parts = path.replace("\\", "/").split("/")
    return any(p in ("explorer", "core") and (k == 0 or parts[k - 1] not in
                                              ("bokeh", "panel", "tornado", "param"))
               for k, p in enumerate(parts[:-1]))


def stack_summary(frames: list[str]) -> str:
    """A stack (innermost first) in a few frames: the innermost, the innermost of the
    web libraries (Bokeh, Panel, Tornado, param) and the innermost of the project's."""
    if not frames:
        return "(no frames)"
    chosen = [frames[0]]
    for test in (lambda f: any(lib in f for lib in _LIBRARIES), lambda f: _own(f)):
        found = next((line for line in frames if test(_frame(line)[1])), None)
        if found is not None and found not in chosen:
            chosen.append(found)
    return " < ".join(_short(line) for line in chosen)


def _short(line: str) -> str:
    func, path = _frame(line)
    return f"{func} ({path.rsplit('site-packages/', 1)[-1]})"


def stall_place(dump: dict[str, Any]) -> tuple[str, str]:
    """Where a dump found the server's event loop: (the innermost frame of the project's
    code, or what else, with the thread's state; the innermost frame)."""
    main, holder = dump["main"], dump.get("holder")
    if "idle" in main["status"]:
        return "idle: waiting for events (the wait was not in the server's loop)", ""
    frames = main["frames"]
    state = ""
    if "gil" not in main["status"]:
        if holder is not None:
            return (f"waiting for the GIL, held by thread {holder['name']!r}",
                    stack_summary(holder["frames"]))
        state = "not holding the GIL (a system call, or waiting for it): "
    # the server's own loop (python -m explorer's _serve) is below everything: not a place
    own = next((line for line in frames if _own(_frame(line)[1])
                and not _frame(line)[1].endswith("explorer/__main__.py")), None)
    served = any(_frame(line)[1].endswith("explorer/__main__.py") for line in frames)
    place = (_short(own) if own is not None else
             "the libraries only (Bokeh, Panel, Tornado: a page's document built, a "
             "message handled or sent)" if served else
             f"(a stack deeper than the {MOST_FRAMES} frames kept)")
    return state + place, _short(frames[0]) if frames else ""


def stall_lines(probe: Probe, t0: float,
                beside: Callable[[float, float], list[str]]) -> list[str]:
    """The report's lines on what the server's event loop did while the probe waited
    (the py-spy dumps), grouped by the innermost frame of the project's code, with when
    and what heavy work ran beside."""
    if probe.py_spy is None:
        return ["", "What the event loop did during the probe's long waits: not seen "
                "(py-spy is not installed; `pip install py-spy` to have the server's "
                "stacks dumped then)."]
    dumps = probe.stacks()
    if not dumps:
        return ["", f"No probe waited over {DUMP_AFTER_S:g} s for a stack dump."]
    groups: dict[str, list[tuple[dict[str, Any], str]]] = {}
    for dump in dumps:
        place, innermost = stall_place(dump)
        groups.setdefault(place, []).append((dump, innermost))
    lines = ["", f"Where the server's main thread (its event loop) was while the probe "
             f"waited over {DUMP_AFTER_S:g} s: {len(dumps)} stack dumps (py-spy, at most one "
             f"a {DUMP_EVERY_S:g} s), by the innermost frame of the project's code, with the "
             "innermost frames seen most often:", "",
             "| the loop was in | dumps | innermost frames | when (t [s]) and what heavy work "
             "ran beside |", "| --- | --- | --- | --- |"]
    for place, members in sorted(groups.items(), key=lambda kv: -len(kv[1])):
        times = sorted(d["t"] - t0 for d, _ in members)
        when = ", ".join(f"{t:.0f}" for t in times[:12]) + (", ..." if len(times) > 12 else "")
        kinds = sorted({k for d, _ in members for k in beside(d["t"], d["t"])})
        seen: dict[str, int] = {}
        for _, innermost in members:
            if innermost:
                seen[innermost] = seen.get(innermost, 0) + 1
        common = "; ".join(f"{frame} x{n}" if n > 1 else frame for frame, n in
                           sorted(seen.items(), key=lambda kv: -kv[1])[:2])
        lines.append(f"| {place.replace('|', '/')} | {len(members)} | "
                     f"{common.replace('|', '/')} | {when}"
                     + (f" ({'; '.join(kinds)})" if kinds else "") + " |")
    return lines


def _crowd_arriving(sampler: Any) -> float:
    """When the crowd began to arrive [s from the sampler's start]."""
    return next(t for t, label in sampler.marks
                if label.startswith("crowd: ") and label.endswith(" arriving"))


def add_marks(sampler: Any, heavy: HeavyRun) -> None:
    """Put the heavy actions' starts and ends among the sampler's marks (the memory
    table shows them)."""
    count: dict[str, int] = {}
    with contextlib.suppress(Exception):
        for a in heavy.actions():
            if a["kind"] not in ("study", "FE check"):
                continue
            count[a["kind"]] = count.get(a["kind"], 0) + 1
            n = count[a["kind"]]
            sampler.marks.append((a["start"] - sampler.t0, f"heavy: {a['kind']} {n} starts"))
            sampler.marks.append((a["end"] - sampler.t0, f"heavy: {a['kind']} {n} ends"))
        sampler.marks.sort()


def met_all(figures: dict[str, Any]) -> bool:
    """Whether the heavy run met every goal of :func:`heavy_lines`."""
    return (max(figures["p95_ratio"], figures["p95_ratio_lost"]) <= P95_GOAL
            and figures["lost"] == 0
            and figures["probe_max"] < 1e3 * PROBE_GOAL_S
            and figures["growth"] <= MEMORY_GOAL)
