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

# The whole suite in six parts at once: four pytest runs and the documentation beside the
# soak tests. A pytest run keeps at most one core busy (its served explorers and Chromium
# aside), and on a shared machine each runnable process gets its share of the cores: one
# pytest for all unit tests was the whole run's length (beside one busy loop: rest 11.1
# of 11.5 min, 2026-12-02). The parts, and what each took on a quiet 2-core machine
# (AMD EPYC, 2026-12-02, the six run together as here):
# - solver: the unit tests of core's lower layers (everything outside the five folders
#   of "front" below; ~175 s of one core alone),
# - front: the unit tests of the explorer, studies, reports, the command line, packaging
#   and the README (~195 s alone),
# - browser-a, browser-b: the browser tests (marker "browser": a served explorer and
#   Chromium each; ~200 s each alone, half of it waiting on the page),
# - soak (marker "soak"): servers and worker processes started, stopped, killed and left
#   idle (~250 s, much of it waiting on them),
# - the documentation (~70 s of CPU).
# Each part has its own temporary directory, pytest cache and served explorers (a free
# port each); the parts of one marker are split by paths with --ignore, so that a new test
# file runs in one of them. History of the split: CHANGELOG.md.
work="$(mktemp -d -t coated-punch-suite.XXXXXX)"
names=()
pids=()
# part NAME PYTEST-ARGS...: one pytest in the background, its output in $work/NAME.log
part() {
    local name=$1
    shift
    python -m pytest -q --basetemp "$work/$name" -o cache_dir=".pytest_cache/$name" "$@" \
        >"$work/$name.log" 2>&1 &
    names+=("$name")
    pids+=($!)
}
front=(tests/explorer tests/study tests/report tests/cli tests/packaging tests/test_readme.py)
browser_a=(tests/explorer/test_explorer_browser_checks.py tests/explorer/test_explorer_browser.py
           tests/explorer/test_explorer_browser_classroom.py
           tests/explorer/test_explorer_browser_fit.py)
part solver -m "not browser and not soak" tests "${front[@]/#/--ignore=}"
part front -m "not browser and not soak" "${front[@]}"
part browser-a -m browser "${browser_a[@]}"
part browser-b -m browser tests "${browser_a[@]/#/--ignore=}"
part soak -m "soak and not browser" tests

# The documentation (docs/, Sphinx): built here so that it cannot rot. Warnings are errors
# (-W), so a renamed API, a broken docstring, a moved report or link, or a gallery example
# that no longer runs fails the run. Always from an empty build directory: an incremental
# build would not repeat the warnings of pages it skips. The pages stay in DOCS_BUILD_DIR
# (default ${TMPDIR:-/tmp}/coated-punch-docs, outside the source tree): open index.html
# there.
docs_dir="${DOCS_BUILD_DIR:-${TMPDIR:-/tmp}/coated-punch-docs}"
build_docs() {
    local start=$SECONDS
    # only a former build is removed (Sphinx leaves .buildinfo in it)
    if [ -e "$docs_dir" ] && [ ! -f "$docs_dir/.buildinfo" ]; then
        echo "DOCS_BUILD_DIR=$docs_dir exists and is not a Sphinx build: not removing it"
        return 1
    fi
    rm -rf "$docs_dir"
    python -m sphinx -W --keep-going -q -b html docs "$docs_dir" &&
        echo "built in $((SECONDS - start)) s: $docs_dir/index.html"
}
build_docs >"$work/docs.log" 2>&1 &
names+=(docs)
pids+=($!)
# (kill fails once a job has ended: no status of its own may reach the exit code)
trap 'kill "${pids[@]}" 2>/dev/null || true; rm -rf "$work"' EXIT
set +e
codes=""
failed=0
for i in "${!pids[@]}"; do
    wait "${pids[$i]}"
    code=$?
    [ "$code" -eq 0 ] || failed=1
    codes+="${codes:+, }${names[$i]} $code"
    echo "---- ${names[$i]} ----"
    cat "$work/${names[$i]}.log"
done
set -e
echo "---- exit codes: $codes ----"
[ "$failed" -eq 0 ]
