#!/usr/bin/env bash
# Regenerates the table "Cities by size" of docs/measurements/generation.md:
# generates cities of 0.5, 1, 2, 4, 8 km side (default params otherwise) and
# prints a Markdown table of triangles, seconds and peak memory from --stats.
# Usage: docs/tools/perf_table.sh [sizes...]   (default: 500 1000 2000 4000 8000)
set -euo pipefail
cd "$(dirname "$0")/../.."
VISTA="${VISTA:-build/vista}"
SIZES="${*:-500 1000 2000 4000 8000}"
TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT
echo "| side (m) | street edges | buildings | trees | triangles (rendered) | triangles (stored) | draw calls | file (MB) | seconds | peak RSS (MB) |"
echo "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
for s in $SIZES; do
  "$VISTA" gen --size "$s" --seed 1 -q --stats "$TMP/s$s.json" -o "$TMP/c$s.osgb"
  mb=$(du -m "$TMP/c$s.osgb" | cut -f1)
  python3 - "$TMP/s$s.json" "$mb" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
print(f"| {j['size_m']:.0f} | {j['street_edges']} | {j['buildings']} | {j['trees']} | {j['triangles']/1e6:.2f} M | {j['stored_triangles']/1e6:.2f} M | {j['draw_calls']} | {sys.argv[2]} | {j['seconds']['total']:.1f} | {j['peak_rss_mb']:.0f} |")
PY
  rm -f "$TMP/c$s.osgb"
done
