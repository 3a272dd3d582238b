"""The "abandon" mode of ``benchmarks/load_test.py``: memory across dropped sessions.

Starts ``python -m explorer`` on 127.0.0.1, drops a few sessions to load what every page
needs once, then drops ``--dropped`` more in rounds of ``--round`` (the four ways of
:mod:`tests.support.abandon`, in equal shares). After each round it first waits as long as
the server needs to discard the round's sessions (the linger, one check interval of the
same length, the collection delay of :mod:`explorer.fixes.gc_policy` and a margin), then until
the memory settles, and records the server's resident memory and its solver processes'
apart: the server's own is what dropped pages could keep; the workers' grows as their
bounded stage caches fill with the scenes the "loaded" visits solved. A server that gave
back what the dropped pages held stays flat: the report gives both settled levels after
each round and their trends per 100 dropped sessions; the goal is on the server's.
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

from tests.support.abandon import WAYS, abandon_sessions, discard_wait_s
from tests.support.serving import ExplorerProcess, ExplorerStartError

#: Visits that load what every page needs once, before the baseline is read.
WARM_UP_VISITS = 2 * len(WAYS)
#: Settled: ``SETTLE_READINGS`` readings ``SETTLE_PERIOD`` s apart agree within this many
#: MiB, for the server and for its workers each.
SETTLE_MIB = 1.0
SETTLE_PERIOD = 1.0
SETTLE_READINGS = 4
#: Longest wait for the memory to settle after a round [s].
SETTLE_LIMIT = 90.0


def memory_mib(pid: int) -> tuple[float, float]:
    """Resident memory of the server ``pid`` and, summed, of its descendants (the solver
    processes) [MiB]."""
    from benchmarks.load_test import process_tree, rss_bytes

    server = rss_bytes(pid) or 0
    workers = sum(r for r in (rss_bytes(p) for p in process_tree(pid)[1:]) if r is not None)
    return server / 2**20, workers / 2**20


def settled_mib(pid: int, session_linger: float) -> tuple[float, float, float]:
    """The memory once the dropped sessions are discarded: (server [MiB], workers [MiB],
    wait [s]). Waits :func:`discard_wait_s`, then until both readings settle."""
    start = time.monotonic()
    time.sleep(discard_wait_s(session_linger))
    readings = [memory_mib(pid)]
    while time.monotonic() - start < SETTLE_LIMIT:
        time.sleep(SETTLE_PERIOD)
        readings.append(memory_mib(pid))
        recent = readings[-SETTLE_READINGS:]
        if len(recent) == SETTLE_READINGS and all(
                max(r[i] for r in recent) - min(r[i] for r in recent) < SETTLE_MIB
                for i in (0, 1)):
            break
    server, workers = readings[-1]
    return server, workers, time.monotonic() - start


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
    # (dropped, visits, server just after, server, workers, wait)
    rows: list[tuple[int, dict[str, int], float, float, float, float]] = []
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
            started = memory_mib(server.pid)
            warm = abandon_sessions(url, WARM_UP_VISITS, seed=1, at_once=args.at_once)
            base_server, base_workers, _ = settled_mib(server.pid, args.session_linger)
            dropped = 0
            seed = 2
            while dropped < args.dropped:
                count = min(args.round, args.dropped - dropped)
                visits = abandon_sessions(url, count, seed=seed, at_once=args.at_once)
                peak, _ = memory_mib(server.pid)
                level, workers, waited = settled_mib(server.pid, args.session_linger)
                dropped += count
                seed += 1
                rows.append((dropped, visits, peak, level, workers, waited))
        finally:
            server.stop()
        log_errors = server_tracebacks(log_path)
    failed = sum(n for (_, visits, *_rest) in rows for way, n in visits.items()
                 if way not in WAYS) + sum(n for way, n in warm.items() if way not in WAYS)
    levels = [r[3] for r in rows]
    worker_levels = [r[4] for r in rows]
    # the first round still fills the result cache and the allocator's pools
    counts = [r[0] for r in rows[1:]]
    trend = trend_per_100(counts, levels[1:])
    worker_trend = trend_per_100(counts, worker_levels[1:])
    ok = not failed and not log_errors and trend < args.trend_goal
    lines = [
        f"## Abandon: {args.dropped} dropped sessions, rounds of {args.round}",
        "",
        "Command (from the repository root):",
        "",
        f"    {command}",
        "",
        f"Machine: {os.cpu_count()} cores ({platform.machine()}), Python "
        f"{platform.python_version()}; server and clients share it (timings noisy); load "
        f"average at the end {' '.join(f'{v:.1f}' for v in os.getloadavg())}. Server: "
        f"`python -m explorer --address {HOST} {' '.join(options)}` (loopback only).",
        "",
        f"Visits: {WARM_UP_VISITS} to warm up, then {args.dropped} in rounds of "
        f"{args.round}, {args.at_once} at a time, each dropped by a connection reset at one "
        f"of four points of its start ({', '.join(WAYS)}: tests/support/abandon.py). After "
        f"each round the memory is read once the server has surely discarded the round's "
        f"sessions ({discard_wait_s(args.session_linger):g} s: linger, one check interval, "
        f"the two collections' delays, a margin) and {SETTLE_READINGS} readings "
        f"{SETTLE_PERIOD:g} s apart agree within {SETTLE_MIB:g} MiB; the server's resident "
        f"memory (RSS) and its solver processes' (summed) are read apart.",
        "",
        f"- Failed visits: **{failed}**; tracebacks in the server log: "
        f"**{len(log_errors)}** (goal 0 each).",
        f"- Server: {started[0]:.0f} MiB at start, {base_server:.0f} MiB after the warm-up, "
        f"{levels[-1]:.0f} MiB after all {args.dropped} ({levels[-1] - base_server:+.0f} "
        f"MiB); trend after the first round **{trend:+.1f} MiB per 100 dropped sessions** "
        f"(goal < {args.trend_goal:g}: flat).",
        f"- Solver processes: {started[1]:.0f} MiB at start, {base_workers:.0f} MiB after "
        f"the warm-up, {worker_levels[-1]:.0f} MiB after all {args.dropped}; trend after the "
        f"first round {worker_trend:+.1f} MiB per 100 (their stage caches filling with the "
        f"scenes the \"loaded\" visits solved, bounded to 512 MiB together).",
        "",
        "| dropped | visits (ways) | server just after [MiB] | server settled [MiB] | "
        "solver processes settled [MiB] | settled after [s] |",
        "| --- | --- | --- | --- | --- | --- |",
        *[f"| {d} | {', '.join(f'{w} {n}' for w, n in sorted(v.items()))} | {p:.0f} | "
          f"{lv:.0f} | {wk:.0f} | {w:.0f} |" for d, v, p, lv, wk, w in rows],
    ]
    if log_errors:
        lines += ["", "Server log tracebacks (first 5):", ""] + [
            f"- {e[:300]!r}" for e in log_errors[:5]]
    return "\n".join(lines) + "\n", ok
