#!/usr/bin/env bash
# Measures the OSM building import for docs/buildings.md "Buildings from OSM":
# `vista gen --osm FILE` with --osm-buildings on and off, interleaved (on off on
# off ...) RUNS times each, prints a Markdown table (median seconds over the
# runs; counts from the stats JSON, identical between runs) on stdout.
#
# usage: docs/tools/osm_buildings.sh [OSM_FILE] [RUNS] [VISTA_BIN] [-- gen args]
#   OSM_FILE  default tests/data/osm/town.osm (the largest OSM fixture)
#   RUNS      default 5;  VISTA_BIN default build/vista
#   gen args  default: --size 1000 --threads 0
# Needs python3. A few seconds per run on 2 cores.
set -euo pipefail
REPO=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
OSM=${1:-$REPO/tests/data/osm/town.osm}
RUNS=${2:-5}
VISTA=$(realpath -m "${3:-$REPO/build/vista}")
shift 3 2>/dev/null || shift $#
[ "${1:-}" = "--" ] && shift
ARGS=("$@")
[ ${#ARGS[@]} -gt 0 ] || ARGS=(--size 1000 --threads 0)
[ -x "$VISTA" ] || { echo "osm_buildings.sh: vista binary not found: $VISTA" >&2; exit 1; }
OUT=$(mktemp -d /tmp/vista-osmb.XXXXXX)
trap 'rm -rf "$OUT"' EXIT
for ((r = 0; r < RUNS; ++r)); do
  for mode in on off; do
    "$VISTA" gen --osm "$OSM" --osm-buildings "$mode" "${ARGS[@]}" -q -o "$OUT/c.osgb" --stats "$OUT/$mode.$r.json" 2>/dev/null
  done
done
python3 - "$OUT" "$RUNS" "$(basename "$OSM")" "${ARGS[*]}" <<'PY'
import json, statistics, sys
out, runs, name, args = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4]
def load(mode):
    return [json.load(open(f"{out}/{mode}.{r}.json")) for r in range(runs)]
rows = {m: load(m) for m in ("on", "off")}
def med(js, f):
    return statistics.median(f(j) for j in js)
print(f"`vista gen --osm {name} {args} --osm-buildings on|off --stats s.json`, median of {runs} interleaved runs:\n")
print("| --osm-buildings | buildings (imported + procedural) | lots | triangles | osm import s | buildings stage s | total s |")
print("|---|---|---|---|---|---|---|")
for m in ("on", "off"):
    js = rows[m]; j = js[0]
    imp = j.get("osm_buildings", {}).get("imported", 0)
    st = lambda k: med(js, lambda x: x["seconds"]["stages"].get(k, 0.0))
    print(f"| {m} | {j['buildings']} ({imp} + {j['buildings'] - imp}) | {j['lots']} | {j['triangles']:,} | "
          f"{st('osm import'):.3f} | {st('buildings'):.4f} | {med(js, lambda x: x['seconds']['total']):.2f} |")
o = rows["on"][0]["osm_buildings"]
print()
print(f"Footprints: {o['candidates']} candidates ({o['ways']} ways, {o['relations']} relations), {o['imported']} imported; "
      "repaired: " + ", ".join(f"{k} {v}" for k, v in o["repaired"].items()) + "; skipped: " +
      ", ".join(f"{k} {v}" for k, v in o["skipped"].items()) + ".  ")
print("Heights: " + ", ".join(f"{k} {v}" for k, v in o["height"].items()) + "; roofs: " +
      ", ".join(f"{k} {v}" for k, v in o["roof"].items()) + f"; lots dropped {o['lots_dropped']}, on a carriageway {o['on_carriageway']}.")
PY
