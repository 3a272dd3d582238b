"""Load test of the served explorer: many sessions moving sliders at once.

Starts ``python -m explorer`` on 127.0.0.1 (loopback only). First one session alone (the
reference), then ``--sessions`` sessions at once, each moving sliders for ``--minutes``
like a student: the force slider most of the time (updates while dragging), now and then
the coating thickness (a new geometry, solved on release, after opening its tab). Every
move is one slider step; the session records the time from the move to the plots showing
the moved value (the force history for a force step, the drawn coating for a thickness
step), which arrive in the same message as the new pressure.

Two kinds of session (``--client``):

- ``browser``: real Chromium pages (Playwright, one browser process); a key press on the
  slider's handle, the time measured in the page to the data change ("data") and to the
  second animation frame after it ("frame").
- ``protocol`` (default): the Bokeh websocket protocol, as a browser speaks it
  (``bokeh.client``: the page's document is pulled, "document ready" is sent, widget
  values are patched, the server's patches applied); no rendering. On the 2-core test
  machine 20 Chromium pages saturate both cores by themselves (see the report), so the
  browser measures its own starvation rather than the server; the protocol client costs
  a fraction of that and leaves the cores to the server.

Reported: errors (failed connections, updates that never came, solve errors shown in a
session, tracebacks in the server's log; goal 0), the answers lost (moves whose update
never came; goal 0), latency percentiles of the crowd against the single session (goal
p95 <= 2x), the server's resident memory over time from ``/proc/PID/status`` (goal:
flat, under 1 GiB) and CPU use of the server and the machine, with the commit, the date
and the machine's load before and after. The run is bounded in time (``--minutes`` after
the last session is ready, a hard deadline on top) and in requests (``--max-requests``
per session), and stops by itself. Not part of the test suite. Usage::

    python benchmarks/load_test.py --sessions 20 --minutes 3 [--client protocol|browser]

``--heavy`` adds, beside the movers, three Chromium pages doing the heavy things a page
can ask for (a 400-point study, the FE coating check, a ~10 MB q(x, t) CSV download and
heavy view links opened again and again) and a probe timing the server's liveness URL
every 0.1 s (the event loop's responsiveness), and reports the goals of issue
"Reliability": movers' p95 <= 2x, no answer lost, the probe under 0.2 s, the memory
after all sessions closed within 10 % of its level before the crowd
(``benchmarks/load_heavy.py``)::

    python benchmarks/load_test.py --sessions 20 --minutes 2 --heavy --report FILE.md

``--mode abandon`` instead opens sessions and drops them abruptly (200 by default) and
reports the server's memory after each round (``benchmarks/load_abandon.py``)::

    python benchmarks/load_test.py --mode abandon --dropped 200 --report FILE.md
"""

from __future__ import annotations

import argparse
import asyncio
import gc
import os
import platform
import random
import statistics
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from tests.support.serving import CHROMIUM, ExplorerProcess, ExplorerStartError  # noqa: E402
from tests.support.serving import CHROMIUM_ARGS as BROWSER_ARGS  # noqa: E402

CHROMIUM_ARGS = [*BROWSER_ARGS,
                 # pages of one browser compete for its renderers: none may be throttled
                 # as a background tab
                 "--disable-background-timer-throttling", "--disable-renderer-backgrounding",
                 "--disable-backgrounding-occluded-windows"]
HOST = "127.0.0.1"
#: Index of the "Coating" tab of the sidebar, and the step of a thickness move [mm].
COATING_TAB = 2
THICKNESS_STEP = 0.1
#: A session waits this long for the plot to follow a move before counting an error [s].
UPDATE_TIMEOUT = 30.0
#: Moves answered later than this [ms] are listed in the report, with when they came.
SLOW_MS = 1000.0

READY = """() => {
  const doc = window.Bokeh && Bokeh.documents && Bokeh.documents[0];
  const src = doc && doc.get_model_by_name('q_source');
  return !!src && !!src.data.q && src.data.q.length > 1;
}"""

# For the first change of the plotted data after a key press (the force history for a
# force step, the drawn coating for a thickness step; the pressure comes in the same
# message): the time to the change ("data") and to the second animation frame after it
# ("frame"), in ms.
INSTRUMENT = """() => {
  const doc = Bokeh.documents[0];
  window.__data = []; window.__frame = []; window.__key = null;
  document.addEventListener('keydown', () => { window.__key = performance.now(); }, true);
  for (const name of ['force_source', 'layer_source']) {
    doc.get_model_by_name(name).change.connect(() => {
      const t0 = window.__key;
      if (t0 === null) return;
      window.__key = null;
      window.__data.push(performance.now() - t0);
      requestAnimationFrame(() => requestAnimationFrame(
        () => window.__frame.push(performance.now() - t0)));
    });
  }
}"""


@dataclass
class Stats:
    """What the sessions of one phase saw (appended to from several threads)."""

    data: list[float] = field(default_factory=list)     # ms
    # (monotonic s when answered, ms, slider) of each move (protocol client)
    moves: list[tuple[float, float, str]] = field(default_factory=list)
    frame: list[float] = field(default_factory=list)    # ms
    requests: int = 0
    geometry_requests: int = 0
    # (monotonic s when sent, slider) of each move whose update never came
    lost: list[tuple[float, str]] = field(default_factory=list)
    errors: list[str] = field(default_factory=list)
    sessions_ready: int = 0
    lock: threading.Lock = field(default_factory=threading.Lock)

    def count(self, geometry: bool) -> None:
        with self.lock:
            self.requests += 1
            self.geometry_requests += geometry

    def ready(self) -> None:
        with self.lock:
            self.sessions_ready += 1

    def error(self, text: str) -> None:
        with self.lock:
            self.errors.append(text)

    def lose(self, sent: float, name: str) -> None:
        """A move (sent at monotonic ``sent`` [s]) whose update never came."""
        with self.lock:
            self.lost.append((sent, name))


class Clock:
    """When the sessions of a phase stop: ``seconds`` after the last one is ready, never
    after ``hard_end`` (monotonic times). Safe across threads."""

    def __init__(self, sessions: int, seconds: float, hard_end: float) -> None:
        self.sessions = sessions
        self.seconds = seconds
        self.hard_end = hard_end
        self.end: float | None = None
        self.all_ready = threading.Event()
        self._ready = 0
        self._lock = threading.Lock()

    def arrived(self) -> None:
        with self._lock:
            self._ready += 1
            if self._ready == self.sessions:
                self.end = time.monotonic() + self.seconds
                self.all_ready.set()

    def running(self) -> bool:
        now = time.monotonic()
        return now < self.hard_end and (self.end is None or now < self.end)


def rss_bytes(pid: int) -> int | None:
    """Resident memory of a process [bytes], from /proc (None once it is gone)."""
    try:
        with open(f"/proc/{pid}/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        return None
    return None


def cpu_seconds(pid: int) -> float | None:
    """User + system CPU time of a process [s], from /proc."""
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii") as fh:
            fields = fh.read().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    except OSError:
        return None


def machine_ticks() -> tuple[int, int]:
    """(busy, total) CPU ticks of the whole machine since boot, from /proc/stat."""
    with open("/proc/stat", encoding="ascii") as fh:
        values = [int(v) for v in fh.readline().split()[1:]]
    idle = values[3] + (values[4] if len(values) > 4 else 0)
    return sum(values) - idle, sum(values)


def process_tree(pid: int) -> list[int]:
    """``pid`` and all its descendants (the server and its solver processes), from /proc."""
    out, todo = [], [pid]
    while todo:
        current = todo.pop()
        out.append(current)
        try:
            tasks = os.listdir(f"/proc/{current}/task")
        except OSError:
            continue
        for task in tasks:
            try:
                with open(f"/proc/{current}/task/{task}/children", encoding="ascii") as fh:
                    todo.extend(int(child) for child in fh.read().split())
            except OSError:
                continue
    return out


class Sampler(threading.Thread):
    """Samples the RSS and CPU time of the server with its solver processes, the server
    process's own CPU time, the CPU time of this load test's own processes (the driver
    and what it started besides the server: Chromium, the probe) and the machine's CPU
    use every ``period`` seconds; ``mark`` records events on the same clock."""

    def __init__(self, pid: int, period: float = 2.0) -> None:
        super().__init__(daemon=True)
        self.pid = pid
        self.period = period
        # (s since start, RSS bytes and CPU s of the server with its solver processes,
        #  machine busy ticks, machine ticks, CPU s of the server's own process, CPU s
        #  of the load test's own processes)
        self.samples: list[tuple[float, int, float, int, int, float, float]] = []
        # the RSS of the server's own process at each sample [bytes] (its solver and
        # study processes are the rest of the sample's sum)
        self.server_rss: list[int] = []
        self.marks: list[tuple[float, str]] = []
        # the last CPU time [s] seen of every process of each tree: a process that ended
        # (a study's, Chromium's) keeps counting with what it had used
        self._seen: dict[str, dict[int, float]] = {"server": {}, "clients": {}}
        self._halt = threading.Event()
        self.t0 = time.monotonic()

    def mark(self, label: str) -> None:
        self.marks.append((time.monotonic() - self.t0, label))

    def run(self) -> None:
        while not self._halt.is_set():
            own = cpu_seconds(self.pid)
            tree = process_tree(self.pid)
            rss = [rss_bytes(p) for p in tree]
            # the driver's tree holds the server's: what is left is the load test's own
            clients = set(process_tree(os.getpid())) - set(tree)
            for name, pids in (("server", tree), ("clients", clients)):
                for p in pids:
                    cpu = cpu_seconds(p)
                    if cpu is not None:
                        self._seen[name][p] = cpu
            if own is not None:
                self.server_rss.append(rss[0] or 0)
                self.samples.append((time.monotonic() - self.t0,
                                     sum(r for r in rss if r is not None),
                                     sum(self._seen["server"].values()),
                                     *machine_ticks(), own,
                                     sum(self._seen["clients"].values())))
            self._halt.wait(self.period)

    def stop(self) -> None:
        self._halt.set()
        self.join(timeout=10)

    def between(self, start: str, stop: str) -> dict[str, float]:
        """CPU between two marks: the server with its solver processes and the server's
        own process [% of one core], the machine [% of all cores]."""
        marks = {label: t for t, label in self.marks}
        inside = [s for s in self.samples if marks[start] <= s[0] <= marks[stop]]
        if len(inside) < 2:
            return dict.fromkeys(("server", "machine", "own", "clients", "others"),
                                 float("nan"))
        return cpu_between(inside[0], inside[-1])


def cpu_between(first: tuple[Any, ...], last: tuple[Any, ...]) -> dict[str, float]:
    """CPU use between two samples of :class:`Sampler`: the server with its solver
    processes, the server's own process, the load test's own processes ("clients") and
    the machine's other work ("others") [% of one core], the machine [% of all cores]."""
    (t0, _, c0, b0, n0, o0, d0), (t1, _, c1, b1, n1, o1, d1) = first, last
    span = max(t1 - t0, 1e-9)
    machine = (b1 - b0) / max(n1 - n0, 1)
    server, clients = 100 * (c1 - c0) / span, 100 * (d1 - d0) / span
    return {"server": server, "own": 100 * (o1 - o0) / span, "clients": clients,
            "machine": 100 * machine,
            "others": max(100 * machine * (os.cpu_count() or 1) - server - clients, 0.0)}



_FREEZE_LOCK = threading.Lock()


def freeze_client_heap() -> None:
    """Keep this driver's garbage collector off the sessions' documents.

    The 20 clients hold 20 copies of the page (~46,000 objects each) in this one process;
    a full collection walking them paused every client for 0.5-0.8 s at once (measured),
    which the latencies would blame on the server.
    """
    with _FREEZE_LOCK:
        gc.collect(1)
        gc.freeze()


def next_step(rng: random.Random, position: dict[str, int], name: str) -> int:
    """A random walk that stays near the start: values repeat across sessions as they do
    in a classroom, and the caches help as they would there."""
    step = rng.choice((-1, 1)) if abs(position[name]) < 15 else \
        (-1 if position[name] > 0 else 1)
    position[name] += step
    return step


# ----------------------------------------------------------------- the protocol client


def _models_with_class(doc: Any, css: str) -> list[Any]:
    return [m for m in list(doc.models) if css in (getattr(m, "css_classes", None) or [])]


def _part(tabs: Any, tab: int, css: str, kind: str) -> Any | None:
    """The Bokeh model of type ``kind`` inside the widget with CSS class ``css`` on the
    sidebar's tab ``tab``, once the server has switched to that tab.

    The explorer's tabs are dynamic: the server replaces an inactive tab's content by a
    Spacer and builds the active one. Until the server's patches for a switch arrive, the
    client still holds the old contents; a value set on them then is lost (the server
    detaches those models), so the switch must be seen complete: every other tab a
    Spacer, this one not. (Tabs built all at once have no Spacers: nothing to wait for.)
    """
    spacers = [type(panel.child).__name__ == "Spacer" for panel in tabs.tabs]
    if any(spacers) and any(spacer == (k == tab) for k, spacer in enumerate(spacers)):
        return None
    content = tabs.tabs[tab].child
    for holder in content.references():
        if css in (getattr(holder, "css_classes", None) or []):
            for ref in holder.references():
                if type(ref).__name__ == kind:
                    return ref
    return None


def _iterative_message_loop() -> None:
    """Make ``bokeh.client`` handle incoming messages in a loop.

    Its connection handles each message one coroutine level deeper than the one before
    (``_handle_messages`` -> ``_next`` -> ``_handle_messages`` ...): fine for the short
    scripts it is meant for, a RecursionError after a few minutes of slider patches.
    """
    from bokeh.client import connection
    from bokeh.client.states import CONNECTED_AFTER_ACK, DISCONNECTED, ErrorReason

    async def handle_messages(self: Any) -> None:
        while True:
            message = await self._pop_message()
            if message is None:
                await self._transition_to_disconnected(
                    DISCONNECTED(ErrorReason.HTTP_ERROR, 500, "Internal server error."))
                return
            if message.msgtype == "PATCH-DOC":
                self._session._handle_patch(message)
            # what _next() would do before the next message, without going deeper
            if self._until_predicate is not None and self._until_predicate():
                self._until_predicate = None
                self._loop.stop()
                return
            if not isinstance(self._state, CONNECTED_AFTER_ACK):
                await self._next()
                return

    connection.ClientConnection._handle_messages = handle_messages


def protocol_session(url: str, seed: int, clock: Clock, max_requests: int, stats: Stats,
                     geometry_share: float, think: tuple[float, float]) -> None:
    """One student on the Bokeh protocol, in its own thread and event loop."""
    import panel  # noqa: F401  (registers Panel's models, so its documents deserialize)
    import panel.models.file_dropper  # noqa: F401  (loaded lazily by Panel: the uploads)
    from bokeh.client import pull_session
    from bokeh.events import DocumentReady

    tag = f"session {seed}"
    rng = random.Random(seed)
    try:
        session = pull_session(url=url + "/app")
    except Exception as exc:  # a refused connection is an error to report
        stats.error(f"{tag}: could not open a session: {type(exc).__name__}: {exc}")
        clock.arrived()
        return
    doc = session.document
    loop = session._connection.io_loop
    # The move is answered when the plots show the moved value: any change of the
    # pressure would also count a late answer to an earlier move, and the explorer sends
    # no pressure at all when a move's result equals the one on screen.
    shown = {"force": doc.select_one({"name": "force_source"}),
             "thickness": doc.select_one({"name": "layer_source"})}
    column = {"force": "v", "thickness": "h_mm"}
    # the drawing's thicknesses are float32 (explorer/plots/scene.py): 6e-8 relative
    match = {"force": 1e-9, "thickness": 1e-6}
    waiting: dict[str, Any] = {"future": None, "name": None, "value": None}

    def check(attr: str, old: Any, new: Any) -> None:
        future, name = waiting["future"], waiting["name"]
        if future is None or future.done() or name is None:
            return
        values = shown[name].data.get(column[name], [])
        if len(values) and min(abs(float(v) - waiting["value"]) for v in values) <= \
                match[name] * max(abs(waiting["value"]), 1.0):
            future.set_result(time.perf_counter())

    for source in shown.values():
        source.on_change("data", check)

    async def wait_for(predicate: Any, timeout: float) -> Any:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            found = predicate()
            if found is not None:
                return found
            await asyncio.sleep(0.05)
        return None

    async def behave() -> None:
        requests = 0
        position = {"force": 0, "thickness": 0}
        try:
            # what BokehJS sends once the page is rendered: Panel's onload callbacks run
            doc.callbacks.send_event(DocumentReady())
            freeze_client_heap()
            stats.ready()
            clock.arrived()
            tabs = next(m for m in doc.models if type(m).__name__ == "Tabs")
            while clock.running() and requests < max_requests:
                geometry = rng.random() < geometry_share
                if geometry:
                    tabs.active = COATING_TAB  # opening a tab builds its widgets
                    target = await wait_for(lambda: _part(tabs, COATING_TAB,
                                                          "coating-thickness", "Spinner"),
                                            UPDATE_TIMEOUT)
                    name = "thickness"
                else:
                    target = await wait_for(lambda: _part(tabs, 0, "load-0-value", "Slider"),
                                            UPDATE_TIMEOUT)
                    name = "force"
                if target is None:
                    shown = [type(panel.child).__name__ for panel in tabs.tabs]
                    stats.error(f"{tag}: the {name} widget did not appear within "
                                f"{UPDATE_TIMEOUT:g} s (tab {tabs.active} active, contents "
                                f"{shown})")
                    break
                step = next_step(rng, position, name)
                future = asyncio.get_running_loop().create_future()
                if geometry:
                    value = round(float(target.value) + step * THICKNESS_STEP, 6)
                else:
                    value = float(target.value) + step * float(target.step)
                waiting.update(future=future, name=name, value=value)
                sent, sent_at = time.perf_counter(), time.monotonic()
                if geometry:
                    # a typed value, confirmed: what the page sends on Enter
                    target.value = value
                    target.set_from_json("value_throttled", value)
                else:
                    target.value = value
                stats.count(geometry)
                requests += 1
                try:
                    received = await asyncio.wait_for(future, UPDATE_TIMEOUT)
                    with stats.lock:
                        stats.data.append(1e3 * (received - sent))
                        stats.moves.append((time.monotonic(), 1e3 * (received - sent), name))
                except asyncio.TimeoutError:
                    stats.lose(sent_at, name)
                    stats.error(f"{tag}: no plot update within {UPDATE_TIMEOUT:g} s after "
                                f"a {name} move")
                if geometry:
                    tabs.active = 0
                    # seen through before the next move (see _part)
                    await wait_for(lambda: _part(tabs, 0, "load-0-value", "Slider"),
                                   UPDATE_TIMEOUT)
                await asyncio.sleep(rng.uniform(*think))
            alert = _models_with_class(doc, "solve-error")
            if alert and getattr(alert[0], "visible", False):
                stats.error(f"{tag}: the session shows a solve error")
        except Exception as exc:  # reported; the other sessions go on
            stats.error(f"{tag}: {type(exc).__name__}: {str(exc)[:200]}")
        finally:
            session.close()

    loop.add_callback(behave)
    session._loop_until_closed()


def run_protocol_phase(url: str, sessions: int, seconds: float, max_requests: int,
                       geometry_share: float, think: tuple[float, float], stagger: float,
                       sampler: Sampler, label: str,
                       on_ready: Callable[[Clock], None] | None = None) -> Stats:
    """One phase of protocol sessions; ``on_ready(clock)`` is called once the last is
    ready (``clock.end``: when they stop), e.g. to start the heavy sessions."""
    _iterative_message_loop()
    stats = Stats()
    clock = Clock(sessions, seconds, time.monotonic() + stagger * sessions + 180 + seconds)
    sampler.mark(f"{label}: {sessions} session(s) arriving")
    threads = []
    for k in range(sessions):
        thread = threading.Thread(target=protocol_session, daemon=True, args=(
            url, 1000 * sessions + k, clock, max_requests, stats, geometry_share, think))
        thread.start()
        threads.append(thread)
        time.sleep(stagger)
    clock.all_ready.wait(timeout=max(clock.hard_end - time.monotonic(), 0))
    sampler.mark(f"{label}: all sessions ready")
    if on_ready is not None:
        on_ready(clock)
    for thread in threads:
        thread.join(timeout=max(clock.hard_end - time.monotonic(), 0) + 60)
        if thread.is_alive():
            stats.error(f"{label}: a session did not stop by the hard deadline")
    sampler.mark(f"{label}: sessions closed")
    return stats


# ------------------------------------------------------------------ the browser client


async def browser_session(context: Any, url: str, seed: int, clock: Clock, max_requests: int,
                          stats: Stats, geometry_share: float, think: tuple[float, float]
                          ) -> None:
    """One student in a Chromium page."""
    rng = random.Random(seed)
    page = await context.new_page()
    tag = f"session {seed}"
    page.on("pageerror", lambda e: stats.error(f"{tag}: page error: {e}"))
    page.on("console", lambda m: m.type == "error" and stats.error(
        f"{tag}: console error: {m.text[:200]}"))
    try:
        await page.goto(url + "/app", wait_until="commit", timeout=120_000)
        await page.wait_for_function(READY, timeout=180_000, polling=200)
        await page.evaluate(INSTRUMENT)
        stats.ready()
        clock.arrived()
        force = page.locator(".load-0-value .noUi-handle").first
        position = {"force": 0, "thickness": 0}
        requests = 0
        while clock.running() and requests < max_requests:
            geometry = rng.random() < geometry_share
            if geometry:
                await page.locator(".bk-tab", has_text="Coating").first.click()
                handle = page.locator(".coating-thickness .noUi-handle").first
                name = "thickness"
            else:
                handle, name = force, "force"
            step = next_step(rng, position, name)
            before = await page.evaluate("() => window.__data.length")
            sent_at = time.monotonic()
            await handle.press("ArrowRight" if step > 0 else "ArrowLeft")
            requests += 1
            stats.count(geometry)
            try:
                await page.wait_for_function(f"() => window.__data.length > {before}",
                                             timeout=1e3 * UPDATE_TIMEOUT, polling=100)
            except Exception:  # any failure to update is an error to report
                stats.lose(sent_at, name)
                stats.error(f"{tag}: no plot update within {UPDATE_TIMEOUT:g} s after a "
                            f"{name} move")
            if geometry:
                await page.locator(".bk-tab", has_text="Scene").first.click()
            await asyncio.sleep(rng.uniform(*think))
        await asyncio.sleep(1.0)  # let the last frames land
        data = await page.evaluate("() => window.__data")
        frame = await page.evaluate("() => window.__frame")
        with stats.lock:
            stats.data.extend(data)
            stats.frame.extend(frame)
        if await page.locator(".solve-error").first.is_visible():
            stats.error(f"{tag}: the page shows a solve error")
    except Exception as exc:  # reported; the other sessions go on
        stats.error(f"{tag}: {type(exc).__name__}: {str(exc)[:200]}")
    finally:
        await page.close()


async def _browser_phase(url: str, sessions: int, seconds: float, max_requests: int,
                         geometry_share: float, think: tuple[float, float], stagger: float,
                         sampler: Sampler, label: str,
                         on_ready: Callable[[Clock], None] | None = None) -> Stats:
    from playwright.async_api import async_playwright

    stats = Stats()
    with tempfile.TemporaryDirectory(prefix="load-test-chromium-") as profile:
        async with async_playwright() as p:
            context = await p.chromium.launch_persistent_context(
                profile, executable_path=CHROMIUM, headless=True, args=CHROMIUM_ARGS,
                viewport={"width": 1280, "height": 1000})
            try:
                sampler.mark(f"{label}: {sessions} session(s) arriving")
                clock = Clock(sessions, seconds,
                              time.monotonic() + stagger * sessions + 180 + seconds)
                tasks = []
                for k in range(sessions):
                    tasks.append(asyncio.create_task(browser_session(
                        context, url, 1000 * sessions + k, clock, max_requests, stats,
                        geometry_share, think)))
                    await asyncio.sleep(stagger)
                while not clock.all_ready.is_set() and time.monotonic() < clock.hard_end:
                    await asyncio.sleep(0.2)
                sampler.mark(f"{label}: all sessions ready")
                if on_ready is not None:
                    on_ready(clock)
                await asyncio.wait_for(asyncio.gather(*tasks),
                                       timeout=clock.hard_end - time.monotonic() + 60)
            finally:
                sampler.mark(f"{label}: sessions closed")
                await context.close()
    return stats


def run_browser_phase(*args: Any, on_ready: Callable[[Clock], None] | None = None) -> Stats:
    return asyncio.run(_browser_phase(*args, on_ready=on_ready))


# ---------------------------------------------------------------------------- report


def percentiles(values: list[float]) -> dict[str, float]:
    if len(values) < 2:
        return {"p50": float("nan"), "p95": float("nan"), "p99": float("nan")}
    q = statistics.quantiles(values, n=100, method="inclusive")
    return {"p50": statistics.median(values), "p95": q[94], "p99": q[98]}


def server_tracebacks(log_path: Path) -> list[str]:
    text = log_path.read_text(errors="replace")
    blocks = text.split("Traceback (most recent call last)")[1:]
    # a client that left while the server wrote to its websocket: no failure of the app
    closed = ("WebSocketClosedError", "StreamClosedError")
    return [b[:400] for b in blocks if not any(c in b[:3000] for c in closed)]


def server_options(args: argparse.Namespace) -> str:
    """The options of ``python -m explorer`` that set where the server solves."""
    if args.solver_processes is None:
        from explorer.__main__ import DEFAULT_SOLVER_PROCESSES

        return f"--solver-processes {DEFAULT_SOLVER_PROCESSES}"
    if args.solver_processes:
        return f"--solver-processes {args.solver_processes}"
    return f"--solver-processes 0 --solver-threads {args.solver_threads}"


def report(args: argparse.Namespace, single: Stats, crowd: Stats, sampler: Sampler,
           log_errors: list[str], command: str, run: list[str],
           extra: list[str] | None = None) -> str:
    """The Markdown report: ``run`` the lines on the run (commit, date, load,
    :func:`benchmarks.run_lines`), ``extra`` more lines before the memory table (the
    heavy sessions')."""
    s_data, c_data = percentiles(single.data), percentiles(crowd.data)
    samples = sampler.samples
    peak = max(s[1] for s in samples)
    marks = {label: t for t, label in sampler.marks}
    start, stop = marks["crowd: all sessions ready"], marks["crowd: sessions closed"]
    crowd_rss = [s[1] for s in samples if start <= s[0] <= stop]
    half = [(s[0], s[1]) for s in samples if (start + stop) / 2 <= s[0] <= stop]
    slope = 0.0
    if len(half) >= 2:
        mt = statistics.fmean(t for t, _ in half)
        mr = statistics.fmean(r for _, r in half)
        slope = sum((t - mt) * (r - mr) for t, r in half) / max(
            sum((t - mt) ** 2 for t, _ in half), 1e-9)
    cpu_single = sampler.between("single: all sessions ready", "single: sessions closed")
    cpu_crowd = sampler.between("crowd: all sessions ready", "crowd: sessions closed")
    errors = single.errors + crowd.errors + [f"server log: {e}" for e in log_errors]
    client = ("real Chromium pages (Playwright, one browser process)" if args.client ==
              "browser" else "Bokeh websocket protocol clients (bokeh.client, one thread "
              "each, no rendering)")

    def row(name: str, s: dict[str, float], c: dict[str, float]) -> str:
        return (f"| {name} | {s['p50']:.0f} / {s['p95']:.0f} / {s['p99']:.0f} | "
                f"{c['p50']:.0f} / {c['p95']:.0f} / {c['p99']:.0f} | "
                f"{c['p95'] / s['p95']:.2f} |")

    lines = [
        f"## {args.sessions} sessions, {args.client} client, {args.minutes:g} min"
        + (", heavy sessions beside them" if args.heavy else ""),
        "",
        "Command (from the repository root):",
        "",
        f"    {command}",
        "",
        *run,
        "",
        f"Machine: {os.cpu_count()} cores ({platform.machine()}), Python "
        f"{platform.python_version()}; server, clients and driver share it. Server: "
        f"`python -m explorer --address {HOST} {server_options(args)}` (loopback only).",
        "",
        f"Sessions: {args.sessions} {client}, arriving {args.stagger:g} s apart, all moving "
        f"sliders until {args.minutes:g} min after the last was ready: one step of the force "
        f"slider (live update) or, with probability {args.geometry_share:g}, of the coating "
        f"thickness (a new geometry; its tab opened first), then a pause of "
        f"{args.think[0]:g}-{args.think[1]:g} s. Single session: the same for "
        f"{args.baseline_seconds:g} s, alone on the same server, before the crowd.",
        "",
        f"- Errors: **{len(errors)}** (goal 0): failed sessions, updates that never came "
        f"(within {UPDATE_TIMEOUT:g} s), solve errors shown, page or console errors "
        "(browser), tracebacks in the server log.",
        f"- Moves: single {single.requests} ({single.geometry_requests} geometry), crowd "
        f"{crowd.requests} ({crowd.geometry_requests} geometry) from "
        f"{crowd.sessions_ready}/{args.sessions} sessions; updates timed: single "
        f"{len(single.data)}, crowd {len(crowd.data)}; answers lost (no update within "
        f"{UPDATE_TIMEOUT:g} s): **{len(single.lost) + len(crowd.lost)}** (goal 0).",
        f"- Server memory (RSS, summed over the server and its solver processes): peak "
        f"**{peak / 2**20:.0f} MiB** (goal < 1024 MiB); during "
        f"the crowd {min(crowd_rss) / 2**20:.0f} to {max(crowd_rss) / 2**20:.0f} MiB, trend "
        f"over its second half {slope * 60 / 2**20:+.1f} MiB/min.",
        f"- CPU: server with its solver processes {cpu_single['server']:.0f} % of one core "
        f"alone, {cpu_crowd['server']:.0f} % with the crowd (the server's own process "
        f"{cpu_single['own']:.0f} % and {cpu_crowd['own']:.0f} %); the whole machine "
        f"{cpu_single['machine']:.0f} % and {cpu_crowd['machine']:.0f} % of its "
        f"{os.cpu_count()} cores, of which this load test's own clients (the driver with "
        f"its threads, and Chromium and the probe where used) {cpu_single['clients']:.0f} % "
        f"and {cpu_crowd['clients']:.0f} % of one core, and other work on the machine "
        f"{cpu_single['others']:.0f} % and {cpu_crowd['others']:.0f} %.",
        "",
        "Latency from the move, ms (p50 / p95 / p99):",
        "",
        "| measured to | single session | crowd | p95 crowd / single (goal <= 2) |",
        "| --- | --- | --- | --- |",
        row("plots showing the moved value", s_data, c_data),
        *[row(f"... of a {name} step only",
              percentiles([ms for _, ms, moved in single.moves if moved == name]),
              percentiles([ms for _, ms, moved in crowd.moves if moved == name]))
          for name in ("force", "thickness")],
        row("... once the last session was ready (no page being built)", s_data,
            percentiles([ms for t, ms, _ in crowd.moves
                         if t - sampler.t0 >= marks["crowd: all sessions ready"]])),
    ]
    if args.client == "browser":
        lines.append(row("second frame painted after it", percentiles(single.frame),
                         percentiles(crowd.frame)))
    slow = sorted(move for move in single.moves + crowd.moves if move[1] > SLOW_MS)
    if slow:
        ready = marks["crowd: all sessions ready"]
        lines += ["", f"Moves answered after more than {SLOW_MS:.0f} ms: {len(slow)}, "
                  f"{sum(t - sampler.t0 < ready for t, _, _ in slow)} of them before the "
                  "last session was ready. When (s from the server's start), how long "
                  "(ms), which slider:", "",
                  "    " + ", ".join(f"{t - sampler.t0:.0f} s {ms:.0f} {name}"
                                     for t, ms, name in slow[:60])]
    lines += extra or []
    lines += ["", "Server memory over time (RSS; t from the server's start), and the CPU "
              "used since the row before [% of one core] by the server with its solver "
              "processes, by this load test's own clients and by other work on the "
              "machine:", "",
              "| t [s] | RSS [MiB] | CPU server / clients / other work | event |",
              "| --- | --- | --- | --- |"]
    step = max(1, int(30 / sampler.period))
    previous = samples[0]
    for i, sample in enumerate(samples):
        t, rss = sample[0], sample[1]
        events = [label for m, label in sampler.marks
                  if t - sampler.period / 2 < m <= t + sampler.period / 2]
        if i % step == 0 or events or i == len(samples) - 1:
            cpu = cpu_between(previous, sample) if sample is not previous else None
            shown = (f"{cpu['server']:.0f} / {cpu['clients']:.0f} / {cpu['others']:.0f}"
                     if cpu is not None else "")
            lines.append(f"| {t:.0f} | {rss / 2**20:.0f} | {shown} | {', '.join(events)} |")
            previous = sample
    if errors:
        # the kinds that come by the dozen are counted, with their first; the others listed
        common = ("could not open a session", "no plot update within")
        rest = [e for e in errors if not any(c in e for c in common)]
        lines += ["", "Errors:", ""]
        for kind in common:
            those = [e for e in errors if kind in e]
            if those:
                lines.append(f"- {len(those)} x \"{kind}\", the first: {those[0]}")
        lines += [f"- {e}" for e in rest[:20]]
        if len(rest) > 20:
            lines.append(f"- ... and {len(rest) - 20} more")
    return "\n".join(lines) + "\n"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sessions", type=int, default=20, help="concurrent sessions")
    parser.add_argument("--minutes", type=float, default=3.0,
                        help="minutes the crowd moves sliders once all have arrived")
    parser.add_argument("--client", choices=("protocol", "browser"), default="protocol",
                        help="Bokeh websocket protocol clients (default) or Chromium pages")
    parser.add_argument("--baseline-seconds", type=float, default=60.0,
                        help="seconds of the single-session reference")
    parser.add_argument("--max-requests", type=int, default=2000,
                        help="most moves per session (a bound on the run)")
    parser.add_argument("--geometry-share", type=float, default=0.15,
                        help="share of moves of the coating thickness")
    parser.add_argument("--think", type=float, nargs=2, default=(0.3, 1.2),
                        metavar=("MIN", "MAX"), help="pause after each update [s]")
    parser.add_argument("--stagger", type=float, default=1.0,
                        help="seconds between the arrivals of two sessions")
    parser.add_argument("--solver-processes", type=int, default=None,
                        help="the server's --solver-processes (default: the server's "
                             "default; 0: solve in the server's threads)")
    parser.add_argument("--solver-threads", type=int, default=2,
                        help="the server's --solver-threads (used with --solver-processes 0)")
    parser.add_argument("--after-seconds", type=float, default=120.0,
                        help="seconds of memory samples after the crowd has left (the "
                             "server discards closed sessions within twice its 15 s "
                             "linger, collects them within 30 s after "
                             "(explorer/fixes/gc_policy.py) and empties its caches 60 s "
                             "after the last has gone (--release-after-idle))")
    parser.add_argument("--heavy", action="store_true",
                        help="crowd: three more sessions (Chromium pages) run a 400-point "
                             "study, the FE coating check and large downloads with heavy "
                             "view links beside the movers, and a probe times the server's "
                             "liveness URL (benchmarks/load_heavy.py)")
    parser.add_argument("--report", help="append the report (Markdown) to this file")
    parser.add_argument("--mode", choices=("crowd", "abandon"), default="crowd",
                        help="crowd: sessions moving sliders (default); abandon: sessions "
                             "opened and dropped, memory after each round "
                             "(benchmarks/load_abandon.py)")
    parser.add_argument("--dropped", type=int, default=200,
                        help="abandon: sessions dropped after the warm-up")
    parser.add_argument("--round", type=int, default=25,
                        help="abandon: sessions dropped per round")
    parser.add_argument("--at-once", type=int, default=10,
                        help="abandon: sessions being dropped at the same time")
    parser.add_argument("--session-linger", type=float, default=2.0,
                        help="abandon: the server's --session-linger [s] (its default 15 "
                             "only makes the rounds longer)")
    parser.add_argument("--trend-goal", type=float, default=10.0,
                        help="abandon: largest settled growth counted flat [MiB per 100 "
                             "dropped sessions]")
    args = parser.parse_args()
    command = "python benchmarks/load_test.py " + " ".join(sys.argv[1:])
    if args.mode == "abandon":
        if not (1 <= args.dropped <= 10_000 and 1 <= args.round and 1 <= args.at_once <= 100):
            parser.error("--dropped must be 1 to 10000, --round >= 1, --at-once 1 to 100")
        from benchmarks.load_abandon import run_abandon

        text, ok = run_abandon(args, command)
        print(text)
        if args.report:
            path = Path(args.report)
            path.parent.mkdir(parents=True, exist_ok=True)
            with path.open("a", encoding="utf-8") as fh:
                fh.write(text + "\n")
        return 0 if ok else 1
    phase = run_browser_phase if args.client == "browser" else run_protocol_phase
    started = datetime.now(timezone.utc)
    load_before = os.getloadavg()[0]
    from benchmarks import run_lines, tree_commit

    commit = tree_commit()  # the code the server starts with (the tree may move on)
    heavy: Any = None

    with tempfile.TemporaryDirectory(prefix="load-test-") as tmp:
        log_path = Path(tmp) / "server.log"
        server = ExplorerProcess(
            args=server_options(args).split(), host=HOST,
            env={"OPENBLAS_NUM_THREADS": os.environ.get("OPENBLAS_NUM_THREADS", "1")},
            log=log_path, ready_timeout=300, stop_timeout=20)
        try:
            url = server.start().url
        except ExplorerStartError as err:
            # the log is in the temporary directory, gone once this exits: quoted instead
            raise SystemExit(str(err)) from None
        sampler = Sampler(server.pid)
        sampler.start()
        sampler.mark("server ready")
        try:
            if args.heavy:
                from benchmarks.load_heavy import HeavyRun

                heavy = HeavyRun(url, server.pid, sampler.mark)  # the probe starts now
            think = tuple(args.think)
            single = phase(url, 1, args.baseline_seconds, args.max_requests,
                           args.geometry_share, think, 0.0, sampler, "single")
            if heavy is not None:
                heavy.open()
            crowd = phase(url, args.sessions, 60 * args.minutes, args.max_requests,
                          args.geometry_share, think, args.stagger, sampler, "crowd",
                          on_ready=heavy.go if heavy is not None else None)
            if heavy is not None:
                heavy.finish()
            time.sleep(args.after_seconds)
            sampler.mark("end")
            time.sleep(sampler.period)
        finally:
            try:
                if heavy is not None:
                    heavy.close()
                sampler.stop()
            finally:
                server.stop()
        log_errors = server_tracebacks(log_path)
        releases = [line.strip() for line in log_path.read_text(errors="replace").splitlines()
                    if line.startswith("No page open for")]
    load_after = os.getloadavg()[0]
    run = run_lines(started, load_before, load_after,
                    "1-minute load average; the machine is shared, its other work included",
                    commit=commit)
    extra: list[str] = []
    goals_met = True
    if heavy is not None:
        from benchmarks.load_heavy import add_marks, heavy_lines, met_all

        add_marks(sampler, heavy)
        extra, figures = heavy_lines(single, crowd, sampler, heavy)
        goals_met = met_all(figures)
        heavy.cleanup()
    # the idle server's releases of its caches (explorer/solving/idle_release.py), as its
    # log says them
    extra += ["", "Releases of the idle server's caches (its log): "
              + ("; ".join(f"`{line}`" for line in releases) or "none") + "."]
    text = report(args, single, crowd, sampler, log_errors, command, run, extra)
    print(text)
    if args.report:
        path = Path(args.report)
        path.parent.mkdir(parents=True, exist_ok=True)
        with path.open("a", encoding="utf-8") as fh:
            fh.write(text + "\n")
    return 0 if goals_met and not (single.errors or crowd.errors or log_errors) else 1


if __name__ == "__main__":
    sys.exit(main())
