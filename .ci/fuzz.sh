#!/usr/bin/env bash
# Builds the libFuzzer targets (Clang, ASan + UBSan) and runs each for
# FUZZ_SECONDS (default 60) on a copy of its seed corpus (tests/fuzz/corpus);
# with FUZZ_RUNS=N a target stops after N executions instead, FUZZ_SECONDS
# then being only a cap (seconds column = the time it took).
# Prints one line per target: name, seconds, executions, corpus size, result;
# writes the same as TSV to ${FUZZ_OUT:-build-fuzz/fuzz-results}/summary.tsv and
# any crashing input beside it. Exit 1 if any target found a crash.
#   usage: .ci/fuzz.sh [target ...]     (default: all targets)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD="${VISTA_FUZZ_BUILD_DIR:-build-fuzz}"
SECONDS_EACH="${FUZZ_SECONDS:-60}"
OUT="${FUZZ_OUT:-$BUILD/fuzz-results}"
ALL="fuzz_params fuzz_street_graph fuzz_path_csv fuzz_cell_result fuzz_osm fuzz_scene_file fuzz_baked_file fuzz_ray_set fuzz_rig fuzz_fcd fuzz_paged_manifest fuzz_dataset_manifest"
TARGETS="${*:-$ALL}"
command -v clang++ >/dev/null || { echo "fuzz.sh: clang++ not found (apt-get install clang)" >&2; exit 2; }
cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
  -DVISTA_FUZZ=ON -DVISTA_BUILD_TESTS=OFF -DVISTA_BUILD_BENCHMARKS=OFF ${VISTA_FUZZ_CMAKE_ARGS:-} >/dev/null
# shellcheck disable=SC2086
cmake --build "$BUILD" -j"$(nproc)" --target $TARGETS
mkdir -p "$OUT"
printf "target\tseconds\texecutions\tcorpus\tresult\n" > "$OUT/summary.tsv"
export ASAN_OPTIONS="detect_leaks=0:abort_on_error=1:symbolize=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:suppressions=$PWD/tests/sanitizers/ubsan.supp"
failed=0
for t in $TARGETS; do
  work="$(mktemp -d)"
  cp -r "tests/fuzz/corpus/$t/." "$work/" 2>/dev/null || true
  log="$OUT/$t.log"
  start=$SECONDS
  set +e
  "$BUILD/tests/fuzz/$t" "$work" -max_total_time="$SECONDS_EACH" ${FUZZ_RUNS:+-runs=$FUZZ_RUNS} -max_len=65536 -timeout=30 \
    -rss_limit_mb=4096 -print_final_stats=1 -artifact_prefix="$OUT/$t-" >"$log" 2>&1
  rc=$?
  set -e
  took=$((SECONDS - start))
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -1)
  corpus=$(find "$work" -type f | wc -l)
  result=clean
  if [ "$rc" -ne 0 ]; then result="FINDING (exit $rc, see $log)"; failed=1; fi
  printf "%s\t%s\t%s\t%s\t%s\n" "$t" "$took" "${execs:-0}" "$corpus" "$result" | tee -a "$OUT/summary.tsv"
  rm -rf "$work"
done
exit "$failed"
