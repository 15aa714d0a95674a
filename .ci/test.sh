#!/usr/bin/env bash
# Runs every test (ctest); rendering tests need a display, so this runs under xvfb-run.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD="${VISTA_BUILD_DIR:-build}"
if [ -z "${DISPLAY:-}" ] && command -v xvfb-run >/dev/null; then
  exec xvfb-run -a -s "-screen 0 1280x1024x24" ctest --test-dir "$BUILD" --output-on-failure -j2 --timeout 900
fi
exec ctest --test-dir "$BUILD" --output-on-failure -j2 --timeout 900
