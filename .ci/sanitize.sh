#!/usr/bin/env bash
# Builds vista with AddressSanitizer + UndefinedBehaviorSanitizer
# (-fno-sanitize-recover=all: any finding fails the test) and runs the test
# suite. Suppressions (tests/sanitizers/*.supp) cover system libraries only,
# each with its reason.
#   usage: .ci/sanitize.sh [ctest -R regex]     (default: every test)
# VISTA_SAN_TARGETS limits the build (e.g. "test_foundation test_citygen vista").
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD="${VISTA_SAN_BUILD_DIR:-build-san}"
# Mesa's software driver is dlopen'ed and unloaded again when the X display
# closes; LeakSanitizer then reports its process-lifetime allocations from an
# "<unknown module>" that no suppression can name. Preloading it (after the
# ASan runtime, which must come first) keeps it mapped, so lsan.supp matches it.
# The scripts' tests preload only Mesa (verify_asan_link_order=0 below lets it come
# before the runtime the vista binary links): their shells, interpreters and
# X server stay unsanitized, and their vista processes are checked.
TEST_ENV=""
SCRIPT_ENV=""
DRI="$(ls /usr/lib/*/dri/swrast_dri.so 2>/dev/null | head -1 || true)"
if [ -n "$DRI" ]; then
  TEST_ENV="LD_PRELOAD=$(gcc -print-file-name=libasan.so) $DRI"
  SCRIPT_ENV="LD_PRELOAD=$DRI"
fi
# Debian's interpreter, as .ci/setup.sh configures it: the one with the Python tests' packages.
cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVISTA_SANITIZE=ON -DVISTA_BUILD_BENCHMARKS=OFF \
  -DPython3_EXECUTABLE=/usr/bin/python3 \
  "-DVISTA_TEST_ENVIRONMENT=$TEST_ENV" "-DVISTA_SCRIPT_TEST_ENVIRONMENT=$SCRIPT_ENV" ${VISTA_SAN_CMAKE_ARGS:-} >/dev/null
# shellcheck disable=SC2086
cmake --build "$BUILD" -j"$(nproc)" ${VISTA_SAN_TARGETS:+--target $VISTA_SAN_TARGETS}
SUPP="$PWD/tests/sanitizers"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1:verify_asan_link_order=0"
export LSAN_OPTIONS="suppressions=$SUPP/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:suppressions=$SUPP/ubsan.supp"
# Stock osgconv (the plugin round-trip test) is not built with ASan: it loads
# our sanitized plugin, so the runtime must be preloaded into it.
export VISTA_TEST_PRELOAD="$(gcc -print-file-name=libasan.so)"
ARGS=(--test-dir "$BUILD" --output-on-failure -j2 --timeout 1800)
[ $# -gt 0 ] && ARGS+=(-R "$1")
if [ -z "${DISPLAY:-}" ] && command -v xvfb-run >/dev/null; then
  exec xvfb-run -a -s "-screen 0 1280x1024x24" ctest "${ARGS[@]}"
fi
exec ctest "${ARGS[@]}"
