"""Benchmarks of the coated-punch solvers and the explorer (speed against error), each
writing its report under ``benchmarks/results/`` with the commit, the date and the load.

:func:`tree_commit` and :func:`run_lines` are what the reports say of how they were made.
"""

from __future__ import annotations

import os
import platform
import subprocess
import sys
from collections.abc import Sequence
from datetime import datetime
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def tree_commit(tree: Path = ROOT) -> str:
    """The short hash of the commit of ``tree`` (default: this one), ``+`` when it has
    uncommitted changes."""
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=tree,
                          capture_output=True, text=True).stdout.strip() or "unknown"
    dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"],
                           cwd=tree, capture_output=True, text=True).stdout.strip()
    return head + ("+" if dirty else "")


def run_lines(started: datetime, load_before: float, load_after: float,
              load_note: str = "", commit: str | None = None) -> list[str]:
    """A report's lines on its run: the commit, the date [UTC] and the machine, and the
    load average before and after (``load_note``: what the load means for its figures).

    ``commit``: :func:`tree_commit` taken when the run started (default: now); a long
    run takes it at its start, as the tree may move on while it runs."""
    commit = tree_commit() if commit is None else commit
    return [f"- commit {commit}, {started:%Y-%m-%d %H:%M} UTC, {platform.machine()}, "
            f"{os.cpu_count()} cores, Python {platform.python_version()}",
            f"- load average {load_before:.2f} before, {load_after:.2f} after"
            + (f" ({load_note})" if load_note else "")]


def help_requested(doc: str | None, argv: Sequence[str] | None = None) -> None:
    """Print ``doc`` (a script's docstring: what it measures and how it is run) and exit
    when ``-h`` or ``--help`` is among the arguments (default: the command line's).

    A script without its own option parser took ``--help`` for a run: it measured for
    a minute and wrote over its committed report in ``benchmarks/results/``."""
    args = sys.argv[1:] if argv is None else list(argv)
    if "-h" in args or "--help" in args:
        print((doc or "").strip())
        raise SystemExit(0)
