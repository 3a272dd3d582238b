"""Run the explorer in a child process: ``python -m explorer`` on a free loopback port.

For the browser tests and the benchmarks, which need a real server next to them::

    with ExplorerProcess(args=["--solver-threads", "2"], ready_timeout=300) as server:
        page.goto(server.url + "/app")

:class:`ExplorerProcess` starts the server, waits until ``/liveness`` answers and stops it
again (terminate, then kill). Importing this module does not import Panel: the server's
cost is paid in the child only.
"""

from __future__ import annotations

import contextlib
import os
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request
from collections.abc import Mapping, Sequence
from pathlib import Path
from types import TracebackType

__all__ = ["CHROMIUM", "CHROMIUM_ARGS", "ExplorerProcess", "ExplorerStartError", "browser_missing",
           "browser_test_server", "free_port"]

#: The browser the tests and benchmarks drive the served page with: Debian's Chromium
#: (installed by tests/run.sh; Playwright's own download does not work everywhere).
CHROMIUM = "/usr/bin/chromium"
#: Its flags: headless, no sandbox (containers), nothing fetched from the network.
CHROMIUM_ARGS = ("--headless=new", "--no-sandbox", "--disable-gpu",
                 "--disable-background-networking", "--disable-component-update",
                 "--no-first-run", "--disable-sync")

# The directory holding the `explorer` and `core` packages (the repository root in a
# checkout): the child must import the same code as its parent, wherever it was started.
_PACKAGE_PARENT = Path(__file__).resolve().parents[2]

# Lines of the server's output quoted when it fails to start: enough for a traceback.
_TAIL_LINES = 60


def browser_missing() -> str | None:
    """Why the served page cannot be driven in a browser here (Chromium or Playwright
    absent, and how to install them), or None when both are present."""
    import importlib.util

    if not os.path.exists(CHROMIUM):
        return (f"Debian's chromium is not at {CHROMIUM}: `bash tests/run.sh` installs it with "
                "apt-get (on a system without apt-get, install Chromium there)")
    if importlib.util.find_spec("playwright") is None:
        return "playwright is not installed: `bash tests/run.sh` installs it"
    return None


def rss_mib(pid: int) -> float:
    """Resident memory of process ``pid`` [MiB], from /proc."""
    with open(f"/proc/{pid}/status", encoding="ascii") as fh:
        for line in fh:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    raise AssertionError(f"no VmRSS for process {pid}")


def free_port(host: str = "127.0.0.1") -> int:
    """A TCP port on ``host`` that nothing listens on at the time of the call.

    The port is released before it is returned, so another process may take it before
    the server binds it; on a test machine that is rare enough to accept.
    """
    with socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET) as s:
        s.bind((host, 0))
        return s.getsockname()[1]


class ExplorerStartError(RuntimeError):
    """The server exited, or did not answer in time; the message quotes its output."""


class ExplorerProcess:
    """``python -m explorer`` in a child process, on a free port of a loopback address.

    Nothing runs until :meth:`start` (or ``with``), which returns once ``/liveness``
    answers; :meth:`stop` (or the end of the ``with`` block) ends the server.

    Parameters
    ----------
    args:
        Further command-line arguments of ``python -m explorer``, e.g.
        ``["--solver-threads", "2"]`` or ``["--warm-up", "none"]``. ``--port`` and
        ``--address`` are set from ``port`` and ``host``; do not repeat them here.
    host:
        Address the server listens on and :attr:`url` names. Bokeh accepts websockets
        from ``localhost:PORT`` only by default, so for any other host the server is also
        told ``--allow-websocket-origin HOST:PORT`` (clients reach it under that name).
    port:
        Port to listen on; ``None`` (default) picks a free one with :func:`free_port`.
    env:
        Environment variables for the child, set on top of this process's environment
        (e.g. ``{"OPENBLAS_NUM_THREADS": "1"}``). ``PYTHONPATH`` is always prefixed with
        the directory holding the ``explorer`` package.
    log:
        File receiving the server's stdout and stderr (truncated at start, kept after
        stop). ``None`` (default): a temporary file, deleted by :meth:`stop`; its text
        remains available from :meth:`output`.
    ready_timeout:
        Seconds to wait for ``/liveness`` to answer after the start, including the
        warm-up solve of the default scene. Default 180 s.
    stop_timeout:
        Seconds :meth:`stop` waits after asking the server to terminate (SIGTERM) before
        killing it (SIGKILL). Default 10 s.
    cwd:
        Working directory of the child; ``None``: the directory holding the package.
    program:
        The program to run instead of ``python -m explorer``, e.g. an installed
        ``coated-punch-explorer`` script. It runs the code it was installed with:
        ``PYTHONPATH`` is removed from its environment, not prefixed.
    """

    def __init__(self, args: Sequence[str] = (), *, host: str = "localhost",
                 port: int | None = None, env: Mapping[str, str] | None = None,
                 log: str | os.PathLike[str] | None = None, ready_timeout: float = 180.0,
                 stop_timeout: float = 10.0, cwd: str | os.PathLike[str] | None = None,
                 program: Sequence[str] | None = None) -> None:
        self.host = host
        self.port = free_port("127.0.0.1" if host == "localhost" else host) \
            if port is None else port
        self.url = f"http://{host}:{self.port}"
        self.ready_timeout = ready_timeout
        self.stop_timeout = stop_timeout
        self._installed = program is not None
        # --exit-with-parent: a test run killed with no time to clean up (SIGTERM to
        # pytest, a CI timeout) takes its servers with it
        self.command = [*(program or (sys.executable, "-m", "explorer")), "--port",
                        str(self.port), "--exit-with-parent"]
        if host != "localhost":
            self.command += ["--address", host,
                             "--allow-websocket-origin", f"{host}:{self.port}"]
        self.command += list(args)
        self._env = dict(env or {})
        self._cwd = Path(cwd) if cwd is not None else _PACKAGE_PARENT
        self._own_log = log is None
        self.log_path: Path | None = None if log is None else Path(log)
        self._final_output: str | None = None
        self.proc: subprocess.Popen[bytes] | None = None

    @property
    def pid(self) -> int:
        """Process id of the server (valid once started)."""
        if self.proc is None:
            raise RuntimeError("the explorer server has not been started")
        return self.proc.pid

    def start(self) -> ExplorerProcess:
        """Start the server and wait until it answers; return ``self``.

        Raises :class:`ExplorerStartError` (the server stopped, the output's last lines
        quoted) if it exits first or does not answer within ``ready_timeout`` seconds.
        """
        if self.proc is not None:
            raise RuntimeError("the explorer server has already been started")
        env = dict(os.environ)
        env.update(self._env)
        if self._installed:
            env.pop("PYTHONPATH", None)
        else:
            env["PYTHONPATH"] = os.pathsep.join(
                filter(None, [str(_PACKAGE_PARENT), env.get("PYTHONPATH")]))
        if self.log_path is None:
            fd, name = tempfile.mkstemp(prefix="explorer-server-", suffix=".log")
            self.log_path = Path(name)
            out = os.fdopen(fd, "wb")
        else:
            out = self.log_path.open("wb")
        # The child holds its own descriptor; ours is closed at once. The log is read back
        # through its path, never through a shared descriptor whose offset the child moves.
        try:
            with out:
                self.proc = subprocess.Popen(self.command, cwd=self._cwd, env=env,
                                             stdout=out, stderr=subprocess.STDOUT)
        except OSError:
            if self._own_log:
                self.log_path.unlink()
            raise
        try:
            self._wait_ready()
        except BaseException:
            self.stop()
            raise
        return self

    def _wait_ready(self) -> None:
        assert self.proc is not None
        # A proxy from the environment (http_proxy) must not be asked for a loopback URL.
        opener = urllib.request.build_opener(urllib.request.ProxyHandler({}))
        liveness = self.url + "/liveness"
        deadline = time.monotonic() + self.ready_timeout
        while True:
            code = self.proc.poll()
            if code is not None:
                raise ExplorerStartError(self._failure(
                    f"the explorer server exited with code {code} before answering at "
                    f"{liveness}"))
            try:
                with opener.open(liveness, timeout=2) as response:
                    if response.status == 200:
                        return
            except OSError:
                pass  # not listening yet
            if time.monotonic() > deadline:
                raise ExplorerStartError(self._failure(
                    f"the explorer server did not answer at {liveness} within "
                    f"{self.ready_timeout:g} s"))
            time.sleep(0.5)

    def _failure(self, message: str) -> str:
        lines = self.output().splitlines()
        if not lines:
            return message + " (it wrote nothing)"
        where = "" if self._own_log else f" (all of it in {self.log_path})"
        shown = "last lines" if len(lines) > _TAIL_LINES else "all"
        return (f"{message}; {shown} of its output{where}:\n"
                + "\n".join(lines[-_TAIL_LINES:]))

    def output(self) -> str:
        """All the server has written to stdout and stderr so far (also after stop)."""
        if self._final_output is not None:
            return self._final_output
        if self.log_path is None:
            return ""
        try:
            return self.log_path.read_text(errors="replace")
        except FileNotFoundError:
            return ""

    def stop(self) -> int | None:
        """End the server: SIGTERM, then SIGKILL after ``stop_timeout`` seconds.

        Safe to call more than once, and on a server that has already exited. Returns its
        exit code (``None`` if it was never started).
        """
        if self.proc is None:
            return None
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=self.stop_timeout)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        if self._own_log and self._final_output is None and self.log_path is not None:
            self._final_output = self.output()
            with contextlib.suppress(OSError):
                self.log_path.unlink()
        return self.proc.returncode

    def __enter__(self) -> ExplorerProcess:
        return self.start()

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.stop()


def browser_test_server(args: Sequence[str] = ()) -> ExplorerProcess:
    """The served explorer the browser tests drive (default options but ``args``, one BLAS
    thread), not started yet: use it as a context manager."""
    # 180 s: the server solves the default scene once before it answers
    return ExplorerProcess(args, env={"OPENBLAS_NUM_THREADS": "1"}, ready_timeout=180)
