#!/bin/sh
# Runs `vista traffic` with its defaults on CITY for each SEED into OUT.sSEED
# (replaced) and checks each with traffic_turns_check.py: no vehicle class on
# a junction turn tighter than its turning need, and at most MAX collisions
# reported by SUMO. Exit 77 (ctest: skipped) when SUMO is not installed.
# Usage: traffic_tight_turns.sh VISTA CITY OUT MAX SEED...
set -eu
vista=$1 city=$2 out=$3 max=$4
shift 4
command -v sumo >/dev/null 2>&1 || { echo "SUMO is not installed: skipped"; exit 77; }
status=0
for seed in "$@"; do
  rm -rf "$out.s$seed"
  "$vista" traffic "$city" -o "$out.s$seed" -q --seed "$seed"
  echo "seed $seed:"
  python3 "$(dirname "$0")/traffic_turns_check.py" "$out.s$seed" --max-collisions "$max" || status=1
  rm -rf "$out.s$seed"
done
exit $status
