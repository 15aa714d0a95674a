#!/usr/bin/env bash
# Measures the OpenDRIVE export on real OpenStreetMap extracts: each EXTRACT
# (an .osm/.osm.pbf, optionally followed by :SIZE to clip a SIZE-metre square
# about the extract's centre) is imported with `vista gen --osm --xodr
# --stats`, checked by the independent checker tests/tools/xodr_check.py
# (road pairs whose driving lanes overlap outside a common junction, driving
# lanes without a link, lane-centre radii on connecting roads under 5 m,
# folds, gaps), checked against the extract's one-way tags by
# tests/tools/osm_oneway_check.py (one-way ways with a road written with lanes
# in both directions or only against the way) and read by SUMO netconvert
# (errors, "not connected" lane warnings). Prints one Markdown table row per
# extract on stdout.
# An argument seed=N:SIZE measures the generated city `vista gen --seed N
# --size SIZE` instead (no OSM input: no one-way column).
# Usage: docs/tools/opendrive_real_maps.sh OUT_DIR VISTA_BINARY EXTRACT[:SIZE]|seed=N:SIZE...
set -euo pipefail
[ $# -ge 3 ] || { echo "usage: $0 OUT_DIR VISTA_BINARY EXTRACT[:SIZE]|seed=N:SIZE..." >&2; exit 2; }
OUT=$1 VISTA=$2
shift 2
command -v netconvert >/dev/null || { echo "netconvert (Debian package sumo) is needed" >&2; exit 2; }
export SUMO_HOME=${SUMO_HOME:-/usr/share/sumo}
CHECK=$(dirname "${BASH_SOURCE[0]}")/../../tests/tools/xodr_check.py
ONEWAY=$(dirname "${BASH_SOURCE[0]}")/../../tests/tools/osm_oneway_check.py
mkdir -p "$OUT"
echo "| extract | window | roads | junctions | joined edges | overlapping pairs | unlinked lanes | one-way ways two-way / against | radii < 5 m | folds | gaps | netconvert errors | not connected |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for arg in "$@"; do
  src=${arg%%:*} size=""
  [ "$arg" != "$src" ] && size=${arg#*:}
  name=$(basename "$src")
  name=${name%%.*}${size:+_$size}
  case "$src" in
    seed=*)
      seed=${src#seed=}
      [ -n "$seed" ] && [ -n "$size" ] || { echo "$arg: a generated city is seed=N:SIZE" >&2; exit 2; }
      name=seed${seed}_$size
      input=(--seed "$seed" --size "$size") ;;
    *) input=(--osm "$src" ${size:+--size "$size"}) ;;
  esac
  "$VISTA" gen "${input[@]}" --detail 0 -q -o "$OUT/$name.osgb" --xodr "$OUT/$name.xodr" \
    --stats "$OUT/$name.stats.json"
  rc=0
  python3 "$CHECK" "$OUT/$name.xodr" --json "$OUT/$name.check.json" -q >/dev/null || rc=$?
  [ "$rc" -le 1 ] || { echo "xodr_check.py could not read $OUT/$name.xodr" >&2; exit 1; }
  rc=0
  rm -f "$OUT/$name.oneway.json"
  case "$src" in
    seed=*) ;;
    *) python3 "$ONEWAY" "$src" "$OUT/$name.xodr" --json "$OUT/$name.oneway.json" -q >/dev/null || rc=$?
       [ "$rc" -le 1 ] || { echo "osm_oneway_check.py could not read $src or $OUT/$name.xodr" >&2; exit 1; } ;;
  esac
  netconvert --opendrive-files "$OUT/$name.xodr" -o "$OUT/$name.net.xml" >"$OUT/$name.netconvert.log" 2>&1 || true
  label=$(basename "$src")
  case "$src" in seed=*) label="generated, seed ${src#seed=}" ;; esac
  python3 - "$label" "${size:-whole}" "$OUT/$name" <<'PY'
import json, sys
src, window, base = sys.argv[1:4]
c = json.load(open(base + ".check.json"))["checks"]
s = json.load(open(base + ".stats.json"))["opendrive"]
try:
    o = json.load(open(base + ".oneway.json"))["checks"]
    oneway = f"{o['two_way']['failures']} / {o['against']['failures']}"
except FileNotFoundError:
    oneway = "–"
log = open(base + ".netconvert.log", errors="replace").read().splitlines()
errors = sum(1 for l in log if l.startswith("Error"))
loose = sum(1 for l in log if "not connected" in l)
print(f"| {src} | {window} | {s['roads']} | {s['junctions']} | {s['joined_edges']} | {c['overlaps']['failures']} | "
      f"{c['unlinked']['failures']} | {oneway} | {c['turn_radius']['failures']} | {c['folds']['failures']} | "
      f"{c['gaps']['failures']} | {errors} | {loose} |")
PY
done
