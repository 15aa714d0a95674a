#!/usr/bin/env bash
# Regenerates docs/measurements/paging.md "Generation": peak RSS, time and output
# size of `vista gen -o DIR.paged` for growing city sizes, beside the
# single-file gen where it exists (up to 16 km). Prints a Markdown table on
# stdout. Each city is deleted after it is measured (a 16 km paged city takes
# about 6 GB of disk, 32 km about 4 times that).
#
# usage: docs/tools/paged_rss_table.sh [BUILD_DIR] [OUT_DIR] [SIZES] [SINGLE_SIZES] [EXTRA_GEN_ARGS]
#   BUILD_DIR defaults to build, OUT_DIR to ./results-paged, SIZES (metres,
#   comma-separated) to 4000,8000,16000,32000, SINGLE_SIZES to 4000,8000.
# Needs /usr/bin/time (GNU time) and jq. Runs under nice.
set -euo pipefail
BUILD=$(realpath "${1:-build}")
OUT=${2:-results-paged}
SIZES=${3:-4000,8000,16000,32000}
SINGLE=${4:-4000,8000}
EXTRA=${5:-}
VISTA=$BUILD/vista
mkdir -p "$OUT" && cd "$OUT"

rss_mb() { awk '/Maximum resident set size/ {printf "%.0f", $6 / 1024}' "$1"; }

echo "| side (km) | area (km²) | output | regions | buildings | triangles (M) | gen time (s) | peak RSS (MB) | bytes (GB) |"
echo "|---|---|---|---|---|---|---|---|---|"
for s in ${SIZES//,/ }; do
    km=$(awk -v s="$s" 'BEGIN { printf "%g", s / 1000 }'); area=$(awk -v s="$s" 'BEGIN { printf "%g", s * s / 1e6 }')
    if [[ ",$SINGLE," == *",$s,"* ]]; then
        nice -n 10 /usr/bin/time -v "$VISTA" gen --size "$s" -q $EXTRA -o single.osgb --stats single.json 2> single.time
        echo "| $km | $area | single file | — | $(jq .buildings single.json) | $(jq '.triangles / 1e6 * 100 | round / 100' single.json) |" \
             "$(jq '.seconds.total | round' single.json) | $(rss_mb single.time) | $(du -b single.osgb | awk '{printf "%.2f", $1 / 1e9}') |"
        rm -f single.osgb
    fi
    rm -rf city.paged
    nice -n 10 /usr/bin/time -v "$VISTA" gen --size "$s" -q $EXTRA -o city.paged --stats paged.json 2> paged.time
    echo "| $km | $area | paged | $(jq .regions paged.json) | $(jq .buildings paged.json) | $(jq '.triangles / 1e6 * 100 | round / 100' paged.json) |" \
         "$(jq '.seconds.total | round' paged.json) | $(rss_mb paged.time) | $(jq '.bytes / 1e9 * 100 | round / 100' paged.json) |"
    rm -rf city.paged
done
