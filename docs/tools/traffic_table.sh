#!/usr/bin/env bash
# Regenerates the table of docs/measurements/traffic.md: `vista traffic` with
# its defaults (300 vehicles, 300 pedestrians, 600 s, 0.5 s steps) on the
# default 2 km city and the OSM town (tests/data/osm/town.osm), seeds 1 to 3.
# Per run: the seconds of each stage (netconvert, demand, sumo; from the
# progress lines), SUMO's collisions (statistics.xml) and its collision records
# by victim (collisions.xml: vehicle-pedestrian, vehicle-vehicle) and
# teleports, the share of vehicle
# samples within 10 cm of a lane centre evaluated from the .xodr
# (tests/tools/traffic_check.py), red-light crossings and stops
# (tests/tools/traffic_signals_check.py) and whether a second run with the
# same seed gives the same bytes. Writes the block between the traffic
# markers of docs/measurements/traffic.md.
# Usage: docs/tools/traffic_table.sh [OUT_DIR] [VISTA_BINARY]
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
doc_setup traffic_table traffic 640x480x24 "$@"
command -v sumo >/dev/null || die "sumo (Debian packages sumo, sumo-tools) is needed"
mkdir -p "$OUT"
DOC=docs/measurements/traffic.md
DOC_TMP_FILES+=("docs/measurements/.traffic.md.tmp")

[ -f "$OUT/default.osgb" ] || "$VISTA" gen -q -o "$OUT/default.osgb"
[ -f "$OUT/town.osgb" ] || "$VISTA" gen -q --osm tests/data/osm/town.osm -o "$OUT/town.osgb"

table="$OUT/table.md"
{
  echo "| city | seed | netconvert (s) | demand (s) | sumo (s) | vehicles | pedestrians | collisions | records veh–ped | records veh–veh | teleports | samples within 10 cm | red crossings | red stops | same bytes |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
} >"$table"
for city in default town; do
  for seed in 1 2 3; do
    run="$OUT/$city.s$seed"
    rm -rf "$run" "$run.again"
    log "$city seed $seed"
    "$VISTA" traffic "$OUT/$city.osgb" -o "$run" --seed "$seed" 2>"$run.log"
    "$VISTA" traffic "$OUT/$city.osgb" -o "$run.again" --seed "$seed" -q
    same=yes
    for f in "$run"/*; do cmp -s "$f" "$run.again/$(basename "$f")" || same=no; done
    python3 tests/tools/traffic_check.py "$run" --json "$run.lanes.json" >/dev/null || true
    python3 tests/tools/traffic_signals_check.py "$run" --json "$run.signals.json" >/dev/null || true
    python3 - "$city" "$seed" "$run" "$same" >>"$table" <<'PYEOF'
import json, re, sys
city, seed, run, same = sys.argv[1:5]
log = open(run + ".log").read()
def stage(name):
    m = re.search(r"traffic: " + name + r"[^\n]* done in ([0-9.]+)s", log)
    return m.group(1) if m else "?"
t = json.load(open(run + "/traffic.json"))
lanes = json.load(open(run + ".lanes.json"))
sig = json.load(open(run + ".signals.json"))
s = t["sumo"]
ev = s.get("collision_events", {})
print(f"| {city} | {seed} | {stage('network')} | {stage('demand')} | {stage('simulation')} | "
      f"{s['vehicles_inserted']} | {s['persons_loaded']} | {s['collisions']} | {ev.get('vehicle_pedestrian', '?')} | "
      f"{ev.get('vehicle_vehicle', '?')} | {s['teleports']} | "
      f"{100 * lanes['share_within']:.2f} % | {sig['red_crossings']} | {sig['red_stop_events']} | {same} |")
PYEOF
  done
done
doc_replace_block "$DOC" traffic "$table"
log "done: $DOC"
