#!/usr/bin/env bash
# Regenerates the two tables of docs/formats.md "OpenDRIVE": the default city
# (data/default.json), a hilly city (tests/data/xodr_hilly.json) and three OSM
# imports (tests/data/osm/town.osm with its building footprints, hard_cases.osm
# and lanes.osm with lane, one-way and speed tags) are written with --xodr,
# read by SUMO netconvert, and their roads, junctions, lanes and traffic lights
# counted on both sides; the independent checker tests/tools/xodr_check.py
# adds its continuity columns (linked lane borders more than 1 cm apart in plan
# or 2 cm in height, the worst plan gap, heading kinks over 0.5 degrees, lane
# borders folding over their centre of curvature, driving lanes without a
# successor or, leaving a junction, without a connecting lane into them;
# signal failures: validity order, codes, controller grouping, crosswalk
# outlines) and the signal and object counts, and xmllint the errors against
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

row() {  # NAME KEY: one row of each table (written to KEY.counts / KEY.checks)
  python3 - "$1" "$OUT/$2" <<'PY2'
import json, re, sys, xml.etree.ElementTree as ET
name, base = sys.argv[1:3]
x = ET.parse(base + ".xodr").getroot()
street = [r for r in x.findall("road") if r.get("junction") == "-1" and not r.get("name", "").startswith("transition")]
trans = [r for r in x.findall("road") if r.get("junction") == "-1" and r.get("name", "").startswith("transition")]
conn = [r for r in x.findall("road") if r.get("junction") != "-1"]
junctions = x.findall("junction")
lanes = sum(len([l for l in r.iter("lane") if l.get("type") == "driving"]) for r in street)
walks = sum(len([l for l in r.iter("lane") if l.get("type") == "sidewalk"]) for r in street)
signals = [s for r in x.findall("road") for s in r.iter("signal")]
lights = [s for s in signals if s.get("dynamic") == "yes"]
lit = {j.get("id") for j in junctions if j.find("controller") is not None}
n = ET.parse(base + ".net.xml").getroot()
nj = [j for j in n.findall("junction") if j.get("type") != "internal" and re.fullmatch(r"\d+", j.get("id"))]
ne = [e for e in n.findall("edge") if e.get("function") != "internal"]
nl = sum(len(e.findall("lane")) for e in ne)
text = open(base + ".log").read()
errors = len(re.findall(r"^Error", text, re.M))
warnings = len(re.findall(r"^Warning", text, re.M))
unconnected = re.findall(r"not connected (?:from any incoming|to any outgoing) edge at junction '([^']*)'", text)
at_junctions = sum(1 for j in unconnected if re.fullmatch(r"\d+", j))
c = json.load(open(base + ".check.json"))
k = c["checks"]
schema = open(base + ".schema.count").read().strip()
with open(base + ".counts", "w") as f:
    f.write(f"| {name} | {len(street)} | {len(trans)} | {len(junctions)} | {len(conn)} | {lanes} | {walks} "
            f"| {len(lights)} at {len(lit)} | {len(signals) - len(lights)} | {c['counts']['objects']} "
            f"| {len(nj)} | {len(ne)} | {nl} | {len(n.findall('tlLogic'))} | {errors} | {warnings} "
            f"| {at_junctions} / {len(unconnected) - at_junctions} |\n")
worst = k["gaps"]["worst"] or 0.0
with open(base + ".checks", "w") as f:
    f.write(f"| {name} | {schema} | {k['gaps']['failures']} of {k['gaps']['checked']} | {worst * 1000:.1f} mm "
            f"| {k['kinks']['failures']} of {k['kinks']['checked']} | {k['folds']['failures']} "
            f"| {k['unlinked']['failures']} of {k['unlinked']['checked']} | {k['references']['failures']} "
            f"| {k['signals']['failures']} of {k['signals']['checked']} |\n")
PY2
}

city() {  # KEY LABEL GEN_ARGS...
  local key=$1 label=$2
  shift 2
  log "$label"
  rm -f "$OUT/$key.osgb" "$OUT/$key.xodr"
  "$VISTA" gen "$@" -q -o "$OUT/$key.osgb" --xodr "$OUT/$key.xodr"
  netconvert --aggregate-warnings -1 --opendrive-files "$OUT/$key.xodr" -o "$OUT/$key.net.xml" >"$OUT/$key.log" 2>&1
  check "$key"
  row "$label" "$key"
}

city default "default (\`data/default.json\`)" --params data/default.json
city hilly "hilly (\`tests/data/xodr_hilly.json\`, 25 m hills)" --params tests/data/xodr_hilly.json
city town "OSM town (\`tests/data/osm/town.osm\`)" --osm tests/data/osm/town.osm
city osm "OSM hard cases (\`tests/data/osm/hard_cases.osm\`)" --osm tests/data/osm/hard_cases.osm
city lanes "OSM lane tags (\`tests/data/osm/lanes.osm\`)" --osm tests/data/osm/lanes.osm
KEYS="default hilly town osm lanes"
echo "| city | roads | transitions | junctions | connecting roads | driving lanes | sidewalk lanes | traffic lights (at junctions) | signs | crosswalks | netconvert junctions | netconvert edges | netconvert lanes | netconvert traffic lights | netconvert errors | netconvert warnings | lanes "not connected" (at junctions / at transitions) |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for k in $KEYS; do cat "$OUT/$k.counts"; done
echo
echo "| city | schema errors | linked lane borders > 1 cm apart | worst gap | heading kinks > 0.5 deg | folding borders | driving lanes without a connection (incl. junction exits) | broken references | signal failures |"
echo "|---|---|---|---|---|---|---|---|---|"
for k in $KEYS; do cat "$OUT/$k.checks"; done
log "done"
