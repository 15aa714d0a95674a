#!/usr/bin/env bash
# Regenerates every measured page of docs/measurements/ (and the CLI reference)
# by running each page's own script in turn. Resumable: a step whose outputs
# exist (OUT/STEP.done) is skipped, and most scripts keep their finished work in
# OUT/STEP/, so after a kill the same command goes on where it stopped. Scripts
# that print their tables instead of writing the page leave them in
# OUT/STEP.md for pasting. Delete OUT/STEP.done to run a step again.
#
# usage: docs/tools/regenerate_all.sh OUT [BUILD_DIR] [STEP...]
#   OUT        working directory (cities, benches, bakes; tens of GB)
#   BUILD_DIR  the build with vista, vista_bake_report and the benchmarks
#              (tests/bench: image_psnr, far_field_sweep, bench_raw_rays, soak;
#              -DVISTA_BUILD_BENCHMARKS=ON); default build
#   STEP...    only these steps (names as listed by --list)
#   --list     print the steps and exit
# Takes many hours on 2 cores (the reliability step alone about 2 hours, the
# whole-city bakes and the paged cities about an hour each) and keeps both
# cores busy: run it on a machine with nothing else to measure.
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
cd "$REPO"

# step name | page it regenerates | command (run from the repository root; $OUT and $BUILD set)
STEPS=(
  "cli|docs/reference/cli.md|python3 docs/tools/cli_reference.py \$BUILD/vista > docs/reference/.cli.md.tmp && mv docs/reference/.cli.md.tmp docs/reference/cli.md"
  "far-field|docs/measurements/far-field.md|docs/tools/far_field_table.sh \$OUT/far-field \$BUILD/vista"
  "farfield-compare|docs/measurements/farfield-compare.md|docs/tools/farfield_compare.sh \$OUT/farfield-compare \$BUILD/vista"
  "modes|docs/measurements/modes.md (tables in OUT/modes.md)|docs/tools/sweep.sh \$BUILD/vista \$OUT/modes > \$OUT/modes.md"
  "effects|docs/measurements/effects.md|docs/tools/effects.sh \$OUT/effects \$BUILD/vista"
  "whole-bake|docs/measurements/bake.md|docs/tools/whole_bake.sh \$OUT/whole-bake \$BUILD/vista"
  "whole-bake-seed2|docs/measurements/bake.md|CITY_SEED=2 MARKER=whole-bake-seed2 docs/tools/whole_bake.sh \$OUT/whole-bake-seed2 \$BUILD/vista"
  "splat|docs/measurements/bake.md|docs/tools/splat_table.sh \$OUT/splat \$BUILD/vista"
  "splat-seed2|docs/measurements/bake.md|SIZE_M=2000 CITY_SEED=2 CELLS='3 20 500 940' SIGMAS='0.25' FRAMES=3 MARKER=splat-table-seed2 docs/tools/splat_table.sh \$OUT/splat-seed2 \$BUILD/vista"
  "bake-table|docs/measurements/bake.md (tables in OUT/bake-table.md)|docs/tools/bake_results.sh \$BUILD \$OUT/bake-table > \$OUT/bake-table.md"
  "generation|docs/measurements/generation.md (table in OUT/generation.md)|VISTA=\$BUILD/vista docs/tools/perf_table.sh 500 1000 2000 4000 8000 > \$OUT/generation.md"
  "paged-generation|docs/measurements/paging.md (table in OUT/paged-generation.md)|docs/tools/paged_rss_table.sh \$BUILD \$OUT/paged-generation 4000,8000,16000,32000 4000,8000 > \$OUT/paged-generation.md"
  "scale|docs/measurements/paging.md|docs/tools/scale_table.sh \$OUT/scale \$BUILD/vista"
  "stream|docs/measurements/paging.md|docs/tools/stream_table.sh \$OUT/stream \$BUILD/vista"
  "paged-reach|docs/measurements/paging.md|docs/tools/paged_reach_table.sh \$OUT/scale/c8000.paged \$OUT/paged-reach \$BUILD"
  "raw-rays|docs/measurements/raw-rays.md|docs/tools/raw_rays.sh \$OUT/raw-rays \$BUILD/vista"
  "opendrive|docs/formats.md \"OpenDRIVE\" (table in OUT/opendrive.md)|docs/tools/opendrive_table.sh \$OUT/opendrive-work \$BUILD/vista > \$OUT/opendrive.md"
  "traffic|docs/measurements/traffic.md|docs/tools/traffic_table.sh \$OUT/traffic \$BUILD/vista"
  "ground-truth|docs/measurements/ground-truth.md (costs in OUT/ground-truth.txt)|mkdir -p \$OUT/ground-truth && \$BUILD/vista gen --params data/default.json -o \$OUT/ground-truth/c.osgb -q && \$BUILD/vista path \$OUT/ground-truth/c.osgb --seed 3 -o \$OUT/ground-truth/p.csv && for m in full hybrid; do rm -rf \$OUT/ground-truth/gt_\$m; xvfb-run -a -s '-screen 0 1280x1024x24' \$BUILD/vista render \$OUT/ground-truth/c.osgb --path \$OUT/ground-truth/p.csv --frames 60 --mode \$m --out \$OUT/ground-truth/gt_\$m --stats -q; done > \$OUT/ground-truth.txt 2>&1"
  "reliability|docs/measurements/reliability.md|docs/tools/reliability.sh 3600 100000"
)

if [ "${1:-}" = "--list" ]; then
  for s in "${STEPS[@]}"; do IFS='|' read -r name page cmd <<< "$s"; printf '%-18s %s\n    %s\n' "$name" "$page" "$cmd"; done
  exit 0
fi
OUT="${1:?usage: $0 OUT [BUILD_DIR] [STEP...]  (or --list)}"
BUILD="$(realpath -m "${2:-build}")"
shift $(( $# >= 2 ? 2 : 1 ))
mkdir -p "$OUT"
OUT="$(realpath "$OUT")"
[ -x "$BUILD/vista" ] || { echo "regenerate_all: $BUILD/vista not found (build the vista target)" >&2; exit 1; }
export OUT BUILD

start=$SECONDS
for s in "${STEPS[@]}"; do
  IFS='|' read -r name page cmd <<< "$s"
  if [ $# -gt 0 ] && [[ " $* " != *" $name "* ]]; then continue; fi
  if [ -e "$OUT/$name.done" ]; then
    echo "regenerate_all: $name: done before ($OUT/$name.done), skipped" >&2
    continue
  fi
  echo "regenerate_all: $name -> $page ($(( (SECONDS - start) / 60 )) min so far)" >&2
  echo "  $cmd" >&2
  bash -c "set -euo pipefail; $cmd"
  date -u > "$OUT/$name.done"
done
echo "regenerate_all: all steps done in $(( (SECONDS - start) / 60 )) min; review git diff docs/" >&2
