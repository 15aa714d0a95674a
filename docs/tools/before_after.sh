#!/usr/bin/env bash
# Before/after check of a refactoring: the same `vista bench` command run by two
# builds of vista, alternately (A B A B ...), on the same city and path, so
# that load changes hit both alike. Prints a markdown table per mode: median
# frame time of each build (median over its runs of the per-run median), the
# ratio after/before, and the two builds' images of the same frame compared
# directly (luma PSNR between them, median and minimum over the frames, and the
# largest fraction of pixels differing by more than 8): the first run of each
# build saves every frame (--worst = frame count). Same frames: the after
# build's path is made with no run-up, as the before build's.
#
# Usage: docs/tools/before_after.sh BEFORE_VISTA AFTER_VISTA CITY.osgb OUT_DIR [RUNS] [-- bench args]
# IMAGE_PSNR (default build/tests/bench/image_psnr) compares two PNGs.
# Needs an X display (runs itself under xvfb-run -a when DISPLAY is unset).
set -euo pipefail
if [ -z "${DISPLAY:-}" ]; then exec xvfb-run -a -s "-screen 0 1280x1024x24" "$0" "$@"; fi
BEFORE=$(realpath "$1"); AFTER=$(realpath "$2"); CITY=$(realpath "$3"); OUT=$4; RUNS=${5:-3}
shift 5 2>/dev/null || shift $#
[ "${1:-}" = "--" ] && shift
ARGS=("$@")
[ ${#ARGS[@]} -eq 0 ] && ARGS=(--seed 7 --frames 40 --size 640x480 --modes full,near,raycast,osgimpostor,hybrid)
IMAGE_PSNR=$(realpath "${IMAGE_PSNR:-build/tests/bench/image_psnr}")
FRAMES=40
for ((i = 0; i < ${#ARGS[@]}; ++i)); do [ "${ARGS[$i]}" = "--frames" ] && FRAMES=${ARGS[$((i + 1))]}; done
mkdir -p "$OUT"
# The after build starts its paths at cruising speed by default; --run-up 0
# gives the path the before build drives.
AFTER_EXTRA=()
if "$AFTER" bench --help 2>&1 | grep -q -- "--run-up"; then AFTER_EXTRA=(--run-up 0); fi
for r in $(seq 1 "$RUNS"); do
  SAVE=(); [ "$r" = 1 ] && SAVE=(--worst "$FRAMES")
  "$BEFORE" bench "$CITY" "${ARGS[@]}" "${SAVE[@]}" --out "$OUT/before_$r" -q
  "$AFTER" bench "$CITY" "${ARGS[@]}" "${AFTER_EXTRA[@]}" "${SAVE[@]}" --out "$OUT/after_$r" -q
done
python3 - "$OUT" "$RUNS" "$IMAGE_PSNR" <<'PY'
import csv, glob, re, statistics, subprocess, sys, os
out, runs, image_psnr = sys.argv[1], int(sys.argv[2]), sys.argv[3]
def images(tag):
    found = {}
    for f in glob.glob(os.path.join(out, f"{tag}_1", "images", "worst*_f*.png")):
        m = re.match(r"worst\d+_(\w+?)_f(\d+)(_ref)?\.png$", os.path.basename(f))
        if m and not f.endswith("_diff.png"):
            found[("full" if m.group(3) else m.group(1), int(m.group(2)))] = f
    return found
IB, IA = images("before"), images("after")
def direct(mode):
    ps, fr = [], []
    for key in IB:
        if key[0] == mode and key in IA:
            p, d = subprocess.check_output([image_psnr, IB[key], IA[key]]).split()
            ps.append(float(p)); fr.append(float(d))
    return ps, fr
def load(tag, r):
    rows = list(csv.DictReader(open(os.path.join(out, f"{tag}_{r}", "frames.csv"))))
    per = {}
    for x in rows:
        per.setdefault(x["mode"], {})[int(x["frame"])] = (float(x["frame_ms"]), float(x["psnr_db"]))
    return per
B = [load("before", r) for r in range(1, runs + 1)]
A = [load("after", r) for r in range(1, runs + 1)]
modes = [m for m in B[0] if m in A[0]]
print("| mode | before ms (median) | after ms (median) | after / before | frames compared | image before vs after: PSNR median / min (dB) | max fraction of pixels differing > 8 |")
print("|---|---|---|---|---|---|---|")
for m in modes:
    bm = statistics.median(statistics.median(v[0] for v in b[m].values()) for b in B)
    am = statistics.median(statistics.median(v[0] for v in a[m].values()) for a in A)
    ps, fr = direct(m)
    cmp = f"{statistics.median(ps):.1f} / {min(ps):.1f} | {max(fr):.5f}" if ps else "— | —"
    print(f"| {m} | {bm:.1f} | {am:.1f} | {am / bm:.2f} | {len(ps)} | {cmp} |")
PY
