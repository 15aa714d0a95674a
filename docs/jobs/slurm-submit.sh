#!/usr/bin/env bash
# Submits a vista job array and its merge to Slurm:
#   docs/jobs/slurm-submit.sh gen  N OUT.paged [vista gen args...]
#   docs/jobs/slurm-submit.sh bake N OUT.baked.osgb CITY.osgb [vista bake args...]
# OUT (and CITY) must be on storage every node sees. Prints the two job ids.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
[ $# -ge 3 ] || { echo "usage: $0 gen|bake N OUT [CITY] [args...]" >&2; exit 2; }
job=$1 n=$2 out=$3; shift 3
case "$n" in ''|*[!0-9]*) echo "slurm-submit: N='$n' is not a whole number >= 1" >&2; exit 2 ;; esac
[ "$n" -ge 1 ] || { echo "slurm-submit: N=$n out of range (>= 1)" >&2; exit 2; }
city=""
if [ "$job" = bake ]; then [ $# -ge 1 ] || { echo "slurm-submit: bake needs CITY" >&2; exit 2; }; city=$1; shift; fi
[ "$job" = gen ] || [ "$job" = bake ] || { echo "slurm-submit: job '$job' (expected gen or bake)" >&2; exit 2; }
export VISTA_JOB="$job" VISTA_SHARDS="$n" VISTA_OUT="$out" VISTA_CITY="$city" VISTA_ARGS="$*"
array=$(sbatch --parsable --array="1-$n" --export=ALL "$here/slurm-array.sbatch")
merge=$(sbatch --parsable --dependency="afterok:${array%%;*}" --export=ALL "$here/slurm-merge.sbatch")
echo "array job $array, merge job $merge"
