#!/usr/bin/env bash
# Before/after check of a refactoring: the same `vista bench` command run by two
# builds of vista, alternately (A B A B ...), on the same city and path, so
# that load changes hit both alike. Prints a markdown table per mode: median
# frame time of each build (median over its runs of the per-run median), the
# ratio after/before, and the largest per-frame difference of PSNR vs `full`
# between the builds (same frames: the path is made with no run-up by both).
#
# Usage: docs/tools/before_after.sh BEFORE_VISTA AFTER_VISTA CITY.osgb OUT_DIR [RUNS] [-- bench args]
# Needs an X display (runs itself under xvfb-run -a when DISPLAY is unset).
set -euo pipefail
if [ -z "${DISPLAY:-}" ]; then exec xvfb-run -a -s "-screen 0 1280x1024x24" "$0" "$@"; fi
BEFORE=$(realpath "$1"); AFTER=$(realpath "$2"); CITY=$(realpath "$3"); OUT=$4; RUNS=${5:-3}
shift 5 2>/dev/null || shift $#
[ "${1:-}" = "--" ] && shift
ARGS=("$@")
[ ${#ARGS[@]} -eq 0 ] && ARGS=(--seed 7 --frames 40 --size 640x480 --modes full,near,raycast,osgimpostor,hybrid)
mkdir -p "$OUT"
# The after build starts its paths at cruising speed by default; --run-up 0
# gives the path the before build drives.
AFTER_EXTRA=()
if "$AFTER" bench --help 2>&1 | grep -q -- "--run-up"; then AFTER_EXTRA=(--run-up 0); fi
for r in $(seq 1 "$RUNS"); do
  "$BEFORE" bench "$CITY" "${ARGS[@]}" --out "$OUT/before_$r" -q
  "$AFTER" bench "$CITY" "${ARGS[@]}" "${AFTER_EXTRA[@]}" --out "$OUT/after_$r" -q
done
python3 - "$OUT" "$RUNS" <<'PY'
import csv, statistics, sys, os
out, runs = sys.argv[1], int(sys.argv[2])
def load(tag, r):
    rows = list(csv.DictReader(open(os.path.join(out, f"{tag}_{r}", "frames.csv"))))
    per = {}
    for x in rows:
        per.setdefault(x["mode"], {})[int(x["frame"])] = (float(x["frame_ms"]), float(x["psnr_db"]))
    return per
B = [load("before", r) for r in range(1, runs + 1)]
A = [load("after", r) for r in range(1, runs + 1)]
modes = [m for m in B[0] if m in A[0]]
print("| mode | before ms (median) | after ms (median) | after / before | max per-frame PSNR change (dB) |")
print("|---|---|---|---|---|")
for m in modes:
    bm = statistics.median(statistics.median(v[0] for v in b[m].values()) for b in B)
    am = statistics.median(statistics.median(v[0] for v in a[m].values()) for a in A)
    dp = max(abs(A[0][m][f][1] - B[0][m][f][1]) for f in B[0][m] if f in A[0][m])
    print(f"| {m} | {bm:.1f} | {am:.1f} | {am / bm:.2f} | {dp:.2f} |")
PY
