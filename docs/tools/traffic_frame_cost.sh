#!/usr/bin/env bash
# What drawing SUMO's traffic costs a frame: `vista bench --modes full,hybrid` over the
# same frames of an ego ride with and without `--traffic`, ROUNDS times alternating (default 3),
# on the default 2 km city with `vista traffic`'s defaults (300 vehicles, 300 pedestrians,
# 600 s). Per round and frame: hybrid's frame time with traffic over the same frame's without
# (the figure is the median over all rounds' frames of that same-frame ratio), and hybrid's PSNR
# against `full` of the same run (with traffic against full with traffic). Writes the block
# between the traffic-cost markers of docs/measurements/traffic.md.
# Usage: docs/tools/traffic_frame_cost.sh [OUT_DIR] [VISTA_BINARY]   (FRAMES=300, ROUNDS=3)
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
doc_setup traffic_frame_cost traffic_cost 1280x1024x24 "$@"
command -v sumo >/dev/null || die "sumo (Debian packages sumo, sumo-tools) is needed"
mkdir -p "$OUT"
DOC=docs/measurements/traffic.md
DOC_TMP_FILES+=("docs/measurements/.traffic.md.tmp")
FRAMES="${FRAMES:-300}"
ROUNDS="${ROUNDS:-3}"

[ -f "$OUT/city.osgb" ] || "$VISTA" gen -q -o "$OUT/city.osgb"
[ -d "$OUT/city.traffic" ] || "$VISTA" traffic "$OUT/city.osgb" -o "$OUT/city.traffic" --seed 1 -q
# The ego: the vehicle that drives longest in the run (a ride through many junctions).
ego=$(python3 - "$OUT/city.traffic/fcd.xml" <<'PY'
import sys, xml.etree.ElementTree as ET
seen = {}
for _, el in ET.iterparse(sys.argv[1]):
    if el.tag == "vehicle" and el.get("type") == "car":
        seen[el.get("id")] = seen.get(el.get("id"), 0) + 1
    el.clear()
print(max(seen, key=lambda k: (seen[k], k)))
PY
)
[ -f "$OUT/ego.csv" ] || "$VISTA" path "$OUT/city.osgb" --traffic "$OUT/city.traffic" --ego "$ego" -o "$OUT/ego.csv"
log "ego $ego"
for r in $(seq "$ROUNDS"); do
  for side in none traffic; do
    run="$OUT/r$r.$side"
    [ -f "$run/frames.csv" ] && continue
    rm -rf "$run"
    extra=()
    [ "$side" = traffic ] && extra=(--traffic "$OUT/city.traffic")
    log "round $r, $side"
    "${XVFB[@]}" "$VISTA" bench "$OUT/city.osgb" --path "$OUT/ego.csv" --modes full,hybrid --frames "$FRAMES" \
      --sampling consecutive --allow-repeated-frames "${extra[@]}" --out "$run" -q
  done
done
table="$OUT/table.md"
python3 - "$OUT" "$ROUNDS" "$FRAMES" "$ego" > "$table" <<'PY'
import csv, statistics, sys
out, rounds, frames, ego = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4]
def rows(run, mode):
    return {int(r["frame"]): r for r in csv.DictReader(open(f"{out}/{run}/frames.csv")) if r["mode"] == mode}
ratios, psnr = [], {"none": [], "traffic": []}
ms = {"none": [], "traffic": []}
for k in range(1, rounds + 1):
    a, b = rows(f"r{k}.none", "hybrid"), rows(f"r{k}.traffic", "hybrid")
    for f in sorted(set(a) & set(b)):
        ratios.append(float(b[f]["frame_ms"]) / float(a[f]["frame_ms"]))
    for side, r in (("none", a), ("traffic", b)):
        ms[side] += [float(x["frame_ms"]) for x in r.values()]
        psnr[side] += [float(x["psnr_db"]) for x in r.values() if x["psnr_db"] not in ("", "nan")]
med = statistics.median
print(f"Ego ride of `{ego}` (the car in the run the longest), {frames} consecutive frames, 640×480, {rounds} rounds.")
print()
print("| measure | without traffic | with traffic |")
print("|---|---|---|")
print(f"| hybrid median frame (ms) | {med(ms['none']):.2f} | {med(ms['traffic']):.2f} |")
print(f"| hybrid / same frame without traffic, median | 1 | {med(ratios):.3f} |")
print(f"| hybrid PSNR against `full` of the same run, median (dB) | {med(psnr['none']):.1f} | {med(psnr['traffic']):.1f} |")
print(f"| hybrid PSNR, 5th percentile (dB) | {statistics.quantiles(psnr['none'], n=20)[0]:.1f} | {statistics.quantiles(psnr['traffic'], n=20)[0]:.1f} |")
PY
doc_replace_block "$DOC" traffic-cost "$table"
log "done: $DOC"
