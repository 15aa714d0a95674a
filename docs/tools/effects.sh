#!/usr/bin/env bash
# Regenerates docs/measurements/effects.md: what each declared effect (sun_shadows, ambient_occlusion,
# haze, glass, night, materials) costs at generation and per frame, how its quality knobs
# trade time for PSNR (with one Pareto plot per effect in docs/img/effects_pareto_*.svg),
# the haze payoff on a 2 km, a 4 km and an 8 km city, reflection rays vs glass in view, raster
# vs ray-caster agreement, and the hybrid with haze vs clear per path kind (effects_haze.sh); plus the README pictures docs/img/effect_{shadows,haze,glass,night}.png.
#
# usage: docs/tools/effects.sh [OUT_DIR] [VISTA_BIN]     (run from anywhere; works in the repo root)
#   OUT_DIR   working directory for cities, benches and frames (default: a new temp dir, removed at
#             the end). Cities (.osgb, up to ~1 GB each) are deleted as soon as they are benched.
#   VISTA_BIN the vista binary (default build/vista); image_psnr is taken from
#             <dir of VISTA_BIN>/tests/bench/image_psnr (override with IMAGE_PSNR=...).
# Needs python3 and, without a display, xvfb-run. About 20 minutes on 2 cores with llvmpipe.
# docs/measurements/effects.md is replaced only when every step succeeded (written to a temp file, then moved).
set -euo pipefail

INVOCATION="docs/tools/effects.sh${1:+ $1}${2:+ $2}"
source "$(dirname "$0")/lib.sh"
doc_setup effects.sh effects 1280x1024x24 "$@"
DOC_TMP_FILES=(docs/measurements/.effects.md.tmp)
IMAGE_PSNR=${IMAGE_PSNR:-$(dirname "$VISTA")/tests/bench/image_psnr}

[ -x "$IMAGE_PSNR" ] || die "image_psnr not found: $IMAGE_PSNR"

PARAMS=data/default.json
FRAMES=24
SIZE=640x480
SEED=3
mkdir -p "$OUT/gen" "$OUT/bench" "$OUT/img"
: > "$OUT/commands.log"

# gen NAME SPEC [gen flags...]  -> $OUT/gen/NAME.osgb and NAME.json (the --stats file)
gen() {
  local name=$1 spec=$2; shift 2
  log "gen $name  (--effects '$spec' $*)"
  local cmd=("$VISTA" gen --params "$PARAMS" --effects "$spec" "$@" -o "$OUT/gen/$name.osgb" --stats "$OUT/gen/$name.json" -q)
  echo "${cmd[*]}" >> "$OUT/commands.log"
  "${cmd[@]}" || die "gen $name failed"
  [ -s "$OUT/gen/$name.json" ] && [ -s "$OUT/gen/$name.osgb" ] || die "gen $name wrote no city/stats"
}
# [BENCH_FRAMES=N] bench NAME CITY KIND MODES [bench flags...]  -> $OUT/bench/NAME/summary.json
bench() {
  local name=$1 city=$2 kind=$3 modes=$4; shift 4
  local d="$OUT/bench/$name"
  rm -rf "$d"
  log "bench $name  ($kind, $modes $*)"
  local cmd=("$VISTA" bench "$OUT/gen/$city.osgb" --seed "$SEED" --kind "$kind" --frames "${BENCH_FRAMES:-$FRAMES}"
             --size "$SIZE" --modes "$modes" --out "$d" -q "$@")
  echo "${cmd[*]}" >> "$OUT/commands.log"
  "${XVFB[@]}" "${cmd[@]}" || die "bench $name failed"
  [ -s "$d/summary.json" ] || die "bench $name wrote no summary.json"
}
drop() { rm -f "$OUT/gen/$1.osgb"; }

ALL=full,hybrid,raycast
FH=full,hybrid

# 1. A plain city and one city per effect (defaults), car path, all three modes, every frame saved.
gen plain none
bench plain plain car $ALL --save-frames

gen sun_shadows sun_shadows
bench sun_shadows sun_shadows car $ALL --save-frames
BENCH_FRAMES=1 bench pic_shadows sun_shadows fly full         # README picture: shadows read better from above
drop sun_shadows

gen ambient_occlusion ambient_occlusion
bench ambient_occlusion ambient_occlusion car $ALL --save-frames
drop ambient_occlusion

gen night night
bench night night car $ALL --save-frames
drop night

gen materials materials
bench materials materials car $ALL --save-frames
drop materials

gen glass glass
bench glass glass car $ALL --save-frames
# 2. glass ray_budget (run-time knob; 50000 = default = the run above); reference 1e8.
for b in 0 2000 10000 100000000; do
  bench "glass_b$b" glass car $FH --save-frames --effects "{\"glass\":{\"ray_budget\":$b}}"
done
# 4. reflection rays vs glass in view on the fly-over.
bench glass_fly glass fly $FH
drop glass

gen haze haze
bench haze haze car $ALL --save-frames
# 2. haze visibility (run-time knob; 1500 = default = the run above); reference 1e6 m (the maximum).
for v in 500 5000 1000000; do
  bench "haze_v$v" haze car $FH --save-frames --effects "{\"haze\":{\"visibility_m\":$v}}"
done
# 3. haze payoff, 2 km: the city with its haze and its clear twin in one run (--also-clear), car
# and fly; and an A/A run (no effect, --also-clear) that shows the band of such a ratio.
bench haze2k_car_aa haze car $FH --effects none --also-clear
bench haze2k_car haze car $FH --also-clear
bench haze2k_fly haze fly $FH --also-clear
drop haze

# 3. haze payoff, 4 km and 8 km (64 km2: much of the city lies beyond the visibility).
for km in 4 8; do
  gen "haze${km}k" haze --size "${km}000"
  for k in car fly; do
    bench "haze${km}k_${k}" "haze${km}k" "$k" $FH --also-clear
  done
  drop "haze${km}k"
done

# 2. Baked knobs on the 1 km centre of the same parameters (the 2 km references would take
# ~10 more minutes): sun_shadows resolution_m {8,4,2,1} (samples 8), reference 0.5 m with 16
# samples; ambient_occlusion samples {4,16,64}, reference 64.
KNOB_SIZE=1000
for r in 8 4 2 1; do
  gen "ss_r$r" "{\"sun_shadows\":{\"resolution_m\":$r}}" --size $KNOB_SIZE
  bench "ss_r$r" "ss_r$r" car $FH --save-frames
  drop "ss_r$r"
done
gen ss_ref '{"sun_shadows":{"resolution_m":0.5,"samples":16}}' --size $KNOB_SIZE
bench ss_ref ss_ref car $FH --save-frames
drop ss_ref
for n in 4 16 64; do
  gen "ao_s$n" "{\"ambient_occlusion\":{\"samples\":$n}}" --size $KNOB_SIZE
  bench "ao_s$n" "ao_s$n" car $FH --save-frames
  drop "ao_s$n"
done
gen plain1k none --size $KNOB_SIZE            # the "effect off" point of both sweeps
bench plain1k plain1k car $FH --save-frames
drop plain1k

# Run-to-run noise: the plain city once more, last.
bench plain_repeat plain car $FH
drop plain

log "measurements done; writing the report"
ELAPSED=$((SECONDS - START))
python3 docs/tools/effects_report.py --out "$OUT" --psnr "$IMAGE_PSNR" --stamp "$(doc_stamp)" \
  --invocation "$INVOCATION" --elapsed "$ELAPSED" --md "$OUT/effects.md" --img "$OUT/img"

# 6. Haze per path kind (hybrid, 600 / 1500 / 3000 m vs clear), into the report's own block.
DOC="$OUT/effects.md" "$(dirname "$0")/effects_haze.sh" "$OUT/haze_kinds" "$VISTA" >/dev/null

# Pictures (first full frame of the chosen bench) and plots, then the doc, all or nothing.
cp "$OUT/bench/pic_shadows/images/first_full.png" "$OUT/img/effect_shadows.png"
cp "$OUT/bench/haze2k_fly/images/first_full.png" "$OUT/img/effect_haze.png"
cp "$OUT/bench/glass/images/first_full.png" "$OUT/img/effect_glass.png"
cp "$OUT/bench/night/images/first_full.png" "$OUT/img/effect_night.png"
for f in "$OUT"/img/*; do [ -s "$f" ] || die "empty output $f"; done
mkdir -p docs/img
cp "$OUT"/img/* docs/img/
cp "$OUT/effects.md" docs/measurements/.effects.md.tmp
mv docs/measurements/.effects.md.tmp docs/measurements/effects.md
log "wrote docs/measurements/effects.md and docs/img/effect*.{png,svg} in $(( (SECONDS - START) / 60 )) min $(( (SECONDS - START) % 60 )) s"
