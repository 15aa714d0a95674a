#!/bin/sh
# Checks the traffic directory DIR against its lights (traffic_signals_check.py:
# no vehicle crosses a red light, some stop at one), then rides the first
# vehicle that stopped at a red light with `vista path --traffic DIR --ego ID`
# and checks that the path stands still through each of its red stops.
# Exit 77 (ctest: skipped) when SUMO is not installed.
# Usage: traffic_ego_red.sh VISTA CITY DIR
set -eu
vista=$1 city=$2 dir=$3
command -v sumo >/dev/null 2>&1 || { echo "SUMO is not installed: skipped"; exit 77; }
here=$(dirname "$0")
python3 "$here/traffic_signals_check.py" "$dir" --json "$dir.signals.json" >/dev/null || {
  cat "$dir.signals.json" 2>/dev/null; exit 1; }
ego=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["vehicles_with_red_stops"][0])' "$dir.signals.json")
rm -f "$dir.ego.csv"
"$vista" path "$city" --traffic "$dir" --ego "$ego" --duration 600 -o "$dir.ego.csv"
exec python3 "$here/traffic_signals_check.py" "$dir" --ego "$ego" --path "$dir.ego.csv"
