#!/usr/bin/env bash
# Regenerates docs/measurements/paging.md "What the coarse far city costs in
# accuracy": the same walkthrough of one paged city with the full
# detail loaded out to a growing --paged-radius and the coarse level beyond
# (detail 0, trees as impostors; the ray-cast far field sees it), against a
# reference run with every region at full detail. PSNR: each run's `hybrid`
# frames against the reference run's `full` frames, frame by frame
# (image_psnr, luma), so it holds both the far field's own error and what the
# coarse city costs; ms: the run's own hybrid median; memory: GNU time's peak
# of the bench. The block between <!-- paged-reach:begin --> and
# <!-- paged-reach:end --> of docs/measurements/paging.md is replaced only when every
# step succeeded.
#
# usage: docs/tools/paged_reach_table.sh CITY.paged [OUT_DIR] [BUILD_DIR]
#   env: RADII (default "500 1000 2000 3000"), SEED (path seed, default 5),
#        KIND (default car), FRAMES (default 8), SAMPLING (default runs:2),
#        IMAGE (default 640x480)
# Needs python3, /usr/bin/time, BUILD_DIR/vista and BUILD_DIR/tests/bench/image_psnr.
# About 15 minutes for the 8 km city on 2 cores (the reference run holds the
# whole city: about 6 GB).
set -euo pipefail
CITY=$(realpath "${1:?usage: paged_reach_table.sh CITY.paged [OUT_DIR] [BUILD_DIR]}")
shift
BUILD=$(realpath -m "${2:-build}")
source "$(dirname "$0")/lib.sh"
doc_setup paged_reach_table.sh reach 1280x1024x24 "${1:-}" "$BUILD/vista"
DOC_TMP_FILES=(docs/measurements/.paging.md.tmp)
IMAGE_PSNR=$BUILD/tests/bench/image_psnr
[ -x "$IMAGE_PSNR" ] || die "image_psnr not found: $IMAGE_PSNR (ninja -C $BUILD image_psnr)"
[ -s "$CITY/manifest.json" ] || die "$CITY is not a paged city (no manifest.json)"
RADII=${RADII:-"500 1000 2000 3000"}
SEED=${SEED:-5}
KIND=${KIND:-car}
FRAMES=${FRAMES:-8}
SAMPLING=${SAMPLING:-runs:2}
IMAGE=${IMAGE:-640x480}
INVOCATION="RADII='$RADII' SEED=$SEED KIND=$KIND FRAMES=$FRAMES SAMPLING=$SAMPLING IMAGE=$IMAGE docs/tools/paged_reach_table.sh $(basename "$CITY")"
mkdir -p "$OUT"
: > "$OUT/commands.log"

run() {  # run NAME RADIUS
  local d="$OUT/$1"
  if [ -s "$d/summary.json" ] && [ -s "$OUT/$1.time" ]; then log "$1: done before, kept"; return; fi
  rm -rf "$d"
  log "$1 (--paged-radius $2)"
  local cmd=("$VISTA" bench "$CITY" --seed "$SEED" --kind "$KIND" --frames "$FRAMES" --sampling "$SAMPLING" --size "$IMAGE"
             --modes full,hybrid --paged-radius "$2" --save-frames --worst 0 --out "$d" -q)
  echo "${cmd[*]}" >> "$OUT/commands.log"
  "${XVFB[@]}" /usr/bin/time -v "${cmd[@]}" 2> "$OUT/$1.time" || die "$1 failed: $(tail -3 "$OUT/$1.time")"
}
run reference 100000
for r in $RADII; do run "r$r" "$r"; done

log "table"
python3 - "$OUT" "$IMAGE_PSNR" "$INVOCATION" "$RADII" > "$OUT/table.md" <<'EOF'
import glob, json, os, re, statistics, subprocess, sys
out, image_psnr, invocation, radii = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4].split()
def rss_mb(name):
    m = re.search(r"Maximum resident set size \(kbytes\): (\d+)", open(f"{out}/{name}.time").read())
    return int(m.group(1)) / 1024
def frames(run, mode):
    return {os.path.basename(f).split("_")[0]: f for f in glob.glob(f"{out}/{run}/frames/f*_{mode}.png")}
ref = frames("reference", "full")
print(f"Command: `{invocation}`; every run is `vista bench CITY --seed M --kind K --frames F --modes full,hybrid "
      "--paged-radius R --save-frames`, the reference with R = 100000 (every region at full detail).")
print()
print("| --paged-radius (m) | regions full + coarse | triangles loaded (M) | region files (MB) | BVH + chunking (s) "
      "| bench peak RSS (MB) | hybrid ms | hybrid PSNR vs reference full, median / min (dB) | PSNR vs its own full (dB) |")
print("|---|---|---|---|---|---|---|---|---|")
for name, radius in [("reference", "all")] + [(f"r{r}", r) for r in radii]:
    s = json.load(open(f"{out}/{name}/summary.json"))
    p, h = s["paged"], s["modes"]["hybrid"]
    setup = h.get("setup_ms", {})
    mine = frames(name, "hybrid")
    ps = [float(subprocess.check_output([image_psnr, mine[k], ref[k]]).split()[0]) for k in sorted(mine) if k in ref]
    print(f"| {radius} | {p['regions_loaded']} + {p['coarse_regions_loaded']} of {p['regions_total']} "
          f"| {s['city_triangles'] / 1e6:.1f} | {p['bytes_loaded'] / 1e6:.0f} "
          f"| {(setup.get('bvh', 0) + setup.get('chunking', 0)) / 1000:.0f} | {rss_mb(name):.0f} "
          f"| {h['frame_ms_median']:.1f} | {statistics.median(ps):.1f} / {min(ps):.1f} | {h['psnr_db_median']:.1f} |")
EOF
cat "$OUT/table.md"

doc_replace_block docs/measurements/paging.md paged-reach "$OUT/table.md"
log "done: docs/measurements/paging.md updated"
