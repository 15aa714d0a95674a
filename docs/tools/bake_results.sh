#!/usr/bin/env bash
# Regenerates the measurements of docs/measurements/bake.md "Table 5.1": Table 5.1
# for three impostors, accuracy against cost for the bake options, the
# antialiasing comparison and (with --whole) the whole-city bake, its
# placement trade-off and a `vista bench --modes full,impostor` run on it.
# Prints the Markdown tables on stdout; intermediate files stay in OUT_DIR and
# are reused when the script is run again (delete them to re-measure).
#
# usage: docs/tools/bake_results.sh [BUILD_DIR] [OUT_DIR] [--whole]
#   BUILD_DIR defaults to build, OUT_DIR to ./results-bake.
# Needs jq and an X display; without one it re-runs itself under `xvfb-run -a`.
# About 15 minutes on 2 cores with llvmpipe; --whole adds about an hour and
# about 6 GB of disk.
set -euo pipefail
BUILD=$(realpath "${1:-build}")
OUT=${2:-results-bake}
WHOLE=${3:-}
VISTA=$BUILD/vista
REPORT=$BUILD/vista_bake_report
if [ -z "${DISPLAY:-}" ]; then exec xvfb-run -a "$0" "$BUILD" "$OUT" $WHOLE; fi
mkdir -p "$OUT" && cd "$OUT"
[ -f city.osgb ] || "$VISTA" gen --size 2000 --seed 1 -q -o city.osgb

med='sort | .[length / 2 | floor]'

# ---- Table 5.1: three single-impostor cells (small, medium, large far field).
# The city-wide storage budget decides which street ends get an impostor in a
# whole bake; the table measures one impostor per cell, so it is off here.
T51="20 940 1180"
for c in $T51; do
    [ -f "t51_$c.json" ] || "$VISTA" bake city.osgb -o "t51_$c.osgb" --cells "$c" --storage-budget off --jobs 2 --stats "t51_$c.json" -q
    if [ "$(jq '.impostor_stats | length' "t51_$c.json")" != 1 ]; then
        echo "bake_results.sh: cell $c has no impostor: $(jq -r '.notes | join("; ")' "t51_$c.json")" >&2
        exit 1
    fi
    [ -f "t51_${c}_report.json" ] || "$REPORT" --cell "$c" --frames 10 --ssaa 4 --baked "t51_$c.osgb" --json "t51_${c}_report.json" > /dev/null
done
echo "### Table 5.1"
echo
echo "Commands: \`vista gen --size 2000 --seed 1 -o city.osgb\`, then per cell C in $T51:"
echo "\`vista bake city.osgb -o t51_C.osgb --cells C --jobs 2 --stats t51_C.json\` and"
echo "\`xvfb-run -a vista_bake_report --cell C --frames 10 --ssaa 4 --baked t51_C.osgb --json t51_C_report.json\`."
echo
row() {  # $1 = label, $2 = jq expression over (stats impostor, report entry), $3 = the thesis' figures
    printf '| %s |' "$1"
    for c in $T51; do
        printf ' %s |' "$(jq -r -n --slurpfile s "t51_$c.json" --slurpfile r "t51_${c}_report.json" \
            "\$s[0].impostor_stats[0] as \$i | \$r[0][0] as \$p | $2")"
    done
    echo " ${3:-—} |"
}
printf '| |'; for c in $T51; do printf ' cell %s |' "$c"; done; echo ' thesis scenes 1 / 2 / 3 |'
printf '|---|'; for c in $T51; do printf -- '---|'; done; echo '---|'
row "street end" '$i.end'
row "far-field triangles replaced" '$i.far_triangles'
row "LDI samples → after removal (removed %)" '"\($i.ldi_samples) → \($i.after_removal) (\(100 - 100 * $i.after_removal / $i.ldi_samples | round) %)"'
row "points (visible from the cell)" '$i.points' "80,341 / 87,665 / 31,252"
row "textured points (rest: one colour)" '$i.textured_points'
row "screen pixels from the cell centre (distinct; bbox)" '"\($i.screen_pixels); \($i.screen_bbox_pixels)"' "34,000 / 36,000 / 11,000 (bbox)"
row "points per screen pixel (distinct; bbox)" '"\($i.points_per_screen_pixel * 100 | round / 100); \($i.points / $i.screen_bbox_pixels * 100 | round / 100)"' "2.35 / 2.42 / 2.8 (bbox)"
row "Monte Carlo rays" '"\($i.mc_rays / 1e6 * 10 | round / 10) M"'
row "bake time (s)" '$i.bake_s * 100 | round / 100' "22 / 41 / 31 min (2001)"
row "memory (MB; all points 8x2 texels)" '"\($i.memory_mb * 100 | round / 100); \($i.memory_mb_uncompressed * 100 | round / 100)"' "1.6 / 1.75 / 0.6 (uncompressed)"
row "render textured (ms, median of 10)" '$p.imp_ms * 10 | round / 10' "60 / 54 / 160 Hz (GPU)"
row "render points only (ms)" '$p.pts_ms * 10 | round / 10' "36 / 32 / 98 Hz (software vertex program)"
row "render replaced geometry (ms)" '$p.geom_ms * 10 | round / 10'
echo

# ---- What accuracy costs: bake options on cell 3 (one impostor)
VARIANTS=(
    "default|"
    "no F test (spread-only rule)|--texel-significance 0"
    "F test at 0.001|--texel-significance 0.001"
    "1 texel per point|--texels 1"
    "4x1 texels|--texels 4x1"
    "looser MC stop (8/255)|--mc-threshold 0.0314"
    "tighter MC stop (0.5/255, max 32)|--mc-threshold 0.00196 --mc-max 32"
    "4 pass-1 samples per texel|--mc-min 4"
    "LDI oversample 0.7|--oversample 0.7"
    "LDI oversample 1.4|--oversample 1.4"
    "fp = 1.33 (exact for 60°)|--perspective 1.3333333"
    "box pixel filter (no monitor Gaussian)|--pixel-sigma 0"
)
files=()
labels=()
for i in "${!VARIANTS[@]}"; do
    label=${VARIANTS[$i]%%|*}
    opts=${VARIANTS[$i]#*|}
    # shellcheck disable=SC2086
    [ -f "var_$i.json" ] || "$VISTA" bake city.osgb -o "var_$i.osgb" --cells 3 --storage-budget off --jobs 2 --stats "var_$i.json" -q $opts
    files+=("var_$i.osgb")
    labels+=("$label")
done
[ -f var_report.json ] || "$REPORT" --cell 3 --frames 10 --ssaa 4 --baked "${files[@]}" --label "${labels[@]}" --json var_report.json > /dev/null
echo "### What accuracy costs (cell 3)"
echo
echo "Commands: \`vista bake city.osgb -o var_K.osgb --cells 3 --storage-budget off --jobs 2 --stats var_K.json [option]\` per row, then"
echo "\`xvfb-run -a vista_bake_report --cell 3 --frames 10 --ssaa 4 --baked var_0.osgb ... --json var_report.json\`."
echo "PSNR: median over 13 views (8 corners, 4 edge midpoints, centre) against the 4x4 supersampled replaced geometry."
echo
echo "| variant | option | bake s | MC rays | points | textured | MB | PSNR textured dB | PSNR points only dB | PSNR geometry dB |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for i in "${!VARIANTS[@]}"; do
    opts=${VARIANTS[$i]#*|}
    jq -r -n --slurpfile s "var_$i.json" --slurpfile r var_report.json --arg o "${opts:-—}" --argjson k "$i" \
        "\$s[0].impostor_stats[0] as \$v | \$r[0][\$k] as \$p |
         \"| \(\$p.label) | \(\$o) | \(\$v.bake_s * 100 | round / 100) | \(\$v.mc_rays / 1e6 * 10 | round / 10) M | \(\$v.points) | \(\$v.textured_points) | \(\$v.memory_mb * 100 | round / 100) | \(\$p.psnr_imp_db | $med * 100 | round / 100) | \(\$p.psnr_pts_db | $med * 100 | round / 100) | \(\$p.psnr_geom_db | $med * 100 | round / 100) |\""
done
echo

# ---- Antialiasing: impostor vs plain geometry per view position
echo "### Antialiasing: PSNR against the 4x4 supersampled reference per view position"
echo
echo "Same renders as above (cells of Table 5.1 and cell 3 with the default bake)."
echo
echo "| cell | view | plain geometry dB | impostor textured dB | impostor points only dB |"
echo "|---|---|---|---|---|"
for c in 3 $T51; do
    f="t51_${c}_report.json"; k=0
    [ "$c" = 3 ] && f=var_report.json
    jq -r --arg c "$c" --argjson k "$k" '.[$k] as $p | range(0; $p.views | length) as $i |
        "| \($c) | \($p.views[$i]) | \($p.psnr_geom_db[$i] * 100 | round / 100) | \($p.psnr_imp_db[$i] * 100 | round / 100) | \($p.psnr_pts_db[$i] * 100 | round / 100) |"' "$f"
done | awk -F'|' '{ print; n++; if ($5 + 0 > $4 + 0) better++ } END { printf "\nViews where the textured impostor is closer to the reference than plain geometry: %d of %d.\n", better, n }'
echo

[ "$WHOLE" = "--whole" ] || exit 0
# ---- Whole-city bake, placement trade-off, walkthrough
[ -f whole.json ] || "$VISTA" bake city.osgb -o city.baked.osgb --jobs 2 --stats whole.json
echo "### Whole-city bake"
echo
echo "Command: \`vista bake city.osgb -o city.baked.osgb --jobs 2 --stats whole.json\`"
echo
jq -r '. as $w | .impostor_stats as $s |
  "| cells | impostors | points | impostor data (MB) | output file (MB) | wall time (s) | cell bake time, sum (s) | per impostor: median bake s / points / points per px |",
  "|---|---|---|---|---|---|---|---|",
  "| \($w.cells) | \($w.impostors) | \($w.points) | \([$s[].memory_mb] | add | round) | \($w.output_bytes / 1048576 | round) | \($w.wall_s | round) | \($w.cell_bake_s_sum | round) | \([$s[].bake_s] | '"$med"' * 100 | round / 100) / \([$s[].points] | '"$med"') / \([$s[].points_per_screen_pixel] | '"$med"' * 100 | round / 100) |"' whole.json
echo
echo "Placement: impostors only at street ends whose far field has at least T triangles"
echo "(\`--min-triangles T\`; the rest draw their far geometry), from the same statistics:"
echo
echo "| T | impostors | impostor data (MB) | cell bake time (s) |"
echo "|---|---|---|---|"
for t in 2000 100000 150000 200000 300000; do
    jq -r --argjson t "$t" '[.impostor_stats[] | select(.far_triangles >= $t)] as $s |
        "| \($t) | \($s | length) | \([$s[].memory_mb] | add // 0 | round) | \([$s[].bake_s] | add // 0 | round) |"' whole.json
done
echo
[ -f car.csv ] || "$VISTA" path city.osgb --seed 1 -o car.csv
[ -f bench/summary.json ] || "$VISTA" bench city.osgb --baked city.baked.osgb --path car.csv --frames 120 --size 640x480 \
    --modes full,impostor --out bench -q
echo "Walkthrough: \`$(jq -r .command bench/summary.json)\`"
echo
echo "| mode | median frame (ms) | p95 frame (ms) | speedup vs full (median of same-frame ratios) | PSNR vs full, median (dB) |"
echo "|---|---|---|---|---|"
jq -r '.mode_order[] as $m | .modes[$m] | "| \($m) | \(.frame_ms_median * 10 | round / 10) | \(.frame_ms_p95 * 10 | round / 10) | \(.speedup_vs_full_median_of_ratios * 100 | round / 100) | \(.psnr_db_median * 10 | round / 10) |"' bench/summary.json
