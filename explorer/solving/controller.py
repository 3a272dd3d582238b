"""Solving off the UI thread: requests, coalescing, stale results and error messages.

A :class:`SolveController` watches an :class:`~explorer.model.state.ExplorerState`. Every
change asks for a solve. At most one solve per session runs at a time; requests made
meanwhile collapse into one pending request (the newest), so a slider dragged through
twenty values costs a handful of solves, not twenty. An outcome is shown only if no
newer outcome has been shown already, so a slow old solve can never overwrite a newer
answer. A rejected scene sets ``error`` (the core's message, naming the field; the newest
change's fault first, :func:`newest_fault`) and leaves ``view`` (the last good result) on
screen.

Previews (:meth:`SolveController.request_preview`): while a slider waits for its release
(solves too slow to follow it), the page may ask for a cheaper scene of the dragged value
(the base elastic at loading, :func:`core.scene.elastic_at_loading`). A preview starts
only when this session's worker is idle (one asked while a request runs starts when it
ends), one at a time, the newest wanted next; it never becomes ``view`` (downloads, pins
and the live decision keep the last real answer), and any request drops the previews
asked before it (a request that comes while one solves waits for it: one preview's solve,
6-50 ms).

Where solves run: on the thread that waits for them (a shared thread pool, or the caller),
or, once :func:`use_worker_processes` has started them, in worker processes
(:mod:`explorer.solving.workers`), the thread then only waiting. ``python -m explorer`` uses
worker processes, so that the server's own process keeps its time for the pages.

Nothing here imports Panel: ``dispatch`` is how outcomes get back to the UI (the app
passes one that schedules on its Bokeh document); the default applies them at once.
"""

from __future__ import annotations

import copy
import logging
import re
import threading
import time
from collections.abc import Callable
from concurrent.futures import Executor, Future, ThreadPoolExecutor
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import param

from core import STAGE_CACHE_BYTES, scene_from_dict, solve
from core.scene import creeps, elastic_at_loading, punches_from_dict
from core.study import parse_path
from core.work import SolveCancelled

from ..model import DesignLimits, ExplorerState, ResultView, prepare_view, scene_with_limits
from .answer_wait import when_answered
from .result_cache import RESULTS, approx_bytes, result_key
from .trace import mark
from .workers import (
    SentRequest,
    SolverProcesses,
    WorkerFailed,
    download_text,
    preview_view,
    solution_text,
    solve_view,
)

if TYPE_CHECKING:
    from core.back_analysis import Calibration

__all__ = ["RESULTS", "SolveController", "approx_bytes", "describe_field", "format_error",
           "result_key", "run_in_background", "shared_pool", "use_worker_processes",
           "worker_processes"]

log = logging.getLogger(__name__)

# Shared by all sessions. Solving in this process: solves are numpy-heavy and release the
# GIL only in part, so a few threads suffice and bound the load a crowd of sessions can put
# on the machine. With worker processes, the threads only wait for the workers, one per
# session with a request out at most; the server then sizes the pool for its sessions.
_POOL: ThreadPoolExecutor | None = None
_POOL_LOCK = threading.Lock()


def shared_pool(max_workers: int = 4) -> ThreadPoolExecutor:
    """The process-wide thread pool the explorer solves on."""
    global _POOL
    with _POOL_LOCK:
        if _POOL is None:
            _POOL = ThreadPoolExecutor(max_workers=max_workers, thread_name_prefix="solve")
        return _POOL


#: A request that comes while this session's solve has run this long [s] cancels it (in a
#: worker process): a solve over the explorer's live bound (0.1 s) draws no frame of a
#: drag anyway, and the newest request (a preset switch, a typed value, a release) then
#: waits for no answer nobody wants. Measured before: a preset switch behind the stepped
#: punch's lift-off solves (4-8 s each) took 10.6 s (benchmarks/results/
#: explorer_latency_presets.md).
CANCEL_AFTER_S = 0.25
#: The outcome of a cancelled solve: nothing to show (the newer request's follows).
CANCELLED = "cancelled"


def _default_solve(scene: dict[str, Any]) -> Any:
    return solve(scene)


#: The worker processes the explorer solves in, once :func:`use_worker_processes` has
#: started them (``python -m explorer`` does); None: solves run on the threads that ask.
_PROCESSES: SolverProcesses | None = None


def use_worker_processes(lanes: int, stage_cache_bytes: int | None = None) -> SolverProcesses:
    """Solve in ``lanes`` worker processes from now on (all sessions of this process).

    ``stage_cache_bytes`` [bytes] bounds the solver's stage caches of each worker; the
    default divides the solver's budget (``core.STAGE_CACHE_BYTES``) among them,
    so the memory the caches may hold does not grow with the number of workers. Sessions
    created before the call keep solving where they did.
    """
    global _PROCESSES
    if stage_cache_bytes is None:
        stage_cache_bytes = STAGE_CACHE_BYTES // max(1, lanes)
    processes = SolverProcesses(lanes, stage_cache_bytes)
    processes.start()
    old, _PROCESSES = _PROCESSES, processes
    if old is not None:
        old.shutdown()
    return processes


def worker_processes() -> SolverProcesses | None:
    """The worker processes in use (None when solves run in this process)."""
    return _PROCESSES


def run_in_background(fn: Callable[..., Any], *args: Any) -> Any:
    """``fn(*args)`` as background work (an FE coating check, a fit): in a worker process
    at the lower priority of :meth:`SolverProcesses.run_background` when the server has
    worker processes, else here, on the calling thread."""
    processes = worker_processes()
    if processes is None:
        return fn(*args)
    return processes.run_background(processes.assign(), fn, *args)


#: Translation of the first part of a core field path into words on screen.
_FIELD_WORDS = {
    "punch": "Punch",
    "punches": "Punches",
    "coating": "Coating",
    "base": "Base",
    "loading": "Loading",
    "times": "Time span",
    "solver": "Solver",
}


def describe_field(path: str) -> str:
    """A field path of the core (``coating[1].thickness``) in words (``Coating layer 2,
    thickness``); unknown paths come back unchanged."""
    head, _, rest = path.partition(".")
    if head.startswith("punches[") and head.endswith("]"):
        try:
            index = int(head[len("punches["):-1])
        except ValueError:
            return path
        words = f"Punch {index + 1}"
    elif head.startswith("coating[") and head.endswith("]"):
        try:
            index = int(head[len("coating["):-1])
        except ValueError:
            return path
        words = f"Coating layer {index + 1}"
    elif head in _FIELD_WORDS:
        words = _FIELD_WORDS[head]
    else:
        return path
    return f"{words}, {rest.replace('.', ', ').replace('_', ' ')}" if rest else words


#: A number with an SI unit of force, moment or stress in the core's messages.
_SI_VALUE = re.compile(r"(?<![\w.])(-?\d+(?:\.\d*)?(?:e[+-]?\d+)?) (N·m/m|N/m|Pa)(?![\w/·])")
#: The page's unit of each (its size in SI): loads in kN/m and kN·m/m as the sliders.
_PAGE_UNITS = {"N/m": ("kN/m", 1e3), "N·m/m": ("kN·m/m", 1e3)}


def _page_units(text: str) -> str:
    """The core's SI values of forces, moments and stresses in the page's units ("P =
    -200000 N/m" reads "P = -200 kN/m"; a stress in kPa or MPa as it reads best)."""
    def shown(match: re.Match[str]) -> str:
        value, unit = float(match.group(1)), match.group(2)
        if unit == "Pa":
            unit, size = ("MPa", 1e6) if abs(value) >= 1e6 else ("kPa", 1e3)
        else:
            unit, size = _PAGE_UNITS[unit]
        return f"{value / size:.6g} {unit}"

    return _SI_VALUE.sub(shown, text)


#: A length in metres in the core's messages, not a position (``x = -1 m`` is a place
#: on the punch, whose boxes are in metres)
_METRES = re.compile(
    r"(?<!x = )(?<!x = -)(?<![\w.])(-?\d+(?:\.\d*)?(?:e[+-]?\d+)?) m(?![\w/·²])")
#: Fields whose box on the page is in millimetres (a coating layer's thickness).
_MILLIMETRE_FIELDS = re.compile(r"(punches\[\d+\]\.)?coating\[\d+\]\.thickness")


#: Fields whose box on the page has a unit of its own: (path, page unit, its size in the
#: core's unit). A value the core refuses ("got 0", "is 0 Pa") is said in it.
_BOX_UNITS = (
    (re.compile(r"(punches\[\d+\]\.)?coating\[\d+\]\.modulus"), "MPa", 1e6),
    (re.compile(r"base\.creep\.modulus(_final)?"), "GPa", 1e9),
    (re.compile(r"base\.thickness|(punches\[\d+\]\.)?(punch\.)?half_width"), "m", 1.0),
    (re.compile(r"base\.age_at_loading|times\.(end|start)"), "days", 1.0),
    # C∞ is typed in 1/GPa: "got -1e-09" read for a box showing -1
    (re.compile(r"base\.creep\.compliance(_final)?"), "1/GPa", 1e-9),
    (re.compile(r"(punches\[\d+\]\.)?punch\.shape\.wavelength"), "m", 1.0),
)
#: A refused value in the core's messages: "got -3" or "is 0 Pa", then the end, a comma,
#: a colon, a parenthesis or the place ("at x = ...").
_REFUSED_VALUE = re.compile(r"(\b(?:got|is) )(-?\d+(?:\.\d*)?(?:e[+-]?\d+)?)"
                            r"(?: (?:Pa|m|days?))?(?=$|[,;:)]| at | \()")


#: A bound of a refused value in the core's messages: "must be >= 10000", "<= 1e+13" or
#: the range "[10000, 1e+13] Pa".
_BOUND = re.compile(r"(\bmust be (?:>=|<=|>|<) )(-?\d+(?:\.\d*)?(?:e[+-]?\d+)?)")
_RANGE = re.compile(r"\[(-?\d+(?:\.\d*)?(?:e[+-]?\d+)?), (-?\d+(?:\.\d*)?(?:e[+-]?\d+)?)\]"
                    r" Pa\b")
#: The core's reminder that moduli are in Pa (a box in MPa or GPa has no use for it).
_PASCAL_HINT = re.compile(r" \(moduli are in Pa[^)]*\)")


def format_error(message: str) -> str:
    """The core's ``"field.path: reason"`` message with the field also named in words,
    its refused value in the unit of the field's box (a coating's thickness in mm, its
    modulus in MPa, the base's in GPa), and its SI values of forces, moments and
    stresses in the page's units."""
    field = message.partition(":")[0].strip()
    for pattern, unit, size in _BOX_UNITS:
        if pattern.fullmatch(field):
            message = _REFUSED_VALUE.sub(
                lambda m, unit=unit, size=size: f"{m.group(1)}{float(m.group(2)) / size:.6g} "
                                                f"{unit}", message)
            if unit.endswith("Pa"):
                message = _PASCAL_HINT.sub("", message)
                message = _BOUND.sub(lambda m, unit=unit, size=size: m.group(0) if float(
                    m.group(2)) == 0.0 else f"{m.group(1)}{float(m.group(2)) / size:.6g} {unit}",
                    message)
                message = _RANGE.sub(lambda m, unit=unit, size=size: (
                    f"[{float(m.group(1)) / size:.6g}, {float(m.group(2)) / size:.6g}] {unit}"),
                    message)
            break
    message = _page_units(message)
    if _MILLIMETRE_FIELDS.match(field):
        message = _METRES.sub(lambda m: f"{1e3 * float(m.group(1)):.6g} mm", message)
    path, sep, reason = message.partition(":")
    if not sep or " " in path.strip():
        return message
    words = describe_field(path.strip())
    if words == path.strip():
        return message
    return f"{words} ({path.strip()}):{reason}"


#: At most this many values changed by one request are looked at on their own
#: (:func:`newest_fault`): more (a preset, a file, an undo) is not one value typed.
_NEWEST_CHANGES = 8


def _changes(before: Any, now: Any, path: tuple = ()) -> list[tuple[tuple, Any]]:
    """The values of the scene dict ``now`` that differ from ``before``: (path, value)
    pairs, a path a tuple of keys and indices; a list whose length changed (a layer added)
    is one value."""
    if isinstance(before, dict) and isinstance(now, dict):
        found: list[tuple[tuple, Any]] = []
        for key in before.keys() | now.keys():
            if key not in now:
                return [(path, now)]
            found += _changes(before.get(key, _MISSING), now[key], path + (key,))
        return found
    if isinstance(before, list) and isinstance(now, list) and len(before) == len(now):
        found = []
        for k, (old, new) in enumerate(zip(before, now, strict=True)):
            found += _changes(old, new, path + (k,))
        return found
    return [] if before == now else [(path, now)]


_MISSING = object()


def _at(scene: Any, path: tuple) -> Any:
    """The value at ``path`` in ``scene`` (``_MISSING`` where it has none)."""
    for key in path:
        try:
            scene = scene[key]
        except (KeyError, IndexError, TypeError):
            return _MISSING
    return scene


def _with_changes(scene: dict[str, Any], changes: list[tuple[tuple, Any]]
                  ) -> dict[str, Any] | None:
    """``scene`` with ``changes`` (:func:`_changes`) made, or None where a path is not in
    it (a layer that the scene has not)."""
    out = copy.deepcopy(scene)
    for path, value in changes:
        if not path:
            return None
        target: Any = out
        for key in path[:-1]:
            try:
                target = target[key]
            except (KeyError, IndexError, TypeError):
                return None
        if isinstance(target, dict) or (isinstance(target, list)
                                        and isinstance(path[-1], int)
                                        and path[-1] < len(target)):
            target[path[-1]] = copy.deepcopy(value)
        else:
            return None
    return out


def _refusal(scene: dict[str, Any] | None) -> str | None:
    """The core's refusal of ``scene`` as it raised it (``"field.path: reason"``; None
    where it is taken, or not looked at)."""
    if scene is None:
        return None
    try:
        (punches_from_dict if "punches" in scene else scene_from_dict)(scene)
    except ValueError as exc:
        return str(exc)
    except Exception:  # a courtesy: the refusal of the request stands alone
        log.debug("scene not checked", exc_info=True)
    return None


def _path_of(message: str) -> tuple | None:
    """The field path a core message names (``"coating[0].thickness: ..."``), as keys
    and indices (the core's own reading of a path, as a study's); None where it names
    none."""
    path = message.partition(":")[0].strip()
    if not path or " " in path:
        return None
    try:
        return parse_path(path)
    except ValueError:
        return None


def _related(path: tuple, paths: list[tuple]) -> bool:
    """Whether ``path`` is one of ``paths``, inside one, or holds one."""
    return any(path[:len(p)] == p or p[:len(path)] == path for p in paths)


#: Older faults set aside at most, looking for the newest change's (:func:`newest_fault`).
_OLDER_FAULTS = 4


def newest_fault(error: str, good: dict[str, Any] | None, before: dict[str, Any] | None,
                 now: dict[str, Any] | None) -> str:
    """The refusal ``error`` of the scene ``now`` (formatted, :func:`format_error`), with
    the fault of the newest change first and the one still in the way before it after.

    The core checks a scene field by field and names the first field at fault: with a
    coating 0 mm thick already refused, a base thickness of -1 m typed next read again
    "coating thickness must be > 0", the value just typed not named; a Poisson ratio of
    0.7 refused, then a coating typed 0 mm thick, named the coating alone. Here the values
    changed from ``before`` (the scene asked before) to ``now`` are the newest; the older
    faults the core names in ``now`` are set back to their values in ``good`` (the scene
    of the result on screen), one at a time, until it names a newest value (its fault
    comes first) or none (the newest values are taken). Values typed since ``good`` and
    taken stay as typed (a time span's end typed, then its start, is not blamed on the
    start). The fault of the rest (the newest values set back) follows.
    """
    if good is None or before is None or now is None:
        return error
    changes = _changes(before, now)
    newest_paths = [path for path, _ in changes if path]
    if not newest_paths or len(changes) > _NEWEST_CHANGES:
        return error
    probe: dict[str, Any] | None = now
    newest = None
    for _ in range(_OLDER_FAULTS + 1):
        fault = _refusal(probe)
        path = None if fault is None else _path_of(fault)
        if fault is None or path is None:
            break
        if _related(path, newest_paths):
            newest = format_error(fault)
            break
        kept = _at(good, path)
        if kept is _MISSING or probe is None:
            break
        probe = _with_changes(probe, [(path, kept)])
    # the others: ``now`` with the newest values set back to those on screen (not
    # ``before``, whose fault the newest value may have mended)
    undone = [(path, _at(good, path)) for path in newest_paths]
    rest = None if any(v is _MISSING for _, v in undone) else _refusal(
        _with_changes(now, undone))
    faults: list[str] = []
    for fault in (newest, error, None if rest is None else format_error(rest)):
        if fault and fault not in faults:
            faults.append(fault)
    if len(faults) == 1:
        return faults[0]
    return (faults[0].rstrip(".") + ". Also still not accepted: "
            + "; ".join(f.rstrip(".") for f in faults[1:]))


def _reused(view: ResultView) -> ResultView:
    """A kept result as shown again: the same view, marked ``info["reused"]``."""
    return replace(view, info={**view.info, "reused": True})


def _failure_text(exc: Exception) -> str:
    """What the page says of a solve that raised ``exc``."""
    if isinstance(exc, ValueError):  # the core's message, naming the field
        return format_error(str(exc))
    if isinstance(exc, WorkerFailed):
        return f"The solver failed on this scene: {exc}."
    if isinstance(exc, MemoryError) and str(exc):  # a worker's bound, said in words
        return f"The solver stopped: {exc}."
    # the session must survive any failure of a solve
    log.error("solve failed", exc_info=exc)
    return f"The solver failed on this scene ({type(exc).__name__}: {exc})."


class SolveController(param.Parameterized):
    """Turns state changes into solves and solves into a displayed :class:`ResultView`."""

    view = param.ClassSelector(class_=ResultView, default=None, allow_None=True,
                               doc="The result on screen (the last good one).")
    error = param.String(default="", doc="Why the newest request was not solved ('' if ok).")
    busy = param.Boolean(default=False, doc="A newer request than the one shown is running.")
    requests = param.Integer(default=0, doc="Requests made.")
    solves = param.Integer(default=0, doc="Outcomes delivered (results and errors).")
    preview = param.ClassSelector(
        class_=ResultView, default=None, allow_None=True,
        doc="The newest preview (request_preview) since the last request, else None.")

    def __init__(self, state: ExplorerState,
                 solve: Callable[[dict[str, Any]], Any] | None = None,
                 executor: Executor | None | str = "shared",
                 dispatch: Callable[[Callable[[], None]], None] | None = None,
                 auto: bool = True, **params: Any) -> None:
        """``executor``: ``"shared"`` (the process pool), an Executor, or None to solve
        synchronously in the caller (tests, scripts). ``auto``: solve on every change."""
        super().__init__(**params)
        self.state = state
        self._solve = solve or _default_solve
        self._executor = shared_pool() if executor == "shared" else executor
        # the lane of the worker processes this session prefers (its stage caches are there)
        self._processes = _PROCESSES if solve is None else None
        self._lane = self._processes.assign() if self._processes is not None else 0
        self._dispatch = dispatch or (lambda callback: callback())
        self._lock = threading.Lock()
        self._latest = 0          # id of the newest request
        self._shown = 0           # id of the newest outcome shown
        self._running = False
        self._pending: tuple[int, dict[str, Any]] | None = None
        # this session's request in a worker now, since when (monotonic [s]) and its scene
        self._in_worker: tuple[SentRequest, float, dict[str, Any]] | None = None
        # the preview scene wanted next (the newest asked), and whether one is solving
        self._preview_wanted: dict[str, Any] | None = None
        self._preview_running = False
        self._preview_generation = 0  # up by one at every request and stop_previews
        # the scenes of the newest request and of the one before (newest_fault)
        self._asked: tuple[dict[str, Any] | None, dict[str, Any] | None] = (None, None)
        if auto:
            state.param.watch(lambda event: self.request(), "revision")

    @property
    def executor(self) -> Executor | None:
        """Where this controller's solves run (None: in the caller)."""
        return self._executor

    # -- requests --------------------------------------------------------------------
    def request(self, keep_running: bool = False) -> int:
        """Ask for a solve of the current state; returns the request id. ``keep_running``:
        a drag step of a slider that applies every step, whose solve waits for this
        session's running one (the drag's next frame) instead of cancelling it after
        :data:`CANCEL_AFTER_S`; the release cancels it (:meth:`released`)."""
        with self._lock:
            self._latest += 1
            rid = self._latest
            self._preview_wanted = None  # the previews asked before are not wanted
            self._preview_generation += 1
        if self.preview is not None:
            self.preview = None
        try:
            scene = self.state.to_scene()
        except ValueError as exc:  # a state the screen cannot turn into a scene
            self._ask(None)
            self.requests = rid
            self._deliver(rid, format_error(str(exc)))
            return rid
        self._ask(scene)
        if self._executor is None:
            self.requests = rid
            self._deliver(rid, self._compute(scene))
            return rid
        known = self._known(scene)
        if known is not None:
            # (a preset switched back to, a value stepped back over) shown at once: in
            # the same message to the page as the change that asked for it, where a
            # thread's turn had sent it apart (the page laid out twice on a preset switch)
            with self._lock:
                self._pending = None  # an older request waiting for the running one
            self.requests = rid
            self._deliver(rid, known)
            return rid
        with self._lock:
            queued = self._running
            if queued:
                self._pending = (rid, scene)
            self._running = True
            running = self._in_worker
        if (queued and not keep_running and running is not None
                and self._processes is not None
                and time.monotonic() - running[1] > CANCEL_AFTER_S):
            self._processes.cancel(running[0])
        # the worker first: the watchers of ``requests`` and ``busy`` (the status line)
        # run while it solves
        sent = None if queued else self._send_now(scene)
        self.requests = rid
        self.busy = True
        if not queued:
            self._wait(rid, scene, sent)
        return rid

    def _ask(self, scene: dict[str, Any] | None) -> None:
        """Note the scene of a request (None: the state gave none), unless it is the one
        asked last (a solve asked again)."""
        if scene is None or scene != self._asked[1]:
            self._asked = (self._asked[1], scene)

    def released(self) -> bool:
        """A slider was let go after a drag: the solve of a value dragged over, still
        running in this session's worker while the released value waits behind it, is
        cancelled (``CANCEL_AFTER_S`` aside), so that the released value is solved at
        once rather than after an answer that would be drawn and at once replaced. Not
        where the waiting scene is the running one. Returns whether it cancelled."""
        with self._lock:
            pending, running = self._pending, self._in_worker
        if pending is None or running is None or self._processes is None:
            return False
        key = result_key(pending[1])  # (here, not on every request's way)
        if key is not None and key == result_key(running[2]):
            return False
        self._processes.cancel(running[0])
        return True

    def _known(self, scene: dict[str, Any]) -> ResultView | None:
        """The result of ``scene`` if one is kept already (:data:`RESULTS`), else None."""
        if self._solve is not _default_solve:
            return None
        key = result_key(scene)
        view = RESULTS.get(key) if key is not None else None
        return None if view is None else _reused(view)

    def _wait(self, rid: int, scene: dict[str, Any], sent: SentRequest | None) -> None:
        # A request written to the worker by the event loop is awaited by that loop
        # (explorer/solving/answer_wait.py); anything else by a thread of the pool.
        if sent is not None:
            with self._lock:
                self._in_worker = (sent, time.monotonic(), scene)
        if sent is None or not when_answered(
                sent, lambda: self._answered(rid, scene, sent),
                lambda: self._executor.submit(self._work, rid, scene, sent)):
            self._executor.submit(self._work, rid, scene, sent)

    def _answered(self, rid: int, scene: dict[str, Any], sent: SentRequest) -> None:
        # on the event loop, the answer in the pipe: read, shown, and the next request
        # (if one came meanwhile) sent
        outcome = self._collect(scene, sent)
        self._dispatch(lambda: self._deliver(rid, outcome))
        # (a cancelled outcome always has a pending request: only a newer one cancels)
        pending = self._take_pending()
        if pending is not None:
            self._wait(*pending, self._send_now(pending[1]))

    def _take_pending(self) -> tuple[int, dict[str, Any]] | None:
        # the request that came while one ran (the newest), or None: then nothing runs,
        # and a preview asked meanwhile (another slider held) starts
        with self._lock:
            pending, self._pending = self._pending, None
            if pending is not None:
                return pending
            self._running = False
            start = self._preview_wanted is not None and not self._preview_running
            if start:
                self._preview_running = True
        if start:
            self._next_preview()
        return None

    def _collect(self, scene: dict[str, Any], sent: SentRequest) -> ResultView | str:
        # The answer of ``sent`` (there to read), kept in RESULTS by a thread of the pool:
        # the cache may wait for another session's solve of the same scene, which the
        # event loop must not.
        try:
            view = self._processes.result(sent)
        except SolveCancelled:
            return CANCELLED
        except Exception as exc:
            return _failure_text(exc)
        finally:
            self._left_worker(sent)
        key = result_key(scene)
        cached = RESULTS.get(key) if key is not None else None
        if cached is not None:
            return _reused(cached)
        if key is not None:
            self._executor.submit(RESULTS.get_or_compute, key, lambda: view)
        return view

    def _send_now(self, scene: dict[str, Any]) -> SentRequest | None:
        # The request goes to this session's worker from the thread that made it (the
        # event loop) when the worker is free and the result not known already; the
        # thread of :meth:`_work` then only collects the answer.
        if self._processes is None:
            return None
        key = result_key(scene)
        if key is None or RESULTS.get(key) is not None:
            return None
        return self._processes.send_now(self._lane, solve_view, scene)

    def start(self) -> int:
        """First request of a session: shown at once when the result is already known
        (the page then arrives with its plots), else solved in the background."""
        try:
            scene = self.state.to_scene()
        except ValueError:
            return self.solve_now()  # delivers the message
        if self._executor is None or self._known(scene) is not None:
            return self.solve_now()
        return self.request()

    def solve_now(self) -> int:
        """Solve the current state in the caller and show the outcome (first paint)."""
        with self._lock:
            self._latest += 1
            rid = self._latest
        self.requests = rid
        try:
            scene = self.state.to_scene()
        except ValueError as exc:
            self._ask(None)
            outcome: ResultView | str = format_error(str(exc))
        else:
            self._ask(scene)
            outcome = self._compute(scene)
        self._deliver(rid, outcome)
        return rid

    # -- previews --------------------------------------------------------------------
    def request_preview(self, scene: dict[str, Any]) -> bool:
        """Preview ``scene`` (a scene dict; see the module notes): its base elastic at
        loading (:func:`~explorer.solving.workers.preview_view`) is solved at once when
        nothing of this session solves, else after the preview solving now (the newest
        asked wins); never while a request runs or waits. Its result becomes ``preview``
        unless a request came meanwhile; a scene that fails is dropped (the release's
        solve says why). False (and nothing asked) for a base that does not creep: its
        preview would be the answer itself."""
        if not creeps(scene):
            return False
        with self._lock:
            self._preview_wanted = scene
            if self._preview_running or self._running:
                return True
            self._preview_running = True
        self._next_preview()
        return True

    @staticmethod
    def previews_differ(scene: dict[str, Any], applied: dict[str, Any]) -> bool:
        """Whether ``scene`` has a preview that differs from that of the scene ``applied``
        (their bases elastic at loading, the name and description aside): False for a
        base that does not creep, a change of a creep field alone that leaves the modulus
        at loading (C∞, a rate: every preview would be the same) and a scene whose preview
        cannot be made (its release says why). Well under a millisecond of checks."""
        if not creeps(scene):
            return False
        try:
            ours, theirs = elastic_at_loading(scene), elastic_at_loading(applied)
        except ValueError:
            return False
        aside = ("name", "description")
        return ({k: v for k, v in ours.items() if k not in aside}
                != {k: v for k, v in theirs.items() if k not in aside})

    def stop_previews(self) -> None:
        """Drop the previews asked and not solved yet (the one solving is not shown)."""
        with self._lock:
            self._preview_wanted = None
            self._preview_generation += 1
        if self.preview is not None:
            self.preview = None

    def _next_preview(self) -> None:
        # with _preview_running set: the wanted scene solved (or nothing is wanted)
        with self._lock:
            scene, self._preview_wanted = self._preview_wanted, None
            epoch = self._preview_generation
            if scene is None or self._running:
                self._preview_running = False
                return
        if self._executor is None:
            self._delivered_preview(epoch, scene, self._preview_view(scene, None))
            return
        sent = None
        if self._processes is not None:
            # only on an idle worker (it may still delay a request that comes meanwhile,
            # by one preview's solve)
            sent = self._processes.send_now(self._lane, preview_view, scene)
            if sent is None:
                with self._lock:
                    # kept for the next step or the end of the work on the lane
                    if self._preview_wanted is None and epoch == self._preview_generation:
                        self._preview_wanted = scene
                    self._preview_running = False
                return
        try:
            self._executor.submit(self._preview_work, epoch, scene, sent)
        except BaseException:
            # (a pool shut down): the answer read here, so that the lane is freed
            with self._lock:
                self._preview_running = False
            if sent is not None:
                self._preview_view(scene, sent)
            raise

    def _preview_work(self, epoch: int, scene: dict[str, Any],
                      sent: SentRequest | None) -> None:
        view = self._preview_view(scene, sent)
        self._dispatch(lambda: self._delivered_preview(epoch, scene, view))

    def _preview_view(self, scene: dict[str, Any], sent: SentRequest | None
                      ) -> ResultView | None:
        try:
            if sent is not None:
                return self._processes.result(sent)
            return preview_view(scene, self._solve)
        except Exception:  # noqa: BLE001 - a preview that fails is only not shown
            log.debug("preview failed", exc_info=True)
            return None

    def _delivered_preview(self, epoch: int, scene: dict[str, Any],
                           view: ResultView | None) -> None:
        with self._lock:
            wanted = epoch == self._preview_generation and not self._running
        try:
            if view is not None and wanted:
                self.preview = view
        finally:  # (a page failing to draw it must not stop the previews for good)
            self._next_preview()

    def _left_worker(self, sent: SentRequest) -> None:
        with self._lock:
            if self._in_worker is not None and self._in_worker[0] is sent:
                self._in_worker = None

    def _work(self, rid: int, scene: dict[str, Any], sent: SentRequest | None = None) -> None:
        while True:
            outcome = self._compute(scene, sent)
            if sent is not None:
                self._left_worker(sent)
            sent = None
            self._dispatch(lambda rid=rid, outcome=outcome: self._deliver(rid, outcome))
            pending = self._take_pending()
            if pending is None:
                if outcome is not CANCELLED:
                    return
                # another session's solve of the same scene, which this one waited for,
                # was cancelled: this session still wants the answer
                with self._lock:
                    self._running = True
                pending = (rid, scene)
            rid, scene = pending

    def _view(self, scene: dict[str, Any], sent: list[SentRequest]) -> ResultView:
        if self._processes is not None:
            if sent:
                return self._processes.result(sent.pop())
            return self._processes.run(self._lane, solve_view, scene)
        return prepare_view(self._solve(scene), scene)

    def _compute(self, scene: dict[str, Any],
                 sent: SentRequest | None = None) -> ResultView | str:
        key = result_key(scene) if self._solve is _default_solve else None
        unread = [sent] if sent is not None else []  # emptied once its answer is read
        try:
            if key is None:
                return self._view(scene, unread)
            view, reused = RESULTS.get_or_compute(key, lambda: self._view(scene, unread))
            return _reused(view) if reused else view
        except SolveCancelled:
            return CANCELLED
        except Exception as exc:
            return _failure_text(exc)
        finally:
            if unread and self._processes is not None:
                # another session solved the same scene meanwhile: the worker's answer
                # to this one is read and dropped, which frees the lane
                try:
                    self._processes.result(unread.pop())
                except Exception:
                    log.debug("dropped answer failed", exc_info=True)

    def _deliver(self, rid: int, outcome: ResultView | str) -> None:
        mark("delivered", rid=rid)
        if rid < self._shown or outcome is CANCELLED:
            return
        self._shown = rid
        with self._lock:
            latest = self._latest
        if isinstance(outcome, str):
            if rid == latest and outcome:
                outcome = newest_fault(outcome, None if self.view is None else self.view.scene,
                                       *self._asked)
            self.param.update(error=outcome, busy=rid < latest, solves=self.solves + 1)
        else:
            self.param.update(view=outcome, error="", busy=rid < latest,
                              solves=self.solves + 1)

    def download(self, view: ResultView, kind: str, limits: DesignLimits | None = None,
                 shown_time: float | None = None,
                 check: dict[str, Any] | None = None,
                 calibration: Calibration | None = None) -> str | bytes:
        """The file of a download of ``view``: ``"to_csv"`` (the histories),
        ``"pressure_csv"`` (q(x, t)) or ``"to_json"`` (everything), in SI units, or the
        printable report, ``"report_html"`` (text) or ``"report_pdf"`` (bytes).

        The shown scene is solved again (where this session's solves run, with its
        caches warm): the solver is deterministic, so the file holds the numbers on screen;
        the JSON's and the report's solve report is the one of the result on screen.
        ``limits``: the Check tab's, put into the scene in place of its own (the report's
        design check); ``shown_time`` [day after loading]: the time on screen, whose
        contact the report describes; ``check``: the FE check of the coating model
        (:func:`core.scene.check_scene`), reported where it was made for this scene;
        ``calibration``: the back-analysis whose fitted scene is on screen (the report's
        section "Back-analysis").
        """
        scene = view.scene if limits is None else scene_with_limits(view.scene, limits)
        if self._processes is not None:
            return self._processes.run(self._lane, download_text, scene, kind, view.info,
                                       shown_time, check, calibration)
        return solution_text(self._solve(scene), kind, view.info, shown_time, check,
                             calibration)

    def solved_within(self, seconds: float) -> bool:
        """Whether the result kept took less than ``seconds`` [s] of CPU time to solve
        (what the scene costs: on a shared server its wall time swings with the others'
        work); False before the first result."""
        view = self.view
        if view is None:
            return False
        # a result kept from before the CPU time was recorded has its wall time only
        spent = view.info.get("cpu_seconds", view.info.get("seconds"))
        return isinstance(spent, (int, float)) and spent < seconds

    def download_later(self, view: ResultView, kind: str, limits: DesignLimits | None = None,
                       shown_time: float | None = None,
                       check: dict[str, Any] | None = None,
                       calibration: Calibration | None = None) -> Future[str | bytes]:
        """:meth:`download` off the calling thread: a future of the file, done when the
        worker has answered (at once where solves run in the caller). The server's event
        loop awaits it (``asyncio.wrap_future``) and keeps serving every page meanwhile."""
        if self._executor is None:
            done: Future[str | bytes] = Future()
            try:
                done.set_result(self.download(view, kind, limits, shown_time, check,
                                              calibration))
            except Exception as exc:
                done.set_exception(exc)
            return done
        return self._executor.submit(self.download, view, kind, limits, shown_time, check,
                                     calibration)

    def wait(self, timeout: float = 60.0) -> bool:
        """Block until the newest request has been delivered (for scripts and tests)."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self._shown >= self._latest and not self._running:
                return True
            time.sleep(0.005)
        return False
