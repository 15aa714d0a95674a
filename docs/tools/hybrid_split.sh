#!/usr/bin/env bash
# Regenerates the table "The adaptive split against its fixed choices" in
# docs/measurements/modes.md: on five cities no test uses and their car, walk
# and fly paths, all drawn by seed at run time (printed, and written above the
# table), the hybrid with --near auto side by side with its fixed choices:
# `raycast` (0 m), `hybrid-fixed` (the near default, 100 m) and `full`
# (everything), modes interleaved per frame, 640x480, 40 frames; PSNR against
# `full`. Per path: the median same-frame ratio of the hybrid to the cheapest of
# the three on that frame, and the hybrid's median PSNR.
#
# usage: docs/tools/hybrid_split.sh [OUT_DIR] [VISTA_BIN]   (default: a temp dir, build/vista)
# Environment: SEEDS="S1 S2 S3 S4 S5" and PATH_SEED=N repeat a run (default: drawn at run time);
# SIZE (city edge, metres, default 1500), FRAMES (default 40), WRITE_DOC=0 prints the table
# without touching docs/measurements/modes.md (a smoke run).
# Needs python3 and, without a display, xvfb-run. About 20 minutes on 2 cores with llvmpipe.
set -euo pipefail
source "$(dirname "$0")/lib.sh"
doc_setup hybrid_split.sh hybrid-split 1280x1024x24 "$@"
DOC_TMP_FILES=(docs/measurements/.modes.md.tmp)
mkdir -p "$OUT"
FRAMES=${FRAMES:-40}
SIZE=${SIZE:-1500}
WRITE_DOC=${WRITE_DOC:-1}
draw() { python3 -c "import random; print(' '.join(str(random.randrange(1000, 1000000)) for _ in range($1)))"; }
SEEDS=${SEEDS:-$(draw 5)}
PATH_SEED=${PATH_SEED:-$(draw 1)}
for s in $SEEDS $PATH_SEED; do
  [[ $s =~ ^[0-9]+$ ]] || { echo "hybrid_split.sh: SEEDS and PATH_SEED take non-negative integers, got '$s'" >&2; exit 2; }
done
log "city seeds: $SEEDS; path seed: $PATH_SEED (repeat with SEEDS=\"$SEEDS\" PATH_SEED=$PATH_SEED)"
SPECS=()
for seed in $SEEDS; do
  city="$OUT/city$seed.osgb"
  [ -s "$city" ] || "$VISTA" gen --params data/default.json --seed "$seed" --size "$SIZE" -o "$city" -q
  for kind in car walk fly; do
    d="$OUT/seed${seed}_$kind"
    log "bench seed $seed $kind"
    "${XVFB[@]}" "$VISTA" bench "$city" --seed "$PATH_SEED" --kind "$kind" --frames "$FRAMES" --size 640x480 \
      --near auto --modes full,raycast,hybrid-fixed,hybrid --out "$d" -q
    SPECS+=("seed $seed|$kind=$d")
  done
done
{
  echo "Cities: seeds $SEEDS of \`data/default.json\`, ${SIZE} m; paths: seed $PATH_SEED; $FRAMES frames at 640x480."
  echo
  python3 docs/tools/hybrid_ratios.py split "${SPECS[@]}"
} > "$OUT/split.md"
cat "$OUT/split.md"
if [ "$WRITE_DOC" != 0 ]; then
  doc_replace_block docs/measurements/modes.md hybrid-split "$OUT/split.md"
  log "wrote docs/measurements/modes.md"
fi
