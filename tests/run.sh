#!/usr/bin/env bash
# Installs everything the test suite needs, then runs the whole suite.
# Usage (from the repository root):  bash tests/run.sh [extra pytest args]
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
python -m pytest -q "$@"
