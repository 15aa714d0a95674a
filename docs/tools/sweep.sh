#!/usr/bin/env bash
# Regenerates the measurements of docs/measurements/modes.md (render modes side by side):
# the 2 km city's six modes side by side at 640x480 and 320x240 (car path), the
# fly-over, and the size sweep. Prints the Markdown tables on stdout.
#
# usage: docs/tools/sweep.sh [VISTA_BINARY] [OUT_DIR]
#   VISTA_BINARY defaults to build/vista, OUT_DIR to ./results-modes.
# Needs an X display; without one it re-runs itself under `xvfb-run -a`.
# Needs jq. Takes about 20 minutes on 2 cores with llvmpipe.
set -euo pipefail
VISTA=$(realpath "${1:-build/vista}")
OUT=${2:-results-modes}
MODES=full,near,raycast,osgimpostor,osglod,hybrid
if [ -z "${DISPLAY:-}" ]; then exec xvfb-run -a "$0" "$VISTA" "$OUT"; fi
mkdir -p "$OUT" && cd "$OUT"

"$VISTA" gen --size 2000 --seed 1 -q -o city.osgb
"$VISTA" path city.osgb --seed 1 -o car1.csv
"$VISTA" path city.osgb --seed 1 --kind fly -o fly1.csv
"$VISTA" bench city.osgb --path car1.csv --frames 60 --size 640x480 --modes $MODES --out bench640 -q
"$VISTA" bench city.osgb --path car1.csv --frames 60 --size 320x240 --modes $MODES --out bench320 -q
"$VISTA" bench city.osgb --path fly1.csv --frames 40 --size 640x480 --modes $MODES --out benchfly640 -q
"$VISTA" bench --sweep sizes=500,1000,2000,4000 --seed 1 --frames 30 --size 320x240 --modes full,near,raycast,hybrid --out sweep -q > /dev/null

table() {  # $1 = bench directory
    echo "Command: \`$(jq -r .command "$1/summary.json")\`"
    echo
    echo "| mode | median frame (ms) | p95 frame (ms) | speedup vs full (median of same-frame ratios) | PSNR vs full, median (dB) | PSNR min (dB) | triangles (median) |"
    echo "|---|---|---|---|---|---|---|"
    jq -r '.mode_order[] as $m | .modes[$m] | "| \($m) | \(.frame_ms_median*10|round/10) | \(.frame_ms_p95*10|round/10) | \(.speedup_vs_full_median_of_ratios*100|round/100) | \(.psnr_db_median*10|round/10) | \(.psnr_db_min*10|round/10) | \(.triangles_median|round) |"' "$1/summary.json"
    echo
}
echo "### 640x480, car path"; echo; table bench640
echo "### 320x240, car path"; echo; table bench320
echo "### 640x480, fly-over path"; echo; table benchfly640
echo "### Size sweep (320x240, 30 frames; full, near, raycast, hybrid)"; echo
echo "Command: \`$(jq -r .command sweep/sweep.json)\`"; echo
cat sweep/sweep.md
