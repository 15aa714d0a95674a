#!/bin/sh
# Runs `vista traffic` on CITY into OUT (replaced) and checks it with
# traffic_check.py. Exit 77 (ctest: skipped) when SUMO is not installed.
# Usage: traffic_on_lanes.sh VISTA CITY OUT [vista traffic options...]
set -eu
vista=$1 city=$2 out=$3
shift 3
command -v sumo >/dev/null 2>&1 || { echo "SUMO is not installed: skipped"; exit 77; }
rm -rf "$out"
"$vista" traffic "$city" -o "$out" -q "$@"
exec python3 "$(dirname "$0")/traffic_check.py" "$out" --json "$out.check.json"
