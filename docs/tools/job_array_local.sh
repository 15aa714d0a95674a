#!/usr/bin/env bash
# Proves the job-array recipes of docs/jobs/ here, without a cluster: runs
# docs/jobs/slurm-array.sbatch as N separate local processes at once (each
# with its own SLURM_ARRAY_TASK_ID, as Slurm would), then slurm-merge.sbatch,
# for a paged-city generation and for a bake, and compares the bytes with one
# unsharded run of the same command. Prints one line per job and exits 1 on
# any difference.
#   docs/tools/job_array_local.sh OUT [VISTA] [N]
set -euo pipefail
REPO="$(cd "$(dirname "$0")/../.." && pwd)"
OUT="${1:?usage: $0 OUT [VISTA] [N]}"
VISTA="$(realpath "${2:-$REPO/build/vista}")"
N="${3:-3}"
export VISTA
mkdir -p "$OUT"
OUT="$(realpath "$OUT")"
rm -rf "$OUT"/one.paged "$OUT"/arr.paged "$OUT"/one.baked.osgb* "$OUT"/arr.baked.osgb* "$OUT"/c.osgb "$OUT"/jobs.log

array() {  # array JOB: the N shards at once, then the merge; their logs in OUT/jobs.log
  local pids=() k
  for k in $(seq 1 "$N"); do
    SLURM_ARRAY_TASK_ID=$k bash "$REPO/docs/jobs/slurm-array.sbatch" 2>>"$OUT/jobs.log" & pids+=($!)
  done
  for p in "${pids[@]}"; do wait "$p" || { cat "$OUT/jobs.log" >&2; exit 1; }; done
  bash "$REPO/docs/jobs/slurm-merge.sbatch" 2>>"$OUT/jobs.log" || { cat "$OUT/jobs.log" >&2; exit 1; }
}

# Generation: a 1.5 km city in 500 m regions.
ARGS="--size 1500 --seed 3 --region-size 500"
"$VISTA" gen $ARGS -q -o "$OUT/one.paged"
VISTA_JOB=gen VISTA_SHARDS=$N VISTA_OUT="$OUT/arr.paged" VISTA_ARGS="$ARGS" array
# Every file: regions, coarse levels, records, index and manifest.
if diff -r "$OUT/one.paged" "$OUT/arr.paged" >/dev/null; then
  echo "gen: $N shards + merge = one run, byte for byte ($(find "$OUT/arr.paged" -type f | wc -l) files)"
else
  echo "gen: $N shards + merge DIFFER from one run" >&2; exit 1
fi

# Bake: a small city, N shards of its cells.
"$VISTA" gen --size 400 --seed 3 -q -o "$OUT/c.osgb"
"$VISTA" bake "$OUT/c.osgb" -q -o "$OUT/one.baked.osgb"
VISTA_JOB=bake VISTA_SHARDS=$N VISTA_OUT="$OUT/arr.baked.osgb" VISTA_CITY="$OUT/c.osgb" VISTA_ARGS="" array
if cmp -s "$OUT/one.baked.osgb" "$OUT/arr.baked.osgb"; then
  echo "bake: $N shards + merge = one run, byte for byte ($(stat -c %s "$OUT/arr.baked.osgb") bytes)"
else
  echo "bake: $N shards + merge DIFFER from one run" >&2; exit 1
fi
