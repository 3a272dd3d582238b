#!/usr/bin/env bash
# Installs everything the test suite needs, then runs the whole suite.
# Usage (from the repository root):  bash tests/run.sh [pytest args]
# Without arguments: the whole suite, browser tests and the rest side by side (below).
set -euo pipefail
cd "$(dirname "$0")/.."

python -m pip install --quiet --disable-pip-version-check -e ".[test]"

# The browser tests drive Debian's Chromium (a browser download by the test tool
# itself does not work on these machines).
if [ ! -x /usr/bin/chromium ]; then
    if command -v apt-get >/dev/null 2>&1; then
        SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
        $SUDO apt-get update -qq
        DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq chromium >/dev/null
    fi
fi

# The set-up above installs Chromium and Playwright: under CI a missing browser fails the
# run (tests/browser_pages.py: require_browser) instead of skipping the browser tests.
export CI="${CI:-1}"

# Small dense matrices: BLAS threads only fight each other on 2 cores (10x slower measured).
export OPENBLAS_NUM_THREADS="${OPENBLAS_NUM_THREADS:-1}"

python -m ruff check core explorer tests benchmarks

# With arguments (a file, -k ...): one pytest run of what they select.
if [ "$#" -gt 0 ]; then
    exec python -m pytest -q "$@"
fi

# The whole suite in two streams at once: the browser tests (-m browser) mostly wait for
# the served explorer and Chromium, the others mostly compute; one after the other they
# kept the machine's cores ~60 % busy (tests share nothing on disk; every server takes a
# free port). The browser stream's report follows the other's.
browser_log="$(mktemp "${TMPDIR:-/tmp}/browser-tests.XXXXXX")"
trap 'rm -f "$browser_log"' EXIT
python -m pytest -q -m browser -p no:cacheprovider >"$browser_log" 2>&1 &
browser_pid=$!
status=0
python -m pytest -q -m "not browser" -p no:cacheprovider || status=$?
browser_status=0
wait "$browser_pid" || browser_status=$?
echo "---- browser tests (-m browser) ----"
cat "$browser_log"
[ "$status" -eq 0 ] && [ "$browser_status" -eq 0 ]
