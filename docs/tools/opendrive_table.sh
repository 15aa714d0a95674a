#!/usr/bin/env bash
# Regenerates the counts table of docs/formats.md "OpenDRIVE": the default city
# (data/default.json) and two OSM imports (tests/data/osm/hard_cases.osm and the
# synthetic town tests/data/osm/town.osm with its building footprints) are
# written with --xodr, read by SUMO netconvert, and their roads, junctions and
# lanes counted on both sides. Prints the Markdown table on stdout.
# Usage: docs/tools/opendrive_table.sh [OUT_DIR] [VISTA_BINARY]
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
doc_setup opendrive_table xodr 640x480x24 "$@"
command -v netconvert >/dev/null || die "netconvert (Debian package sumo) is needed"
if [ -z "${SUMO_HOME:-}" ]; then
  SUMO_HOME=$(dirname "$(dirname "$(realpath "$(command -v netconvert)")")")/share/sumo
  export SUMO_HOME
fi
mkdir -p "$OUT"

row() {  # NAME XODR NETLOG NET
  python3 - "$@" <<'PY'
import re, sys, xml.etree.ElementTree as ET
name, xodr, log, net = sys.argv[1:5]
x = ET.parse(xodr).getroot()
roads = [r for r in x.findall("road") if r.get("junction") == "-1"]
conn = [r for r in x.findall("road") if r.get("junction") != "-1"]
junctions = x.findall("junction")
lanes = sum(len([l for l in r.iter("lane") if l.get("type") == "driving"]) for r in roads)
walks = sum(len([l for l in r.iter("lane") if l.get("type") == "sidewalk"]) for r in roads)
n = ET.parse(net).getroot()
nj = [j for j in n.findall("junction") if j.get("type") != "internal" and re.fullmatch(r"\d+", j.get("id"))]
ne = [e for e in n.findall("edge") if e.get("function") != "internal"]
nl = sum(len(e.findall("lane")) for e in ne)
text = open(log).read()
errors = len(re.findall(r"^Error", text, re.M))
warnings = len(re.findall(r"^Warning", text, re.M))
print(f"| {name} | {len(roads)} | {len(junctions)} | {len(conn)} | {lanes} | {walks} | {len(nj)} | {len(ne)} | {nl} | {errors} | {warnings} |")
PY
}

log "default city"
"$VISTA" gen --params data/default.json -q -o "$OUT/default.osgb" --xodr "$OUT/default.xodr"
netconvert --opendrive-files "$OUT/default.xodr" -o "$OUT/default.net.xml" >"$OUT/default.log" 2>&1
log "OSM import"
"$VISTA" gen --osm tests/data/osm/hard_cases.osm -q -o "$OUT/osm.osgb" --xodr "$OUT/osm.xodr"
netconvert --opendrive-files "$OUT/osm.xodr" -o "$OUT/osm.net.xml" >"$OUT/osm.log" 2>&1
log "OSM town"
"$VISTA" gen --osm tests/data/osm/town.osm -q -o "$OUT/town.osgb" --xodr "$OUT/town.xodr"
netconvert --opendrive-files "$OUT/town.xodr" -o "$OUT/town.net.xml" >"$OUT/town.log" 2>&1
echo "| city | roads | junctions | connecting roads | driving lanes | sidewalk lanes | netconvert junctions | netconvert edges | netconvert lanes | netconvert errors | netconvert warnings |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
row "default (\`data/default.json\`)" "$OUT/default.xodr" "$OUT/default.log" "$OUT/default.net.xml"
row "OSM import (\`tests/data/osm/hard_cases.osm\`)" "$OUT/osm.xodr" "$OUT/osm.log" "$OUT/osm.net.xml"
row "OSM town (\`tests/data/osm/town.osm\`, streets + buildings)" "$OUT/town.xodr" "$OUT/town.log" "$OUT/town.net.xml"
log "done"
