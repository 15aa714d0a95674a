#!/usr/bin/env bash
# Regenerates the counts table of docs/formats.md "OpenDRIVE": the default city
# (data/default.json) and two OSM imports (tests/data/osm/hard_cases.osm and the
# synthetic town tests/data/osm/town.osm with its building footprints) are
# written with --xodr, read by SUMO netconvert, and their roads, junctions and
# lanes counted on both sides; the independent checker tests/tools/xodr_check.py
# adds its continuity columns (linked lane borders more than 1 cm apart in plan
# or 2 cm in height, the worst plan gap, heading kinks over 0.5 degrees, lane
# borders folding over their centre of curvature, driving lanes without a
# successor) and the signal and object counts, and xmllint the errors against
# the ASAM OpenDRIVE 1.6 schema when VISTA_OPENDRIVE_XSD names
# opendrive_16_core.xsd or its folder ("n/a" otherwise: the schema is not
# shipped with vista). Prints the Markdown table on stdout.
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
XSD=""
if [ -n "${VISTA_OPENDRIVE_XSD:-}" ]; then
  XSD=$VISTA_OPENDRIVE_XSD
  [ -d "$XSD" ] && XSD=$XSD/opendrive_16_core.xsd
  [ -f "$XSD" ] || die "VISTA_OPENDRIVE_XSD: no schema at $XSD"
  command -v xmllint >/dev/null || die "xmllint (Debian package libxml2-utils) is needed for the schema column"
fi

check() {  # NAME: runs the checker (exit 1 = some check fails, which the table reports) and the schema
  local rc=0
  python3 tests/tools/xodr_check.py "$OUT/$1.xodr" --json "$OUT/$1.check.json" -q >/dev/null || rc=$?
  [ "$rc" -le 1 ] || die "xodr_check.py could not read $OUT/$1.xodr"
  if [ -n "$XSD" ]; then
    xmllint --noout --schema "$XSD" "$OUT/$1.xodr" 2>"$OUT/$1.schema.log" >/dev/null || true
    grep -c "validity error" "$OUT/$1.schema.log" >"$OUT/$1.schema.count" || true
  else
    echo "n/a" >"$OUT/$1.schema.count"
  fi
}

row() {  # NAME XODR NETLOG NET CHECK_JSON SCHEMA_COUNT
  python3 - "$@" <<'PY'
import json, re, sys, xml.etree.ElementTree as ET
name, xodr, log, net, check, schema = sys.argv[1:7]
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
c = json.load(open(check))
k = c["checks"]
worst = k["gaps"]["worst"] or 0.0
print(f"| {name} | {len(roads)} | {len(junctions)} | {len(conn)} | {lanes} | {walks} | {len(nj)} | {len(ne)} | {nl} "
      f"| {errors} | {warnings} | {open(schema).read().strip()} | {k['gaps']['failures']} | {worst:.3f} m "
      f"| {k['kinks']['failures']} | {k['folds']['failures']} | {k['unlinked']['failures']} "
      f"| {c['counts']['signals']} | {c['counts']['objects']} |")
PY
}

log "default city"
"$VISTA" gen --params data/default.json -q -o "$OUT/default.osgb" --xodr "$OUT/default.xodr"
netconvert --opendrive-files "$OUT/default.xodr" -o "$OUT/default.net.xml" >"$OUT/default.log" 2>&1
check default
log "OSM import"
"$VISTA" gen --osm tests/data/osm/hard_cases.osm -q -o "$OUT/osm.osgb" --xodr "$OUT/osm.xodr"
netconvert --opendrive-files "$OUT/osm.xodr" -o "$OUT/osm.net.xml" >"$OUT/osm.log" 2>&1
check osm
log "OSM town"
"$VISTA" gen --osm tests/data/osm/town.osm -q -o "$OUT/town.osgb" --xodr "$OUT/town.xodr"
netconvert --opendrive-files "$OUT/town.xodr" -o "$OUT/town.net.xml" >"$OUT/town.log" 2>&1
check town
echo "| city | roads | junctions | connecting roads | driving lanes | sidewalk lanes | netconvert junctions | netconvert edges | netconvert lanes | netconvert errors | netconvert warnings | schema errors | gaps > 1 cm | worst gap | kinks | folds | unlinked lanes | signals | objects |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
row "default (\`data/default.json\`)" "$OUT/default.xodr" "$OUT/default.log" "$OUT/default.net.xml" "$OUT/default.check.json" "$OUT/default.schema.count"
row "OSM import (\`tests/data/osm/hard_cases.osm\`)" "$OUT/osm.xodr" "$OUT/osm.log" "$OUT/osm.net.xml" "$OUT/osm.check.json" "$OUT/osm.schema.count"
row "OSM town (\`tests/data/osm/town.osm\`, streets + buildings)" "$OUT/town.xodr" "$OUT/town.log" "$OUT/town.net.xml" "$OUT/town.check.json" "$OUT/town.schema.count"
log "done"
