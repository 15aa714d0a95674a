#!/usr/bin/env bash
# Regenerates every measured page of docs/measurements/ (and the CLI reference)
# by running each page's own scripts in turn. Every step stays under an hour on
# 2 cores, so a page (--page NAME: all its steps) or a single step can run on
# its own, in as many sittings as it has steps. Resumable: a step whose outputs
# exist (OUT/STEP.done) is skipped, and most scripts keep their finished work in
# OUT/STEP/, so after a kill the same command goes on where it stopped. Delete
# OUT/STEP.done to run a step again.
#
# Every table lands in its page's generated block (<!-- NAME:begin/end -->)
# under a stamp: the vista version and commit, the machine, and the load
# average when the step started (docs/tools/lib.sh, doc_stamp). A step started
# at a 1-minute load average above 0.5 is marked "Measured under load" by its
# own script: run this with nothing else on the machine (no builds, no other
# measurements). tests/tools/check_docs.py fails on a block stamped with an
# older minor version than CMake's project VERSION.
#
# usage: docs/tools/regenerate_all.sh OUT [BUILD_DIR] [STEP...]
#        docs/tools/regenerate_all.sh OUT [BUILD_DIR] --page PAGE   (e.g. --page paging)
#        docs/tools/regenerate_all.sh --list    (steps, pages, minutes, commands)
#   OUT        working directory (cities, benches, bakes; tens of GB)
#   BUILD_DIR  the build with vista, vista_bake_report and the benchmarks
#              (tests/bench: image_psnr, far_field_sweep, bench_raw_rays, soak,
#              stream_memory; -DVISTA_BUILD_BENCHMARKS=ON); default build
#   STEP...    only these steps (names as listed by --list)
# Minutes are on 2 cores with llvmpipe and nothing else running; all steps
# together take about 22 hours, 12 of them fuzzing (reliability).
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
cd "$REPO"

# The fuzz targets of .ci/fuzz.sh: one reliability step each (FUZZ_S seconds per target).
FUZZ_TARGETS="fuzz_params fuzz_street_graph fuzz_path_csv fuzz_cell_result fuzz_osm fuzz_scene_file fuzz_baked_file fuzz_ray_set fuzz_rig fuzz_fcd fuzz_paged_manifest"
FUZZ_S=3000
W=docs/tools/write_block.sh

# step name | page (docs/measurements/PAGE.md, or a path) | minutes | command
# (run from the repository root; $OUT, $BUILD and $FUZZ_S set)
STEPS=(
  "cli|docs/reference/cli.md|1|python3 docs/tools/cli_reference.py \$BUILD/vista > docs/reference/.cli.md.tmp && mv docs/reference/.cli.md.tmp docs/reference/cli.md"
  "far-field|far-field|45|docs/tools/far_field_table.sh \$OUT/far-field \$BUILD/vista"
  "farfield-compare|farfield-compare|30|docs/tools/farfield_compare.sh \$OUT/farfield-compare \$BUILD/vista"
  "modes|modes|20|docs/tools/sweep.sh \$BUILD/vista \$OUT/modes > \$OUT/modes.md && $W docs/measurements/modes.md modes-sweep \$OUT/modes.md \$BUILD/vista"
  "hybrid-split|modes|10|docs/tools/hybrid_split.sh \$OUT/hybrid-split \$BUILD/vista"
  "near-detail|modes|40|docs/tools/near_detail.sh \$OUT/near-detail \$BUILD/vista"
  "effects|effects|30|docs/tools/effects.sh \$OUT/effects \$BUILD/vista"
  "whole-bake|bake|55|docs/tools/whole_bake.sh \$OUT/whole-bake \$BUILD/vista"
  "whole-bake-seed2|bake|55|CITY_SEED=2 MARKER=whole-bake-seed2 docs/tools/whole_bake.sh \$OUT/whole-bake-seed2 \$BUILD/vista"
  "splat|bake|20|docs/tools/splat_table.sh \$OUT/splat \$BUILD/vista"
  "splat-seed2|bake|15|SIZE_M=2000 CITY_SEED=2 CELLS='3 20 500 940' SIGMAS='0.25' FRAMES=3 MARKER=splat-table-seed2 docs/tools/splat_table.sh \$OUT/splat-seed2 \$BUILD/vista"
  "bake-table|bake|15|docs/tools/bake_results.sh \$BUILD \$OUT/bake-table > \$OUT/bake-table.md && $W docs/measurements/bake.md table-5-1 \$OUT/bake-table.md \$BUILD/vista"
  "generation|generation|5|VISTA=\$BUILD/vista docs/tools/perf_table.sh 500 1000 2000 4000 8000 > \$OUT/generation.md && $W docs/measurements/generation.md generation-table \$OUT/generation.md \$BUILD/vista"
  "paged-generation|paging|30|docs/tools/paged_rss_table.sh \$BUILD \$OUT/paged-generation 4000,8000,16000,32000 4000,8000 > \$OUT/paged-generation.md && $W docs/measurements/paging.md paged-generation \$OUT/paged-generation.md \$BUILD/vista"
  "scale|paging|50|docs/tools/scale_table.sh \$OUT/scale \$BUILD/vista"
  "paged-reach|paging|15|docs/tools/paged_reach_table.sh \$OUT/scale/c8000.paged \$OUT/paged-reach \$BUILD"
  "stream|paging|55|docs/tools/stream_table.sh \$OUT/stream \$BUILD/vista"
  "stream-budget|paging|15|docs/tools/stream_budget.sh \$OUT/stream \$BUILD/vista"
  "raw-rays|raw-rays|10|docs/tools/raw_rays.sh \$OUT/raw-rays \$BUILD/vista"
  "opendrive|docs/formats.md \"OpenDRIVE\" (table in OUT/opendrive.md)|20|docs/tools/opendrive_table.sh \$OUT/opendrive-work \$BUILD/vista > \$OUT/opendrive.md"
  "traffic|traffic|20|docs/tools/traffic_table.sh \$OUT/traffic \$BUILD/vista"
  "traffic-cost|traffic|20|docs/tools/traffic_frame_cost.sh \$OUT/traffic-cost \$BUILD/vista"
  "rig-table|ground-truth|15|docs/tools/rig_table.sh \$OUT/rig-table \$BUILD/vista"
  "ground-truth|ground-truth (costs in OUT/ground-truth.txt)|5|mkdir -p \$OUT/ground-truth && \$BUILD/vista gen --params data/default.json -o \$OUT/ground-truth/c.osgb -q && \$BUILD/vista path \$OUT/ground-truth/c.osgb --seed 3 -o \$OUT/ground-truth/p.csv && for m in full hybrid; do rm -rf \$OUT/ground-truth/gt_\$m; xvfb-run -a -s '-screen 0 1280x1024x24' \$BUILD/vista render \$OUT/ground-truth/c.osgb --path \$OUT/ground-truth/p.csv --frames 60 --mode \$m --out \$OUT/ground-truth/gt_\$m --stats -q; done > \$OUT/ground-truth.txt 2>&1"
)
# reliability: the fuzz build (one execution per target), each fuzz target alone, the sanitizer
# suite, the soak, then the page from their results (reliability.sh runs the regression tests,
# the fault sweep and the write races itself).
STEPS+=("reliability-fuzz-build|reliability|40|mkdir -p \$OUT/reliability && FUZZ_RUNS=1 FUZZ_OUT=\$OUT/reliability/fuzz-build ./.ci/fuzz.sh > \$OUT/reliability/fuzz-build.txt 2>&1")
for t in $FUZZ_TARGETS; do
  STEPS+=("reliability-$t|reliability|55|rm -rf \$OUT/reliability/$t && mkdir -p \$OUT/reliability && FUZZ_SECONDS=\$FUZZ_S FUZZ_OUT=\$OUT/reliability/$t ./.ci/fuzz.sh $t > \$OUT/reliability/$t.txt 2>&1 || true")
done
STEPS+=(
  "reliability-sanitize|reliability|35|mkdir -p \$OUT/reliability && { ./.ci/sanitize.sh > \$OUT/reliability/sanitize.txt 2>&1 || true; }"
  "reliability-soak|reliability|50|mkdir -p \$OUT/reliability && \$BUILD/vista gen --params data/default.json -q -o \$OUT/reliability/soak.osgb && xvfb-run -a -s '-screen 0 1280x1024x24' \$BUILD/tests/bench/soak \$OUT/reliability/soak.osgb 100000 64x48 > \$OUT/reliability/soak.csv"
  "reliability|reliability|30|{ printf 'target\\tseconds\\texecutions\\tcorpus\\tresult\\n'; for t in $FUZZ_TARGETS; do tail -n +2 \$OUT/reliability/\$t/summary.tsv; done; } > \$OUT/reliability/fuzz.tsv && FUZZ_TSV=\$OUT/reliability/fuzz.tsv SANITIZE_LOG=\$OUT/reliability/sanitize.txt SOAK_CSV=\$OUT/reliability/soak.csv docs/tools/reliability.sh \$FUZZ_S 100000"
)

page_of() { local p=${1%% *}; case "$p" in */*) echo "$p" ;; *) echo "docs/measurements/$p.md" ;; esac; }

if [ "${1:-}" = "--list" ]; then
  declare -A total=()
  order=()
  for s in "${STEPS[@]}"; do
    IFS='|' read -r name page minutes cmd <<< "$s"
    printf '%-34s %3s min  %s\n    %s\n' "$name" "$minutes" "$(page_of "$page")" "$cmd"
    key=$(page_of "$page")
    [ -n "${total[$key]:-}" ] || order+=("$key")
    total[$key]=$(( ${total[$key]:-0} + minutes ))
  done
  echo
  echo "per page (minutes on 2 cores, all its steps; each step under an hour):"
  for key in "${order[@]}"; do printf '  %-42s %4s\n' "$key" "${total[$key]}"; done
  exit 0
fi
OUT="${1:?usage: $0 OUT [BUILD_DIR] [STEP... | --page PAGE]  (or --list)}"
BUILD="$(realpath -m "${2:-build}")"
shift $(( $# >= 2 ? 2 : 1 ))
PAGE=""
if [ "${1:-}" = "--page" ]; then
  PAGE="${2:?--page needs a page name: far-field, modes, bake, paging, ... (see --list)}"
  shift 2
  known=0
  for s in "${STEPS[@]}"; do IFS='|' read -r _ page _ _ <<< "$s"; [ "${page%% *}" = "$PAGE" ] && known=1; done
  [ "$known" = 1 ] || { echo "regenerate_all: --page $PAGE: no step writes docs/measurements/$PAGE.md (see --list)" >&2; exit 2; }
fi
if [ $# -gt 0 ]; then
  for want in "$@"; do
    found=0
    for s in "${STEPS[@]}"; do [ "${s%%|*}" = "$want" ] && found=1; done
    [ "$found" = 1 ] || { echo "regenerate_all: no step named '$want' (see --list)" >&2; exit 2; }
  done
fi
[ -x "$BUILD/vista" ] || { echo "regenerate_all: $BUILD/vista not found (build the vista target)" >&2; exit 2; }
mkdir -p "$OUT"
OUT="$(realpath "$OUT")"
export OUT BUILD FUZZ_S

start=$SECONDS
for s in "${STEPS[@]}"; do
  IFS='|' read -r name page minutes cmd <<< "$s"
  if [ $# -gt 0 ] && [[ " $* " != *" $name "* ]]; then continue; fi
  if [ -n "$PAGE" ] && [ "${page%% *}" != "$PAGE" ]; then continue; fi
  if [ -e "$OUT/$name.done" ]; then
    echo "regenerate_all: $name: done before ($OUT/$name.done), skipped" >&2
    continue
  fi
  # The load average as the step starts: the stamp of its block reports it
  # and marks the block "Measured under load" above 0.5.
  DOC_START_LOAD="$(cut -d' ' -f1-3 /proc/loadavg)"
  export DOC_START_LOAD
  echo "regenerate_all: $name -> $(page_of "$page") (about $minutes min; load average $DOC_START_LOAD; $(( (SECONDS - start) / 60 )) min so far)" >&2
  echo "  $cmd" >&2
  bash -c "set -euo pipefail; $cmd"
  date -u > "$OUT/$name.done"
done
echo "regenerate_all: the steps asked for are done in $(( (SECONDS - start) / 60 )) min; review git diff docs/" >&2
