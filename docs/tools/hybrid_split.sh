#!/usr/bin/env bash
# Regenerates the table "The adaptive split against its fixed choices" in
# docs/measurements/modes.md: on three cities no test uses (seeds 11, 23, 37,
# 1.5 km, data/default.json) and their car, walk and fly paths (path seed 5),
# the hybrid with --near auto side by side with its fixed choices: `raycast`
# (0 m), `hybrid-fixed` (the near default, 100 m) and `full` (everything),
# modes interleaved per frame, 640x480, 40 frames; PSNR against `full`.
#
# usage: docs/tools/hybrid_split.sh [OUT_DIR] [VISTA_BIN]   (default: a temp dir, build/vista)
# Needs python3 and, without a display, xvfb-run. About 10 minutes on 2 cores with llvmpipe.
set -euo pipefail
source "$(dirname "$0")/lib.sh"
doc_setup hybrid_split.sh hybrid-split 1280x1024x24 "$@"
DOC_TMP_FILES=(docs/measurements/.modes.md.tmp)
mkdir -p "$OUT"
FRAMES=${FRAMES:-40}
SPECS=()
for seed in 11 23 37; do
  city="$OUT/city$seed.osgb"
  [ -s "$city" ] || "$VISTA" gen --params data/default.json --seed "$seed" --size 1500 -o "$city" -q
  for kind in car walk fly; do
    d="$OUT/seed${seed}_$kind"
    log "bench seed $seed $kind"
    "${XVFB[@]}" "$VISTA" bench "$city" --seed 5 --kind "$kind" --frames "$FRAMES" --size 640x480 --near auto \
      --modes full,raycast,hybrid-fixed,hybrid --out "$d" -q
    SPECS+=("seed $seed|$kind=$d")
  done
done
python3 docs/tools/hybrid_ratios.py split "${SPECS[@]}" > "$OUT/split.md"
cat "$OUT/split.md"
doc_replace_block docs/measurements/modes.md hybrid-split "$OUT/split.md"
log "wrote docs/measurements/modes.md"
