"""The command line ``python -m core`` as the tests run it: in the test's own process
(``core.cli.main``, its output captured), or for the entry point itself in a child."""

from __future__ import annotations

import contextlib
import io
import os
import subprocess as child_process
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def run_cli(*args: str | os.PathLike, cwd: str | os.PathLike | None = None,
            subprocess: bool = False, timeout: float = 300.0,
            stdin: str | bytes = b"") -> child_process.CompletedProcess:
    """``python -m core ARGS`` run in ``cwd`` (default: the repository root), ``stdin`` on
    its standard input: its exit code and the text it wrote to stdout and stderr.

    By default ``core.cli.main`` runs in this process, its output captured; with
    ``subprocess=True`` a child process runs the real entry point (one BLAS thread;
    ``timeout`` [s] bounds it).
    """
    argv = [str(a) for a in args]
    where = Path(cwd) if cwd is not None else ROOT
    data = stdin.encode("utf-8") if isinstance(stdin, str) else stdin
    if subprocess:
        env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
        env["PYTHONPATH"] = str(ROOT) + os.pathsep + env.get("PYTHONPATH", "")
        done = child_process.run([sys.executable, "-m", "core", *argv], cwd=where, env=env,
                                 capture_output=True, input=data, timeout=timeout)
        return child_process.CompletedProcess(done.args, done.returncode,
                                              done.stdout.decode("utf-8"),
                                              done.stderr.decode("utf-8"))
    from core.cli import main

    out, err = io.StringIO(), io.StringIO()
    here, given = Path.cwd(), sys.stdin
    try:
        os.chdir(where)
        sys.stdin = io.TextIOWrapper(io.BytesIO(data), encoding="utf-8")
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code = main(argv)
            except SystemExit as exc:  # as the interpreter would end the process
                code = exc.code if isinstance(exc.code, int) else 1
    finally:
        os.chdir(here)
        sys.stdin = given
    return child_process.CompletedProcess(["python", "-m", "core", *argv], code,
                                          out.getvalue(), err.getvalue())
