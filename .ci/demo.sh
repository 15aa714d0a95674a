#!/usr/bin/env bash
# The main job on the built-in default city: set up, generate, walk through headless.
# Prints the generation figures and the per-mode frame times; writes out/demo/ (scene, stats, PNGs).
set -euo pipefail
cd "$(dirname "$0")/.."
./.ci/setup.sh
BUILD="${VISTA_BUILD_DIR:-build}"
VISTA="$BUILD/vista"
OUT=out/demo
mkdir -p "$OUT"
"$VISTA" gen --params data/default.json --stats "$OUT/city.stats.json" -o "$OUT/city.osgb"
run() { if [ -z "${DISPLAY:-}" ]; then xvfb-run -a -s "-screen 0 1280x1024x24" "$@"; else "$@"; fi; }
run "$VISTA" bench "$OUT/city.osgb" --seed 1 --frames 40 --size 640x480 --modes full,near,raycast,hybrid --out "$OUT/bench"
echo "pictures: $OUT/bench/*.png   figures: $OUT/bench/summary.json   city: $OUT/city.osgb"
