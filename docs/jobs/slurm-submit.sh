#!/usr/bin/env bash
# Submits a vista job array and its merge to Slurm:
#   docs/jobs/slurm-submit.sh gen  N OUT.paged [vista gen args...]
#   docs/jobs/slurm-submit.sh bake N OUT.baked.osgb CITY.osgb [vista bake args...]
#   docs/jobs/slurm-submit.sh render N OUT --dataset M.json   (or: CITY [vista render args...])
# OUT (and CITY) must be on storage every node sees, and so must this
# directory (the merge calls this script to submit missing shards again).
# The array runs shard K/N as task K; the merge (--dependency=afterany)
# starts once every task has ended, however it ended, and submits the shards
# that are not done again with a new merge (VISTA_MAX_ROUNDS). Logs go to
# OUT.logs/ (shard-ARRAYJOB_K.log, merge-JOBID.log), created here. Prints the
# two job ids. To stop a run, cancel both: scancel ARRAYJOB MERGEJOB.
#
# Optional environment:
#   VISTA_SBATCH_OPTS        more sbatch options for both jobs, split at white
#                            space (e.g. "--partition=long --account=maps --time=04:00:00")
#   VISTA_MERGE_SBATCH_OPTS  more sbatch options for the merge only
#   VISTA_SHARD_LIST         the shards to run (again), as sbatch --array takes
#                            them ("2,5", "3-4"; default 1-N); the merge waits for them
#   VISTA_MERGE_MEM          the merge's memory, as sbatch --mem takes it
#                            (default gen and render: 1G; bake: 2 GB + 4 x the city file)
#   VISTA_LOGS               the log directory (default OUT.logs)
#   VISTA_MAX_ROUNDS         how often a merge submits missing shards again
#                            (default 2; 0: never, it names them and exits 2)
#   VISTA, VISTA_MAX_RESTARTS  passed to the jobs (see slurm-array.sbatch)
# Slurm's own input variables (SBATCH_PARTITION, SBATCH_ACCOUNT,
# SBATCH_TIMELIMIT, ...) apply too; VISTA_SBATCH_OPTS wins over them.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
usage="usage: $0 gen|bake|render N OUT [CITY] [vista args...]"
[ $# -ge 3 ] || { echo "$usage" >&2; exit 2; }
job=$1 n=$2 out=$3
shift 3
case "$n" in '' | *[!0-9]*) echo "slurm-submit: N='$n' is not a whole number >= 1" >&2; exit 2 ;; esac
[ "$n" -ge 1 ] || { echo "slurm-submit: N=$n out of range (>= 1)" >&2; exit 2; }
city=""
case "$job" in
  gen | render) ;;
  bake)
    [ $# -ge 1 ] || { echo "slurm-submit: bake needs CITY ($usage)" >&2; exit 2; }
    city=$1
    shift
    [ -f "$city" ] || { echo "slurm-submit: CITY='$city' is not a file" >&2; exit 2; }
    ;;
  *) echo "slurm-submit: job '$job' (expected gen, bake or render)" >&2; exit 2 ;;
esac
tasks="${VISTA_SHARD_LIST:-1-$n}"
if ! [[ "$tasks" =~ ^[0-9]+(-[0-9]+)?(,[0-9]+(-[0-9]+)?)*$ ]]; then
  echo "slurm-submit: VISTA_SHARD_LIST='$tasks': expected shard numbers and ranges like 2,5,7-9" >&2; exit 2
fi
for k in ${tasks//[,-]/ }; do
  if [ "$k" -lt 1 ] || [ "$k" -gt "$n" ]; then
    echo "slurm-submit: VISTA_SHARD_LIST='$tasks': shard $k outside 1..$n" >&2; exit 2
  fi
done
# Absolute paths: the jobs start in the submit directory, but on other nodes.
abs() { case "$1" in /*) echo "$1" ;; *) echo "$PWD/$1" ;; esac; }
out="$(abs "${out%/}")"
[ -n "$city" ] && city="$(abs "$city")"
logs="$(abs "${VISTA_LOGS:-$out.logs}")"
mkdir -p "$logs"  # Slurm does not create the directory of --output: without it a job has no log
if [ -n "${VISTA_MERGE_MEM:-}" ]; then
  merge_mem="$VISTA_MERGE_MEM"
elif [ "$job" = bake ]; then
  # The bake merge holds the city, every cell result and the assembled scene.
  merge_mem="$((2048 + 4 * ($(stat -c %s "$city") / 1048576)))M"
else
  merge_mem=1G
fi
read -r -a opts <<<"${VISTA_SBATCH_OPTS:-}"
read -r -a merge_opts <<<"${VISTA_MERGE_SBATCH_OPTS:-}"

export VISTA_JOB="$job" VISTA_SHARDS="$n" VISTA_OUT="$out" VISTA_CITY="$city" VISTA_ARGS="$*"
export VISTA_SUBMIT="$here/slurm-submit.sh" VISTA_ROUND="${VISTA_ROUND:-0}"
array=$(sbatch --parsable --array="$tasks" --output="$logs/shard-%A_%a.log" --export=ALL \
  ${opts[@]+"${opts[@]}"} "$here/slurm-array.sbatch")
array="${array%%;*}"
merge=$(VISTA_ARRAY_JOB="$array" sbatch --parsable --dependency="afterany:$array" --mem="$merge_mem" \
  --output="$logs/merge-%j.log" --export=ALL ${opts[@]+"${opts[@]}"} ${merge_opts[@]+"${merge_opts[@]}"} \
  "$here/slurm-merge.sbatch")
merge="${merge%%;*}"
echo "array job $array (shards $tasks of $n), merge job $merge; logs in $logs"
