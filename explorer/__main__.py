"""Serve the explorer: ``python -m explorer [--port 5006] [--show]``.

The page is served at ``/app``; ``/`` redirects there. By default the server listens on
localhost only and opens no browser.
"""

from __future__ import annotations

import argparse
import concurrent.futures
import importlib.util
import os
import signal
import socket
import sys
from collections.abc import Callable
from typing import Any

import core
from core.work import BLAS_THREAD_VARIABLES

# The solver works on small dense matrices from several threads at once; BLAS threads on
# top of those only fight for the cores (a cold solve measured 1.5 s instead of 0.09 s on
# 2 cores). Set before numpy is first imported; an explicit setting is respected.
for _name in BLAS_THREAD_VARIABLES:
    os.environ.setdefault(_name, "1")

#: The memory allocator the served explorer runs with (``PYTHONMALLOC``). Python's own
#: small-object allocator takes memory in 1 MiB arenas and returns an arena to the system
#: only once every object in it is gone. A page builds ~46,000 objects; the few that
#: outlive its session (a cancelled timer, a session record) each kept a whole arena, so a
#: server whose Python objects stayed flat (+12 kB per 25 dropped sessions) grew by
#: ~18 MiB of arenas three-quarters empty per round. The C library's allocator gives
#: back the free pages around such survivors (``gc_policy`` trims after each collection).
SERVER_ALLOCATOR = "malloc"
#: The C library's arenas the served explorer's threads share (``MALLOC_ARENA_MAX``). Each
#: thread that allocates gets an arena of its own by default (up to 8 per core), and
#: every arena keeps the pages around the few objects that outlive the work that filled
#: it: after the load test with its heavy pages (``benchmarks/load_test.py --heavy``, 18
#: threads) the server's live heap was back to its start +7 MiB, but ten thread arenas
#: held 63 MiB of pages (the server's own process 158 -> 235 MiB). With two: 158 -> 196
#: and 199 MiB in two runs, the movers' and the probe's latencies as without (the
#: threads allocate under Python's lock anyway). The solver and study processes, started
#: from the server's environment, run with the same setting (their solves run on one
#: thread each; not measured apart).
SERVER_ARENAS = 2

#: How long the server waits for the headers of a request on an open connection [s].
#: Tornado's default is an hour: every connection (each page's GET and websocket) left a
#: one-hour timer on the event loop, cancelled when the connection closed but kept in the
#: loop's queue until its hour was up or the cancelled ones outnumbered the live ones, one
#: more of the small survivors per dropped session. A minute is ample for a browser to
#: send a request's headers; an idle keep-alive connection is then closed (the browser
#: opens another), and a client that sends nothing is dropped within the minute, not the
#: hour.
HEADER_TIMEOUT_S = 60.0


#: Worker processes by default: the server's own process keeps a core for the pages; two
#: at least, so that one slow solve cannot hold up every session (measured on 2 cores with
#: 20 sessions, benchmarks/results/load_test.md: 2 workers gave the crowd's p95 1.75-1.92x
#: the single session's in three runs, solving in the server's threads 4.1x; one worker
#: measured no faster than two).
DEFAULT_SOLVER_PROCESSES = max(2, min(4, (os.cpu_count() or 2) - 1))
#: Threads waiting for the worker processes, for all sessions together; beyond this many
#: sessions with a request out at once, requests queue before reaching the workers.
WAITING_THREADS = 64
#: With ``--exit-with-parent``: how often the server looks whether its parent still runs
#: [s] (a look costs microseconds; the server stops within this long of its parent).
PARENT_CHECK_S = 1.0


#: Largest message the server accepts from a page [bytes]. Uploads arrive in chunks of
#: 256 KiB (explorer/views/widgets.py) and every other message is small: a larger one (a
#: 15-million-character scene name held 380 MiB of the server's memory) closes that
#: page's connection instead of being read.
WEBSOCKET_MAX_BYTES = 4 * 2**20


#: What the page needs beyond the solver (the ``explorer`` extra of the package).
EXPLORER_PACKAGES = ("panel", "bokeh", "param", "tornado", "holoviews", "distributed", "xarray")


#: Seconds with no page open after which the server empties its caches and warms up again
#: (``--release-after-idle``; explorer/solving/idle_release.py). Longer than a page reload
#: or a class moving rooms takes, short enough that a server left running gives its memory
#: back within minutes.
RELEASE_AFTER_IDLE_S = 60.0


def quiet_bokeh_diagnostics() -> None:
    """Turn off Bokeh's "expensive error diagnostics" (its setting
    ``perform_error_diagnostics``) in the server: a check of every callback's signature
    as it is registered (~4,800 a page, each through ``inspect.signature``: 6 % of a
    page's building, cProfile) and close-match suggestions for a misspelt attribute. They
    serve whoever writes the code, and the test suite keeps them on (the explorer's code
    is checked there: tests/explorer/test_served_by_panel.py serves a page with them, as
    any other server does); a visitor's page gains nothing from them."""
    from bokeh.settings import settings

    settings.perform_error_diagnostics.set_value(False)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="coated-punch-explorer",
        description="Serve the coated-punch explorer. Open http://localhost:PORT/app "
                    "(/ redirects there). Add ?preset=NAME to start from a preset scene; "
                    "the address bar always holds a link to the scene on screen.")
    parser.add_argument("--version", action="version",
                        version=f"coated-punch {core.__version__}")
    parser.add_argument("--port", type=int, default=5006,
                        help="port to listen on (default 5006)")
    parser.add_argument("--address", default="localhost",
                        help="address to listen on (default localhost; 0.0.0.0 exposes the "
                             "explorer on every network interface)")
    parser.add_argument("--allow-websocket-origin", action="append", default=None,
                        metavar="HOST[:PORT]",
                        help="host allowed to open the page's websocket (repeatable); needed "
                             "when the page is reached under a name other than localhost")
    parser.add_argument("--show", action="store_true",
                        help="open the page in the default browser")
    parser.add_argument("--warm-up", choices=("default", "all", "none"), default="default",
                        help="preset scenes solved before serving, so that visitors find them "
                             "ready: the default one (default), all of them (slower start), "
                             "or none")
    parser.add_argument("--solver-processes", type=int, default=DEFAULT_SOLVER_PROCESSES,
                        help="worker processes solving scenes for all sessions (default "
                             f"{DEFAULT_SOLVER_PROCESSES} on this machine: one per core but "
                             "one, at least 2, at most 4); 0 solves in the server's own "
                             "process, on --solver-threads threads")
    parser.add_argument("--solver-threads", type=int, default=2,
                        help="with --solver-processes 0: threads solving scenes, shared by "
                             "all sessions (default 2)")
    parser.add_argument("--session-linger", type=float, default=15.0, metavar="SECONDS",
                        help="how long a page's session is kept after its connection is "
                             "lost, for the page to reconnect, before everything it holds "
                             "is given back (default 15)")
    parser.add_argument("--release-after-idle", type=float, default=RELEASE_AFTER_IDLE_S,
                        metavar="SECONDS",
                        help="empty the caches of solved scenes and renew the solver "
                             "processes once no page has been open for this long (then "
                             "solve the --warm-up scenes again), 1 to 86400, or 0 never "
                             "(default "
                             f"{RELEASE_AFTER_IDLE_S:g})")
    parser.add_argument("--live-bound", type=float, default=None, metavar="SECONDS",
                        help="the sliders of the Punch, Coating, Base and Time tabs, which "
                             "otherwise wait for their release, follow a drag while the last "
                             "solve took less CPU time than this, 0.001 to 60 (default 0.1: "
                             "ten answers a second; the eccentricity slider of a lift-off "
                             "keeps its own 0.2); raise it on a slow server to keep more "
                             "sliders live at fewer frames, lower it to keep drags smooth")
    parser.add_argument("--exit-with-parent", action="store_true",
                        help="stop the server (as on SIGTERM) when the process that started "
                             "it ends, even if that process is killed: for scripts and test "
                             "runs that start a server of their own")
    return parser


def _restart_with_server_allocator() -> None:
    """Start this program again with :data:`SERVER_ALLOCATOR` and :data:`SERVER_ARENAS`
    (same process id, same arguments), unless an allocator was chosen in the environment
    (``PYTHONMALLOC``, which is respected: ``PYTHONMALLOC=pymalloc`` keeps Python's own;
    so is ``MALLOC_ARENA_MAX``)."""
    if os.environ.get("PYTHONMALLOC"):
        return
    os.environ["PYTHONMALLOC"] = SERVER_ALLOCATOR
    if not os.environ.get("MALLOC_ARENA_MAX"):  # (set and empty: as unset)
        os.environ["MALLOC_ARENA_MAX"] = str(SERVER_ARENAS)
    sys.stdout.flush()
    sys.stderr.flush()
    # the command line as given (python -m explorer ..., or the installed script)
    os.execv(sys.executable, [sys.executable, *sys.orig_argv[1:]])


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``python -m explorer`` and the ``coated-punch-explorer`` script.

    ``argv``: the arguments (default: the command line's). Run from the command line
    (``argv`` None), the program first starts itself again with the server's memory
    allocator (:data:`SERVER_ALLOCATOR`)."""
    args = build_parser().parse_args(argv)
    # (the restart below keeps the process id, hence the parent)
    parent = os.getppid() if args.exit_with_parent else None
    missing = [name for name in EXPLORER_PACKAGES if importlib.util.find_spec(name) is None]
    if missing:
        print(f"The explorer needs {', '.join(missing)}, not installed here: "
              "pip install 'coated-punch[explorer]'", file=sys.stderr)
        return 2
    if argv is None:
        _restart_with_server_allocator()
    import panel as pn

    from explorer.app import check_live_bound, create_app
    from explorer.fixes import closed_pages
    from explorer.model import ORDER
    from explorer.solving import (
        idle_release,
        shared_pool,
        use_worker_processes,
        warm_up,
        worker_processes,
    )

    if args.solver_processes < 0 or args.solver_threads < 1:
        print("--solver-processes must be 0 or more and --solver-threads 1 or more",
              file=sys.stderr)
        return 2
    if args.live_bound is not None:
        try:
            check_live_bound(args.live_bound)
        except ValueError as exc:
            print(str(exc).replace("live_bound", "--live-bound", 1), file=sys.stderr)
            return 2
    if not 0.5 <= args.session_linger <= 3600:
        print("--session-linger must be between 0.5 and 3600 seconds", file=sys.stderr)
        return 2
    if not (args.release_after_idle == 0 or 1 <= args.release_after_idle <= 86400):
        print("--release-after-idle must be 0 (never) or between 1 and 86400 seconds",
              file=sys.stderr)
        return 2
    closed_pages.install()  # a tab closed abruptly is a debug line, not a traceback
    quiet_bokeh_diagnostics()
    if args.solver_processes:
        print(f"Starting {args.solver_processes} solver process(es)...", file=sys.stderr,
              flush=True)
        use_worker_processes(args.solver_processes)
        # these threads only wait for the workers: one per session with a request out
        shared_pool(WAITING_THREADS)
    else:
        shared_pool(args.solver_threads)
    if args.warm_up != "none":
        keys = ORDER if args.warm_up == "all" else ORDER[:1]
        print(f"Solving {len(keys)} preset scene(s) once before serving...", file=sys.stderr,
              flush=True)
        warm_up(keys)
    origins = args.allow_websocket_origin
    if origins is None and args.address not in ("localhost", "127.0.0.1"):
        host = socket.gethostname() if args.address in ("0.0.0.0", "::") else args.address
        origins = [f"localhost:{args.port}", f"{host}:{args.port}"]
        print("Pages are accepted from " + ", ".join(origins) + " (add others with "
              "--allow-websocket-origin)", file=sys.stderr, flush=True)
    if parent is not None and os.getppid() != parent:
        # (the parent ended during the start-up: the serving loop would look only now)
        processes = worker_processes()
        if processes is not None:
            processes.shutdown()
        return 0
    print(f"Serving the explorer at http://{args.address}:{args.port}/app", file=sys.stderr,
          flush=True)
    linger_ms = int(args.session_linger * 1000)
    try:
        if args.release_after_idle:
            def released(done: dict[str, float]) -> None:
                print(f"No page open for {args.release_after_idle:g} s: emptied the caches "
                      f"({done['bytes'] / 2**20:.1f} MiB), collected "
                      f"{done['collected']:.0f} objects and renewed {done['workers']:.0f} "
                      f"solver process(es) in {done['seconds']:.1f} s", file=sys.stderr,
                      flush=True)

            from tornado.ioloop import IOLoop

            from explorer.fixes import gc_policy

            # the loop _serve runs (this thread's)
            io_loop = IOLoop.current()
            idle_release.enable(args.release_after_idle, on_release=released,
                                rewarm=None if args.warm_up == "none"
                                else lambda: warm_up(keys),
                                collect=lambda: _on_event_loop(
                                    io_loop, gc_policy.collect_ended_sessions))
        app: Callable[[], Any] = create_app
        if args.live_bound is not None:
            # a function (Panel serves a partial object as its text, not as a page)
            def app_with_bound(bound: float = args.live_bound) -> Any:
                return create_app(live_bound=bound)

            app = app_with_bound
        _serve(pn, {"app": app}, parent=parent, port=args.port, address=args.address,
               show=args.show, websocket_origin=origins, title="Coated punch explorer",
               liveness=True, websocket_max_message_size=WEBSOCKET_MAX_BYTES,
               unused_session_lifetime_milliseconds=linger_ms,
               check_unused_sessions_milliseconds=linger_ms,
               http_server_kwargs={"idle_connection_timeout": HEADER_TIMEOUT_S})
    except KeyboardInterrupt:
        pass  # Ctrl+C during the server's set-up
    finally:
        idle_release.disable()  # a release running stops before the workers do
        processes = worker_processes()
        if processes is not None:
            processes.shutdown()
    return 0


#: The longest a thread waits for a call it handed to the event loop [s].
ON_LOOP_TIMEOUT_S = 60.0


def _on_event_loop(io_loop: Any, fn: Callable[[], Any]) -> Any:
    """``fn()`` run on ``io_loop`` (a Tornado ``IOLoop`` running in another thread: never
    call this from the loop's own), its result or exception returned or raised here;
    ``concurrent.futures.TimeoutError`` after :data:`ON_LOOP_TIMEOUT_S` (a loop stopped or
    closed never runs it), and then ``fn`` is not run later either. The server's
    collection runs there: finalisers and weakref callbacks of what it frees (Bokeh
    documents, Tornado handles) expect the loop's thread."""
    done: concurrent.futures.Future[Any] = concurrent.futures.Future()

    def run() -> None:
        if not done.set_running_or_notify_cancel():
            return  # the waiting thread gave up
        try:
            done.set_result(fn())
        except BaseException as exc:  # noqa: BLE001 - handed to the waiting thread
            done.set_exception(exc)

    io_loop.add_callback(run)
    try:
        return done.result(timeout=ON_LOOP_TIMEOUT_S)
    except concurrent.futures.TimeoutError:
        done.cancel()
        raise


def _serve(pn: Any, apps: dict[str, Any], parent: int | None = None,
           **options: Any) -> None:
    """Serve ``apps`` with Panel until SIGTERM or SIGINT, then stop the server in order.

    With ``parent`` (a process id), also stop once this process's parent is no longer
    ``parent`` (it ended and the process was handed to another): a test run killed with
    SIGTERM or SIGKILL runs no clean-up of its own, and its servers kept running (two such
    servers were found alive 15 min later, at ~10 % of a core each).

    Both signals are handled by the event loop (``add_signal_handler``): the handler runs
    as one of the loop's callbacks and stops the loop there, and a signal that comes
    before the loop runs stops it as soon as it starts. A Python handler that raises
    KeyboardInterrupt instead runs between any two bytecodes of the main thread, also
    inside a weakref callback or a finaliser, where Python prints the exception
    ("Exception ignored in ...") and drops it: the server printed a traceback and kept
    serving until it was killed.
    """
    from tornado.ioloop import IOLoop, PeriodicCallback

    io_loop = IOLoop.current()
    loop = io_loop.asyncio_loop
    loop.add_signal_handler(signal.SIGTERM, io_loop.stop)
    try:
        server = pn.serve(apps, threaded=False, start=False, loop=io_loop, **options)
        # after pn.serve, which sets a SIGINT handler of its own
        loop.add_signal_handler(signal.SIGINT, io_loop.stop)
        if parent is not None:
            PeriodicCallback(lambda: os.getppid() != parent and io_loop.stop(),
                             1000 * PARENT_CHECK_S).start()
        try:
            server.start()
            io_loop.start()
        finally:
            # closes the listening socket and the sessions' connections, stops the callbacks
            server.stop()
    finally:
        for signum in (signal.SIGTERM, signal.SIGINT):
            loop.remove_signal_handler(signum)


if __name__ == "__main__":
    sys.exit(main())
