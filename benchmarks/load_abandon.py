"""The "abandon" mode of ``benchmarks/load_test.py``: memory across dropped sessions.

Starts ``python -m explorer`` on 127.0.0.1, drops a few sessions to load what every page
needs once, then drops ``--dropped`` more in rounds of ``--round`` (the four ways of
:mod:`benchmarks.abandon`, in equal shares). After each round it waits until the
server's resident memory (summed over the server and its solver processes) settles and
records it. A server that gave back what the dropped pages held stays flat: the report
gives the settled level after each round and its trend per 100 dropped sessions.
Bounded: the number of visits is fixed, every wait has a limit.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import tempfile
import time
from pathlib import Path

from benchmarks.abandon import WAYS, abandon_sessions
from benchmarks.serving import ExplorerProcess, ExplorerStartError

#: Visits that load what every page needs once, before the baseline is read.
WARM_UP_VISITS = 2 * len(WAYS)
#: Settled: three readings ``SETTLE_PERIOD`` s apart agree within this many MiB.
SETTLE_MIB = 2.0
SETTLE_PERIOD = 1.0
#: Longest wait for the memory to settle after a round [s].
SETTLE_LIMIT = 90.0


def tree_rss_mib(pid: int) -> float:
    """Resident memory of process ``pid`` and its descendants [MiB]."""
    from benchmarks.load_test import process_tree, rss_bytes

    return sum(r for r in (rss_bytes(p) for p in process_tree(pid)) if r is not None) / 2**20


def settled_rss_mib(pid: int) -> tuple[float, float]:
    """The memory once the dropped sessions are discarded: (level [MiB], wait [s])."""
    start = time.monotonic()
    readings = [tree_rss_mib(pid)]
    while time.monotonic() - start < SETTLE_LIMIT:
        time.sleep(SETTLE_PERIOD)
        readings.append(tree_rss_mib(pid))
        recent = readings[-3:]
        if len(recent) == 3 and max(recent) - min(recent) < SETTLE_MIB:
            break
    return readings[-1], time.monotonic() - start


def trend_per_100(dropped: list[int], level: list[float]) -> float:
    """Least-squares slope of the settled level against the sessions dropped [MiB/100]."""
    if len(dropped) < 2:
        return float("nan")
    md, ml = statistics.fmean(dropped), statistics.fmean(level)
    den = sum((d - md) ** 2 for d in dropped)
    return 100 * sum((d - md) * (v - ml) for d, v in zip(dropped, level, strict=True)) / den


def run_abandon(args: argparse.Namespace, command: str) -> tuple[str, bool]:
    """Run the abandon mode; return the Markdown report and whether it met its goals."""
    from benchmarks.load_test import HOST, server_options, server_tracebacks

    options = server_options(args).split() + ["--session-linger", f"{args.session_linger:g}"]
    rows: list[tuple[int, dict[str, int], float, float, float]] = []
    with tempfile.TemporaryDirectory(prefix="load-abandon-") as tmp:
        log_path = Path(tmp) / "server.log"
        server = ExplorerProcess(
            args=options, host=HOST, log=log_path, ready_timeout=300, stop_timeout=20,
            env={"OPENBLAS_NUM_THREADS": os.environ.get("OPENBLAS_NUM_THREADS", "1")})
        try:
            url = server.start().url
        except ExplorerStartError as err:
            raise SystemExit(str(err)) from None
        try:
            started = tree_rss_mib(server.pid)
            warm = abandon_sessions(url, WARM_UP_VISITS, seed=1, at_once=args.at_once)
            baseline, _ = settled_rss_mib(server.pid)
            dropped = 0
            seed = 2
            while dropped < args.dropped:
                count = min(args.round, args.dropped - dropped)
                visits = abandon_sessions(url, count, seed=seed, at_once=args.at_once)
                peak = tree_rss_mib(server.pid)
                level, waited = settled_rss_mib(server.pid)
                dropped += count
                seed += 1
                rows.append((dropped, visits, peak, level, waited))
        finally:
            server.stop()
        log_errors = server_tracebacks(log_path)
    failed = sum(n for (_, visits, *_rest) in rows for way, n in visits.items()
                 if way not in WAYS) + sum(n for way, n in warm.items() if way not in WAYS)
    levels = [r[3] for r in rows]
    # the first round still fills the result cache and the allocator's pools
    trend = trend_per_100([r[0] for r in rows[1:]], levels[1:])
    growth = levels[-1] - baseline
    ok = not failed and not log_errors and trend < args.trend_goal
    lines = [
        f"## Abandon: {args.dropped} dropped sessions, rounds of {args.round}",
        "",
        "Command (from the repository root):",
        "",
        f"    {command}",
        "",
        f"Machine: {os.cpu_count()} cores ({platform.machine()}), Python "
        f"{platform.python_version()}; server and clients share it (timings noisy). Server: "
        f"`python -m explorer --address {HOST} {' '.join(options)}` (loopback only).",
        "",
        f"Visits: {WARM_UP_VISITS} to warm up, then {args.dropped} in rounds of "
        f"{args.round}, {args.at_once} at a time, each dropped by a connection reset at one "
        f"of four points of its start ({', '.join(WAYS)}: benchmarks/abandon.py). After "
        f"each round the memory (RSS of the server with its solver processes) is read once "
        f"three readings {SETTLE_PERIOD:g} s apart agree within {SETTLE_MIB:g} MiB.",
        "",
        f"- Failed visits: **{failed}**; tracebacks in the server log: "
        f"**{len(log_errors)}** (goal 0 each).",
        f"- Memory: {started:.0f} MiB at start, {baseline:.0f} MiB after the warm-up, "
        f"{levels[-1]:.0f} MiB after all {args.dropped} ({growth:+.0f} MiB); trend after "
        f"the first round **{trend:+.1f} MiB per 100 dropped sessions** (goal "
        f"< {args.trend_goal:g}: flat).",
        "",
        "| dropped | visits (ways) | RSS just after [MiB] | settled [MiB] | settled after [s] |",
        "| --- | --- | --- | --- | --- |",
        *[f"| {d} | {', '.join(f'{w} {n}' for w, n in sorted(v.items()))} | {p:.0f} | "
          f"{lv:.0f} | {w:.0f} |" for d, v, p, lv, w in rows],
    ]
    if log_errors:
        lines += ["", "Server log tracebacks (first 5):", ""] + [
            f"- {e[:300]!r}" for e in log_errors[:5]]
    return "\n".join(lines) + "\n", ok
