#!/usr/bin/env bash
# Two writers racing on one output, TRIALS times per command: `vista path`
# (two seeds into one CSV) and a paged `vista gen` (two seeds into one
# directory, 1 km city, 500 m regions). A trial is right when exactly one
# writer exits 0, the other exits 2, and the output is the winner's own
# (byte-equal to the winner's seed written alone; for the paged city, its
# manifest names the winner's seed and a rerun of that seed regenerates no
# region). Prints one TSV row per command: command, trials, one winner and
# the winner's output, mixed outputs, other outcomes.
# Usage: docs/tools/race_trials.sh [TRIALS] [VISTA_BINARY]
set -euo pipefail
TRIALS="${1:-50}"
VISTA=$(realpath -m "${2:-build/vista}")
[ -x "$VISTA" ] || { echo "race_trials: error: $VISTA is not an executable" >&2; exit 1; }
W=$(mktemp -d /tmp/vista-race.XXXXXX)
trap 'rm -rf "$W"' EXIT
cd "$W"
"$VISTA" gen --size 800 -q -o c.osgb
for s in 1 2; do "$VISTA" path c.osgb --kind car --seed "$s" --duration 60 -o "ref$s.csv" 2>/dev/null; done
race() {  # race CMD1 CMD2 -> sets r1 r2
  set +e
  eval "$1" 2>/dev/null & local p1=$!
  eval "$2" 2>/dev/null & local p2=$!
  wait $p1; r1=$?
  wait $p2; r2=$?
  set -e
}
printf "command\ttrials\tone_winner\tmixed\tother\n"
ok=0 mix=0 other=0
for _ in $(seq "$TRIALS"); do
  rm -f out.csv
  race "'$VISTA' path c.osgb --kind car --seed 1 --duration 60 -o out.csv" \
       "'$VISTA' path c.osgb --kind car --seed 2 --duration 60 -o out.csv"
  if [ $((r1 == 0)) -ne $((r2 == 0)) ] && { [ "$r1" -eq 2 ] || [ "$r2" -eq 2 ]; }; then
    w=1; [ "$r2" -eq 0 ] && w=2
    if cmp -s out.csv "ref$w.csv"; then ok=$((ok + 1)); else mix=$((mix + 1)); fi
  else
    other=$((other + 1))
  fi
done
printf "path\t%s\t%s\t%s\t%s\n" "$TRIALS" "$ok" "$mix" "$other"
ok=0 mix=0 other=0
gen="--size 1000 --detail 1 --region-size 500 -q -o race.paged"
for _ in $(seq "$TRIALS"); do
  rm -rf race.paged
  race "'$VISTA' gen $gen --seed 1" "'$VISTA' gen $gen --seed 2"
  if [ $((r1 == 0)) -ne $((r2 == 0)) ] && { [ "$r1" -eq 2 ] || [ "$r2" -eq 2 ]; }; then
    w=1; [ "$r2" -eq 0 ] && w=2
    if grep -q "\"seed\": $w" race.paged/manifest.json &&
       "$VISTA" gen $gen --seed "$w" --stats again.json 2>/dev/null &&
       grep -q '"regions_generated": 0' again.json; then ok=$((ok + 1)); else mix=$((mix + 1)); fi
  else
    other=$((other + 1))
  fi
done
printf "paged gen\t%s\t%s\t%s\t%s\n" "$TRIALS" "$ok" "$mix" "$other"
