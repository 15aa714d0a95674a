#!/usr/bin/env bash
# Regenerates the table "Run-time effects only save: the hybrid per path kind"
# in docs/measurements/effects.md (or in the file DOC names; effects.sh calls
# it for its own copy): on the 2 km city (data/default.json, seed 1, glass
# marked) the hybrid (--near auto) with haze at 600, 1500 and 3000 m, the
# night sky, and glass, against the same frames with no run-time effect, on
# car, walk and fly paths (path seed 3, 24 frames, 640x480). Runs alternate
# none, 600, 1500, 3000, night, glass, twice per path kind; a frame's time is
# its median over the two runs; the ratio is the median over frames of
# (effect / none) on the same frame. Glass is compared on the frames where it
# is off-screen (no reflection pass ran): on-screen its pass is the effect's
# own work (section 1).
#
# usage: docs/tools/effects_haze.sh [OUT_DIR] [VISTA_BIN]       (DOC=path to write another copy)
# Needs python3 and, without a display, xvfb-run. About 8 minutes on 2 cores with llvmpipe.
set -euo pipefail
DOC=${DOC:-docs/measurements/effects.md}
source "$(dirname "$0")/lib.sh"
doc_setup effects_haze.sh effects-haze 1280x1024x24 "$@"
DOC_TMP_FILES=("$(dirname "$DOC")/.$(basename "$DOC").tmp")
mkdir -p "$OUT"
city="$OUT/city.osgb"
[ -s "$city" ] || "$VISTA" gen --params data/default.json --effects glass -o "$city" -q
bench() {  # bench DIR KIND EFFECTS
  rm -rf "$1"
  "${XVFB[@]}" "$VISTA" bench "$city" --seed 3 --kind "$2" --frames 24 --size 640x480 --near auto --modes hybrid \
    --effects "$3" --out "$1" -q >/dev/null
}
SPECS=()
for kind in car walk fly; do
  for rep in 1 2; do
    log "$kind: none, haze 600, 1500, 3000 m, night, glass ($rep)"
    bench "$OUT/${kind}_clear$rep" "$kind" none
    for v in 600 1500 3000; do bench "$OUT/${kind}_v${v}_$rep" "$kind" "{\"haze\":{\"visibility_m\":$v}}"; done
    bench "$OUT/${kind}_night_$rep" "$kind" night
    bench "$OUT/${kind}_glass_$rep" "$kind" glass
  done
  for v in 600 1500 3000; do
    SPECS+=("haze $v m | $kind=$OUT/${kind}_v${v}_1:$OUT/${kind}_clear1:$OUT/${kind}_v${v}_2:$OUT/${kind}_clear2")
  done
  SPECS+=("night sky | $kind=$OUT/${kind}_night_1:$OUT/${kind}_clear1:$OUT/${kind}_night_2:$OUT/${kind}_clear2")
  SPECS+=("glass off-screen | $kind=$OUT/${kind}_glass_1:$OUT/${kind}_clear1:$OUT/${kind}_glass_2:$OUT/${kind}_clear2")
done
python3 docs/tools/hybrid_ratios.py effect "${SPECS[@]}" > "$OUT/haze.md"
cat "$OUT/haze.md"
doc_replace_block "$DOC" effects-haze "$OUT/haze.md"
log "wrote $DOC"
