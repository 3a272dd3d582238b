#!/usr/bin/env bash
# Installs everything the test suite needs, then runs the whole suite and builds the
# documentation.
# Usage (from the repository root):  bash tests/run.sh [pytest args]
# Without arguments the whole suite runs in three parts at once and the documentation is
# built beside them (see below); with arguments one pytest run gets them (e.g.
# bash tests/run.sh tests/scene/test_scene.py -x) and the documentation is not built.
# SKIP_SETUP=1 skips the installation (an environment already set up).
#
# This script runs every test. For a quick loop while working, the unit tests alone (the
# markers, described in pyproject.toml, set apart what needs a browser, long-running
# servers and processes, or seconds per check), from the repository root:
#     OPENBLAS_NUM_THREADS=1 python -m pytest -m "not browser and not soak and not slow"
set -euo pipefail
cd "$(dirname "$0")/.."

if [ "${SKIP_SETUP:-0}" != "1" ]; then
    python -m pip install --quiet --disable-pip-version-check -e ".[test,docs]"

    # The browser tests drive Debian's Chromium (a browser download by the test tool
    # itself does not work on these machines).
    if [ ! -x /usr/bin/chromium ]; then
        if command -v apt-get >/dev/null 2>&1; then
            SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
            $SUDO apt-get update -qq
            DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq chromium >/dev/null
        fi
    fi
fi

# The set-up above installs Chromium and Playwright: under CI a missing browser fails the
# run (tests/browser_pages.py: require_browser) instead of skipping the browser tests.
export CI="${CI:-1}"

# Small dense matrices: BLAS threads only fight each other on 2 cores (10x slower measured).
export OPENBLAS_NUM_THREADS="${OPENBLAS_NUM_THREADS:-1}"

python -m ruff check core explorer tests benchmarks docs
# The import contracts of pyproject.toml (through python: a new console script may not be
# on PATH until a shell rehashes).
python -c 'import sys; from importlinter.cli import lint_imports_command; sys.exit(lint_imports_command())'

if [ "$#" -gt 0 ]; then
    exec python -m pytest -q "$@"
fi

# The whole suite in three parts at once, one pytest each: the browser tests (marker
# "browser": a served explorer and Chromium), the soak tests (marker "soak": servers and
# worker processes started, stopped, killed and left idle, much of it waiting on them)
# with the checks of seconds each (marker "slow"), and the rest. One pytest keeps at most one core busy, and the soak part waits much of its
# time; when one part ends first the others still have both cores. Measured on a fresh
# clone, 2 cores with nothing else running (2026-11-30): 19.8-21.4 min with the
# installation (rest 18.5-19.9, browser 16.0-17.6, soak 7.5-8.8 min, documentation
# 4.5-5.3 min) at load average ~4: the whole is bound by the cores' time (the rest alone:
# 12.6 min; the rest in two halves took as long, the browser part then the longest).
# Two pytest-xdist workers each for the rest and the browser tests (2026-12-01) took more
# of the cores' time, 1677 s against ~1390 (each worker imports and warms its own caches,
# each browser worker serves its own explorer), with the load at ~9; and one Chromium per
# pytest instead of one per module saved nothing measurable (5 modules: 58.3 against
# 58.8 s of CPU). The checks of seconds each (marker "slow", 75 tests with the soak ones)
# run in the soak part instead (2026-12-01) balanced the parts (rest 25.4, browser 24.5,
# soak 23.9 min) but not the whole: 26.1 min on a fresh clone, 2107 s user + 110 s system
# CPU, against 23.6 min (1773 s + 86 s) for the split above on the same day. Beside a CPU
# hog (two busy-loop processes, load 5-8; 2026-12-01, a fresh clone): 51.3 min, all
# green (rest 50.2, browser 35.2, soak 15.4 min, documentation 580 s), 2216 s user +
# 107 s system CPU of the suite.
# On a fresh clone, 2 cores, quiet (2026-12-02): 20.1 min, 1481 s user + 70 s system
# (rest 19.6, browser 16.1, soak 7.1 min, documentation 275 s), after the FE check's
# ordering, warm solver workers and the PDF report's own plots cut their CPU. Where the
# rest's CPU went before them (py-spy, 50 Hz, its subprocesses included): the solver
# 34 % (creep lift-off marches 17 %), imports 13 %, explorer sessions built in-process
# 9 %, fits 7 %, FE checks 7 %, PDF reports 3 %.
# On a faster machine (AMD EPYC, 2 cores; 2026-12-02), fresh clones: quiet 6.8-10.1 min,
# 544-809 s of CPU (the machine's speed moves by a third from hour to hour); beside one
# busy loop (mean load average 4.2-4.8) 9.7-11.5 min, 601-720 s of CPU (rest 9.4-11.1,
# browser 8.9-10.3, soak 4.0-4.8 min); beside two (load 5-7.7) 15.5 min: all green. Other
# splits beside one busy loop took as long: six parts (the rest and the browser tests in
# two each) 11.4 min, the "slow" checks in the soak part 10.2 min (load 5.4). The cores'
# time is the bound: a shorter run needs less CPU, not other parts. On a fresh clone, quiet
# (2026-12-04): 11:10 (rest 10:37, browser 9:00, soak 5:00; 796 s user CPU, 127 % of a
# core); the rest in two halves by directory (tests/explorer and tests/engines, ~230 s of
# one core each, beside the others) 11:12, the browser part then the longest (10:39).
# Beside a CPU hog on the faster machine (AMD EPYC, 2026-12-04, fresh clones, five runs in
# a row, all green): two busy loops (load 3.4-7) 11:09; one busy loop (load ~4-6) 8:20,
# 8:02, 8:03 and 7:48, the rest part 7:31-8:03 of each.
# On a fresh clone, quiet (2026-12-06, one after the other): the "slow" checks (67 of them then,
# ~130 s of one core) in the soak part instead of the rest's, 10:21 (rest 10:05, browser
# 9:00, soak and slow 8:47, documentation 148 s; 824 s user CPU, 141 % of a core) against
# 12:08 as above (rest 11:50, browser 8:25, soak 3:50; 853 s, 123 %): the soak part waits
# much of its time, and the rest ran alone on one core for its last 3.5 minutes.
# The parts share nothing: each has its own temporary directory, pytest cache and served
# explorers (a free port each).
work="$(mktemp -d -t coated-punch-suite.XXXXXX)"
python -m pytest -q -m browser --basetemp "$work/browser" -o cache_dir=.pytest_cache/browser \
    >"$work/browser.log" 2>&1 &
browser_pid=$!
python -m pytest -q -m "(soak or slow) and not browser" --basetemp "$work/soak" \
    -o cache_dir=.pytest_cache/soak >"$work/soak.log" 2>&1 &
soak_pid=$!

# The documentation (docs/, Sphinx): built here so that it cannot rot. Warnings are errors
# (-W), so a renamed API, a broken docstring, a moved report or link, or a gallery example
# that no longer runs fails the run. Always from an empty build directory: an incremental
# build would not repeat the warnings of pages it skips. It runs beside the three parts
# (~35-110 s of one core, with the machine's speed; measured in docs/conf.py's docstring). The pages stay in
# DOCS_BUILD_DIR (default ${TMPDIR:-/tmp}/coated-punch-docs, outside the source tree):
# open index.html there.
docs_dir="${DOCS_BUILD_DIR:-${TMPDIR:-/tmp}/coated-punch-docs}"
build_docs() {
    local start=$SECONDS
    # only a former build is removed (Sphinx leaves .buildinfo in it, or only .doctrees
    # when the build was interrupted)
    if [ -e "$docs_dir" ] && [ ! -f "$docs_dir/.buildinfo" ] && [ ! -d "$docs_dir/.doctrees" ]; then
        echo "DOCS_BUILD_DIR=$docs_dir exists and is not a Sphinx build: not removing it"
        return 1
    fi
    rm -rf "$docs_dir"
    python -m sphinx -W --keep-going -q -b html docs "$docs_dir" &&
        echo "built in $((SECONDS - start)) s: $docs_dir/index.html"
}
build_docs >"$work/docs.log" 2>&1 &
docs_pid=$!
# (kill fails once a job has ended: no status of its own may reach the exit code)
trap 'kill "$browser_pid" "$soak_pid" "$docs_pid" 2>/dev/null || true; rm -rf "$work"' EXIT
set +e
python -m pytest -q -m "not browser and not soak and not slow" --basetemp "$work/rest" \
    -o cache_dir=.pytest_cache/rest
rest=$?
wait "$browser_pid"
browser=$?
wait "$soak_pid"
soak=$?
wait "$docs_pid"
docs=$?
set -e
echo "---- documentation (sphinx -W) ----"
cat "$work/docs.log"
echo "---- browser tests (pytest -m browser) ----"
cat "$work/browser.log"
echo "---- soak and slow tests (pytest -m \"(soak or slow) and not browser\") ----"
cat "$work/soak.log"
echo "---- exit codes: rest $rest, browser $browser, soak $soak, docs $docs ----"
[ "$rest" -eq 0 ] && [ "$browser" -eq 0 ] && [ "$soak" -eq 0 ] && [ "$docs" -eq 0 ]
