#!/usr/bin/env bash
# Runs the Slurm recipe of docs/jobs/ the way Slurm runs it, without Slurm:
# fake `sbatch`, `scontrol` and `srun` on PATH record what the scripts ask
# for; a small scheduler here then runs each batch script as slurmd would:
# a fresh environment (the submitter's, --export=ALL) plus the SLURM_*
# variables, the submit directory as working directory, stdout and stderr
# into the --output file (%A, %a, %j, %x expanded; a rerun truncates it
# unless --open-mode=append),
# SIGUSR1 to the batch shell before the time limit (--signal=B:USR1@...),
# SIGTERM to the job's processes on scancel, requeued tasks run again with
# SLURM_RESTART_COUNT, the merge after its afterany dependency. As in Slurm,
# the last task of an array has the array's job id as its own, and
# `scontrol requeue ARRAYJOB` requeues every task.
#
# The city: 1.5 km in 500 m regions (9 regions, facade detail 0), 3 shards. Shard 1 reaches
# its time limit, shard 2 is cancelled, shard 3 fails after damaging a region
# file. Shards 1 and 3 requeue themselves (and nothing else); the merge finds
# shard 2/3 missing (vista names it and the command that runs it) and submits
# it again with a new merge, which finishes the city; the result must be byte
# for byte the single-machine run. The same for a rendered dataset (4 shards
# of whole drives, one cancelled and submitted again by the merge). Also checked: the scripts run with
# VISTA_ARGS unset (set -u), logs land in OUT.logs (not the submit
# directory), VISTA_SBATCH_OPTS reach sbatch, the merge asks for a sized
# amount of memory that covers its measured peak, and a merge out of rounds
# (VISTA_MAX_ROUNDS) or given bad input submits nothing and exits 2.
#   tests/tools/test_slurm_jobs.sh VISTA SOURCE_DIR WORK_DIR
set -euo pipefail
for tool in /usr/bin/time setsid truncate; do
  [ -x "$tool" ] || command -v "$tool" >/dev/null || { echo "SKIP: $tool not found"; exit 77; }
done
VISTA_BIN="$(realpath "${1:?usage: $0 VISTA SOURCE_DIR WORK_DIR}")"
SRC="$(realpath "${2:?}")"
W="${3:?}"
rm -rf "$W"
mkdir -p "$W"
W="$(realpath "$W")"
JOBS="$SRC/docs/jobs"
S="$W/slurm"  # the fake controller's state
mkdir -p "$S/jobs" "$W/bin" "$W/submit"
echo 1000 >"$S/next_id"
: >"$S/requeued"

fail() { echo "FAIL: $*" >&2; exit 1; }
ok() { echo "ok: $*"; }

# --- the fake Slurm commands -------------------------------------------------
cat >"$W/bin/sbatch" <<'EOF'
#!/usr/bin/env bash
# Fake sbatch: records the submission (options, a copy of the script, the
# environment, the submit directory) under $FAKE_SLURM/jobs/ID; runs nothing.
set -euo pipefail
S="$FAKE_SLURM"
parsable=0 opts=()
while [ $# -gt 0 ] && [ "${1#-}" != "$1" ]; do
  [ "$1" = --parsable ] && parsable=1 || opts+=("$1")
  shift
done
script="${1:?sbatch: no script}"
[ -f "$script" ] || { echo "sbatch: error: Unable to open file $script" >&2; exit 1; }
id=$(cat "$S/next_id")
echo $((id + 100)) >"$S/next_id"
d="$S/jobs/$id"
mkdir -p "$d"
# #SBATCH lines first, then the command line (later options win, as in sbatch).
sed -n 's/^#SBATCH \([^ ]*\).*/\1/p' "$script" >"$d/options"
printf '%s\n' ${opts[@]+"${opts[@]}"} >>"$d/options"
printf '%s\n' ${opts[@]+"${opts[@]}"} >"$d/argv"
cp "$script" "$d/script"  # Slurm keeps a copy: the job runs what was submitted
env -0 >"$d/env"
pwd >"$d/cwd"
out="$(sed -n 's/^--output=//p' "$d/options" | tail -1)"
case "$out" in /*) ;; *) out="$(pwd)/$out" ;; esac
[ -d "$(dirname "$out")" ] || echo "the directory of --output=$out does not exist" >>"$S/errors"
if [ "$parsable" = 1 ]; then echo "$id"; else echo "Submitted batch job $id"; fi
EOF
cat >"$W/bin/scontrol" <<'EOF'
#!/usr/bin/env bash
# Fake scontrol: `scontrol requeue JOB...` asks the fake controller to run
# these jobs again, recorded by their job ids: ARRAYJOB_K is task K; an
# array's own job id is every task of it (as Slurm does); any other id is
# that job. Nothing else is supported.
set -euo pipefail
[ "${1:-}" = requeue ] || { echo "fake scontrol: only 'requeue' is supported, not '$*'" >&2; exit 1; }
shift
for j in "$@"; do
  if [[ "$j" =~ ^([0-9]+)_([0-9]+)$ ]]; then
    "$FAKE_SLURM/task_id" "${BASH_REMATCH[1]}" "${BASH_REMATCH[2]}" >>"$FAKE_SLURM/requeued"
  elif [ -n "$(sed -n 's/^--array=//p' "$FAKE_SLURM/jobs/$j/options" 2>/dev/null)" ]; then
    for k in $("$FAKE_SLURM/task_list" "$j"); do "$FAKE_SLURM/task_id" "$j" "$k" >>"$FAKE_SLURM/requeued"; done
  else
    echo "$j" >>"$FAKE_SLURM/requeued"
  fi
done
EOF
# task_list ARRAYJOB: its tasks ("1-3", "2,5" or "3-4" expanded);
# task_id ARRAYJOB K: task K's job id (the last task: the array's own id).
cat >"$S/task_list" <<'EOF'
#!/usr/bin/env bash
spec="$(sed -n 's/^--array=//p' "$FAKE_SLURM/jobs/$1/options" | tail -1)"
for k in ${spec//,/ }; do
  case "$k" in *-*) seq "${k%-*}" "${k#*-}" ;; *) echo "$k" ;; esac
done
EOF
cat >"$S/task_id" <<'EOF'
#!/usr/bin/env bash
last="$("$FAKE_SLURM/task_list" "$1" | sort -n | tail -1)"
if [ "$2" = "$last" ]; then echo "$1"; else echo $(($1 + $2)); fi
EOF
chmod +x "$S/task_list" "$S/task_id"
cat >"$W/bin/srun" <<'EOF'
#!/usr/bin/env bash
# Fake srun: a job step is the command itself.
exec "$@"
EOF
chmod +x "$W/bin/"*
export FAKE_SLURM="$S"
export PATH="$W/bin:$PATH"

# started N: waits until shard N's first vista run has begun (the batch shell is past its setup).
started() {
  local i
  for i in $(seq 1 600); do
    [ -e "$W/first.$1" ] && return 0
    sleep 0.1
  done
  fail "shard $1 did not start vista"
}

opt() { sed -n "s/^--$2=//p" "$S/jobs/$1/options" | tail -1; }  # opt JOBID NAME: the value that applies

tasks() { "$S/task_list" "$1"; }  # the array tasks of a job
tid() { "$S/task_id" "$1" "$2"; }   # tid ARRAYJOB K: task K's job id

# start JOBID [TASK]: starts the batch script as slurmd does; PID is its pid
# (a process group of its own, so that a cancel reaches vista too). The
# task's own job id is tid JOBID TASK, its array job id JOBID.
start() {
  local id=$1 k=${2:-} d="$S/jobs/$1" jid out restarts
  jid=$id
  local -a vars=(SLURM_JOB_ID="$id" SLURM_SUBMIT_DIR="$(cat "$d/cwd")" SLURM_JOB_NAME="$(opt "$id" job-name)")
  out="$(opt "$id" output)"
  if [ -n "$k" ]; then
    jid=$(tid "$id" "$k")
    local -a ks
    mapfile -t ks < <(tasks "$id")
    vars=(SLURM_JOB_ID="$jid" SLURM_ARRAY_JOB_ID="$id" SLURM_ARRAY_TASK_ID="$k" SLURM_ARRAY_TASK_COUNT="${#ks[@]}"
      SLURM_ARRAY_TASK_MIN="${ks[0]}" SLURM_ARRAY_TASK_MAX="${ks[-1]}" "${vars[@]:1}")
    out="${out//%a/$k}"
  fi
  restarts=$(grep -c "^$jid\$" "$S/requeued" || true)
  [ "$restarts" -gt 0 ] && vars+=(SLURM_RESTART_COUNT="$restarts")
  out="${out//%A/$id}"
  out="${out//%j/$jid}"
  out="${out//%x/$(opt "$id" job-name)}"
  case "$out" in /*) ;; *) out="$(cat "$d/cwd")/$out" ;; esac
  echo "$out" >"$d/log.$jid"
  [ "$(opt "$id" open-mode)" = append ] || : >"$out"  # Slurm truncates the log of a rerun by default
  (cd "$(cat "$d/cwd")" && exec setsid env -i bash --noprofile --norc -c \
    'while IFS= read -r -d "" kv; do export "$kv" 2>/dev/null || true; done <"$1"; shift; exec env "$@"' \
    _ "$d/env" "${vars[@]}" bash "$d/script" >>"$out" 2>&1) &
  PID=$!
}

# run JOBID [TASK]: runs it to the end; RC is its exit code.
run() {
  start "$@"
  RC=0
  wait "$PID" || RC=$?
}

# --- set -u: the scripts with VISTA_ARGS unset, vista a recorder ------------
cat >"$W/bin/vista-argv" <<'EOF'
#!/usr/bin/env bash
printf '%s\n' "$*" >>"$ARGV_LOG"
EOF
chmod +x "$W/bin/vista-argv"
(
  unset VISTA_ARGS
  export ARGV_LOG="$W/argv" VISTA="$W/bin/vista-argv" VISTA_JOB=gen VISTA_SHARDS=4 VISTA_OUT=/x/c.paged
  SLURM_ARRAY_TASK_ID=2 bash "$JOBS/slurm-array.sbatch"
  bash "$JOBS/slurm-merge.sbatch"
  VISTA_JOB=bake VISTA_CITY=/x/c.osgb VISTA_OUT=/x/c.baked.osgb SLURM_ARRAY_TASK_ID=4 bash "$JOBS/slurm-array.sbatch"
) 2>"$W/unset.err" || { cat "$W/unset.err"; fail "a script fails with VISTA_ARGS unset"; }
expected="gen -q -o /x/c.paged --shard 2/4
gen -q -o /x/c.paged --merge --shards 4
bake /x/c.osgb -q -o /x/c.baked.osgb --shard 4/4"
[ "$(cat "$W/argv")" = "$expected" ] || fail "with VISTA_ARGS unset the scripts ran: $(cat "$W/argv")"
ok "the scripts run with VISTA_ARGS unset (set -u)"

# Bad input (exit 2) is not retried; nor is a failure once VISTA_MAX_RESTARTS is reached.
printf '#!/usr/bin/env bash\nexit "$EXIT"\n' >"$W/bin/vista-exit"
chmod +x "$W/bin/vista-exit"
for c in "2 0" "1 3"; do
  set -- $c
  rc=0
  VISTA="$W/bin/vista-exit" EXIT=$1 SLURM_RESTART_COUNT=$2 SLURM_JOB_ID=99 SLURM_ARRAY_TASK_ID=1 VISTA_JOB=gen \
    VISTA_SHARDS=2 VISTA_OUT=/x/c.paged bash "$JOBS/slurm-array.sbatch" 2>>"$W/retry.err" || rc=$?
  [ "$rc" = "$1" ] || fail "vista exiting $1 made the task exit $rc"
done
[ ! -s "$S/requeued" ] || fail "requeued after bad input or past VISTA_MAX_RESTARTS: $(cat "$W/retry.err")"
ok "bad input and a task past VISTA_MAX_RESTARTS are not requeued"

# --- the single-machine run -------------------------------------------------
ARGS=(--size 1500 --seed 3 --detail 0 --region-size 500)  # facade detail 0: the shards, not the facades, are under test
"$VISTA_BIN" gen "${ARGS[@]}" -q -o "$W/one.paged"

# --- vista as the cluster sees it: shard 1 runs into its time limit, shard 2
# --- is cancelled, shard 3 fails after damaging a region file; each only once.
cat >"$W/bin/vista-cluster" <<EOF
#!/usr/bin/env bash
# Every run's peak RSS (KiB) and arguments go to $W/rss.
shard=""
for a in "\$@"; do case "\$a" in */3) shard="\$a" ;; esac; done
first="$W/first.\${shard%/*}"
if [ -n "\$shard" ] && [ ! -e "\$first" ]; then
  : >"\$first"
  case "\$shard" in
    1/3 | 2/3) exec sleep 600 ;;  # long: stopped by the time limit / cancelled
    3/3)
      "$VISTA_BIN" "\$@" || exit
      out="\$(printf '%s\n' "\$@" | grep '\.paged\$')"
      region="\$(ls "\$out"/region_*.osgb | grep -v coarse | head -1)"
      truncate -s 100 "\$region"  # killed while writing it
      exit 137 ;;
  esac
fi
exec /usr/bin/time -a -o "$W/rss" -f "%M \$*" "$VISTA_BIN" "\$@"
EOF
chmod +x "$W/bin/vista-cluster"

cd "$W/submit"
export VISTA="$W/bin/vista-cluster"
VISTA_SBATCH_OPTS="--partition=debug --account=maps" \
  "$JOBS/slurm-submit.sh" gen 3 "$W/arr.paged" "${ARGS[@]}" >"$W/submit1.out"
array=1000 merge=1100
grep -q "array job $array .*merge job $merge" "$W/submit1.out" || fail "submit printed: $(cat "$W/submit1.out")"
[ ! -e "$S/errors" ] || fail "$(cat "$S/errors")"
for j in $array $merge; do
  grep -qx -- "--partition=debug" "$S/jobs/$j/argv" && grep -qx -- "--account=maps" "$S/jobs/$j/argv" \
    || fail "VISTA_SBATCH_OPTS did not reach sbatch for job $j: $(tr '\n' ' ' <"$S/jobs/$j/argv")"
done
ok "VISTA_SBATCH_OPTS reach sbatch"
[ "$(opt $array array)" = 1-3 ] || fail "array $(opt $array array)"
[ "$(opt $merge dependency)" = "afterany:$array" ] || fail "merge dependency '$(opt $merge dependency)'"
[ "$(opt $array signal)" = "B:USR1@180" ] && grep -qx -- --requeue "$S/jobs/$array/options" \
  || fail "the array asks for no time-limit warning or no requeue"

# Shard 1: the time limit is near (SIGUSR1 to the batch shell).
start $array 1
started 1
kill -USR1 "$PID"
rc=0
wait "$PID" || rc=$?
grep -qx "$(tid $array 1)" "$S/requeued" || fail "shard 1 did not requeue itself before the time limit (exit $rc)"
# Shard 2: scancel (SIGTERM to every process of the job).
start $array 2
started 2
kill -TERM -- "-$PID"
wait "$PID" || true
grep -qx "$(tid $array 2)" "$S/requeued" && fail "a cancelled shard requeued itself"
# Shard 3, the last task, whose job id is the array's: vista fails.
[ "$(tid $array 3)" = $array ] || fail "the fake controller gives task 3 the id $(tid $array 3)"
run $array 3
rc=$RC
[ "$rc" = 137 ] || fail "shard 3's first run exited $rc"
grep -qx "$array" "$S/requeued" || fail "shard 3 did not requeue itself after vista failed"
[ "$(sort -u "$S/requeued" | tr '\n' ' ')" = "$(printf '%s\n' "$(tid $array 1)" $array | sort -u | tr '\n' ' ')" ] \
  || fail "requeued $(tr '\n' ' ' <"$S/requeued"), not just shards 1 and 3 (a task requeued by the array's id?)"
ok "time limit and failure requeue the shard (and only it), a cancel does not"

# The controller runs the requeued tasks again.
for k in 1 3; do
  run $array $k
  rc=$RC
  [ "$rc" = 0 ] || fail "shard $k/3 failed again (exit $rc): $(cat "$(cat "$S/jobs/$array/log.$(tid $array $k)")")"
done
grep -q "attempt 2" "$(cat "$S/jobs/$array/log.$array")" || fail "shard 3's log lost a run (open-mode=append)"
grep -q "requeueing" "$(cat "$S/jobs/$array/log.$array")" || fail "shard 3's log does not say it requeued"

# afterany: every task has ended, the merge runs, finds shard 2/3 missing and
# submits it again with a new merge.
run $merge
rc=$RC
mlog="$(cat "$S/jobs/$merge/log.$merge")"
[ "$rc" = 0 ] || fail "the merge with shard 2 missing exited $rc: $(cat "$mlog")"
grep -q "region_1_0.osgb (shard 2/3)" "$mlog" || fail "vista does not name the region's shard: $(cat "$mlog")"
grep -q "run shard 2/3 again: vista gen .* -o $W/arr.paged --shard 2/3; then the merge" "$mlog" \
  || fail "vista does not print the command for shard 2/3: $(cat "$mlog")"
[ ! -e "$W/arr.paged/index.osgb" ] || fail "a refused merge wrote the index"
array2=1200 merge2=1300
[ "$(opt $array2 array)" = 2 ] || fail "the merge submitted --array=$(opt $array2 array), not 2: $(cat "$mlog")"
[ "$(opt $merge2 dependency)" = "afterany:$array2" ] || fail "the new merge waits for '$(opt $merge2 dependency)'"
grep -q "array job $array2 (shards 2 of 3), merge job $merge2" "$mlog" || fail "the merge does not name the new jobs"
tr '\0' '\n' <"$S/jobs/$array2/env" | grep -qx VISTA_ROUND=1 || fail "the new jobs do not count the round"
! tr '\0' '\n' <"$S/jobs/$array2/env" | grep -q '^SLURM_' || fail "the merge's SLURM_* variables reached the new jobs"
grep -qx -- "--partition=debug" "$S/jobs/$array2/argv" || fail "VISTA_SBATCH_OPTS lost in the resubmission"
ok "the merge submits shard 2/3 again with a new merge (round 1)"

run $array2 2
rc=$RC
[ "$rc" = 0 ] || fail "shard 2 rerun exited $rc"
run $merge2
rc=$RC
[ "$rc" = 0 ] || fail "the second merge exited $rc: $(cat "$(cat "$S/jobs/$merge2/log.$merge2")")"
diff -r "$W/one.paged" "$W/arr.paged" >/dev/null || fail "shards + requeues + a resubmission + merge differ from one run"
ok "shards, requeues, a resubmission and the merge = one run, byte for byte ($(find "$W/arr.paged" -type f | wc -l) files)"

# Logs: in arr.paged.logs, one per task (appended over its runs) and merge; none in the submit directory.
ls "$W/arr.paged.logs/shard-${array}_1.log" "$W/arr.paged.logs/shard-${array}_3.log" \
  "$W/arr.paged.logs/shard-${array2}_2.log" "$W/arr.paged.logs/merge-$merge.log" >/dev/null \
  || fail "logs missing from arr.paged.logs: $(ls "$W/arr.paged.logs")"
[ -z "$(ls -A "$W/submit")" ] || fail "files in the submit directory: $(ls -A "$W/submit")"
ok "logs in OUT.logs, nothing in the submit directory"

# The merge's memory: what it asks for covers its measured peak, and is not the shard's.
mem="$(opt $merge2 mem)"
[ "$mem" = 1G ] || fail "the gen merge asks for --mem=$mem"
peak="$(grep -- '--merge' "$W/rss" | tail -1 | cut -d' ' -f1)"
[ -n "$peak" ] && [ "$peak" -lt $((1024 * 1024)) ] || fail "the merge's peak ${peak:-?} KiB is over its 1G"
ok "gen merge asks for 1G, peaks at $((peak / 1024)) MiB"
truncate -s 50M "$W/c.osgb"
VISTA="$W/bin/vista-argv" VISTA_SHARD_LIST=2-3 "$JOBS/slurm-submit.sh" bake 4 "$W/c.baked.osgb" "$W/c.osgb" >/dev/null
[ "$(opt 1500 mem)" = 2248M ] || fail "the bake merge of a 50 MB city asks for --mem=$(opt 1500 mem), not 2048 + 4 x 50 MB"
[ "$(opt 1400 array)" = 2-3 ] || fail "VISTA_SHARD_LIST=2-3 gave --array=$(opt 1400 array)"
ok "bake merge sized from the city file (2248M for 50 MB)"

# A merge out of rounds names the shards and the command, submits nothing and
# exits 2; so does one told VISTA_MAX_ROUNDS=0; bad input (exit 2 without
# missing shards) is never submitted again.
cat >"$W/bin/vista-missing" <<'EOF'
#!/usr/bin/env bash
echo "vista gen: --merge: 1 of 9 regions of 'x' are missing, corrupt or from other parameters (region_1_0.osgb (shard 2/4)); run shard 2/4 again: vista gen -o x --shard 2/4; then the merge" >&2
exit 2
EOF
printf '#!/usr/bin/env bash\necho "vista gen: option --size: bad" >&2\nexit 2\n' >"$W/bin/vista-bad"
chmod +x "$W/bin/vista-missing" "$W/bin/vista-bad"
before=$(cat "$S/next_id")
for env in "VISTA=$W/bin/vista-missing VISTA_ROUND=2" "VISTA=$W/bin/vista-missing VISTA_MAX_ROUNDS=0" \
  "VISTA=$W/bin/vista-bad"; do
  rc=0
  env $env VISTA_JOB=gen VISTA_SHARDS=4 VISTA_OUT=/x/c.paged VISTA_SUBMIT="$JOBS/slurm-submit.sh" \
    bash "$JOBS/slurm-merge.sbatch" 2>"$W/rounds.err" || rc=$?
  [ "$rc" = 2 ] || fail "merge ($env) exited $rc: $(cat "$W/rounds.err")"
  case "$env" in
    *missing*) grep -q "VISTA_SHARD_LIST=2 $JOBS/slurm-submit.sh gen 4 /x/c.paged" "$W/rounds.err" \
      || fail "merge ($env) does not print the command: $(cat "$W/rounds.err")" ;;
  esac
done
[ "$(cat "$S/next_id")" = "$before" ] || fail "a merge out of rounds or given bad input submitted jobs"
ok "a merge out of rounds or given bad input submits nothing, exits 2 and prints the command"
# --- a rendered dataset: 4 shards of whole drives (two cities x two paths),
# --- shard 3 cancelled before it ran; the merge submits it again, and the
# --- result is the single-machine run byte for byte (summary.json aside:
# --- timings and the command line). Camera drives need a display.
if [ -z "${DISPLAY:-}" ]; then
  echo "skip: the render dataset part (no DISPLAY; run under xvfb-run -a)"
else
  D="$W/dataset"
  mkdir -p "$D"
  "$VISTA_BIN" gen --size 400 --seed 11 -q -o "$D/a.osgb"
  "$VISTA_BIN" gen --size 400 --seed 12 -q -o "$D/b.osgb"
  cat >"$D/ds.json" <<'EOF2'
{"cities": ["a.osgb", "b.osgb"],
 "paths": [{"name": "p1", "seed": 2, "duration": 3}, {"name": "p2", "seed": 4, "duration": 3}],
 "rigs": [{"name": "cam", "size": "64x48", "channels": "rgb,depth,semantic"}],
 "options": {"frames": 2}}
EOF2
  "$VISTA_BIN" render --dataset "$D/ds.json" -q --out "$D/one"
  export VISTA="$VISTA_BIN"
  "$JOBS/slurm-submit.sh" render 4 "$D/arr" --dataset "$D/ds.json" >"$W/submit_render.out"
  read -r rarray rmerge < <(sed -n 's/^array job \([0-9]*\) .*merge job \([0-9]*\);.*/\1 \2/p' "$W/submit_render.out")
  [ -n "${rmerge:-}" ] || fail "render submit printed: $(cat "$W/submit_render.out")"
  [ "$(opt "$rarray" array)" = 1-4 ] && [ "$(opt "$rmerge" mem)" = 1G ] \
    || fail "render array $(opt "$rarray" array), merge mem $(opt "$rmerge" mem)"
  for k in 1 2 4; do
    run "$rarray" $k
    [ "$RC" = 0 ] || fail "render shard $k/4 exited $RC: $(cat "$(cat "$S/jobs/$rarray/log.$(tid "$rarray" $k)")")"
  done
  run "$rmerge"
  rlog="$(cat "$S/jobs/$rmerge/log.$rmerge")"
  [ "$RC" = 0 ] || fail "the render merge with shard 3 missing exited $RC: $(cat "$rlog")"
  grep -q "shard 3/4: missing" "$rlog" || fail "vista render does not name the missing shard: $(cat "$rlog")"
  grep -q "run shard 3/4 again: vista render --dataset $D/ds.json -q --out $D/arr --shard 3/4; then the merge" "$rlog" \
    || fail "vista render does not print the command for shard 3/4: $(cat "$rlog")"
  [ ! -e "$D/arr" ] || fail "a refused render merge wrote the output"
  read -r rarray2 rmerge2 < <(sed -n 's/.*array job \([0-9]*\) (shards 3 of 4), merge job \([0-9]*\);.*/\1 \2/p' "$rlog")
  [ -n "${rmerge2:-}" ] || fail "the render merge did not submit shard 3 again: $(cat "$rlog")"
  run "$rarray2" 3
  [ "$RC" = 0 ] || fail "render shard 3/4 rerun exited $RC"
  run "$rmerge2"
  [ "$RC" = 0 ] || fail "the second render merge exited $RC: $(cat "$(cat "$S/jobs/$rmerge2/log.$rmerge2")")"
  diff -r -x summary.json "$D/one" "$D/arr" >/dev/null || fail "render shards + a resubmission + merge differ from one run"
  ok "render: 4 dataset shards, a resubmission and the merge = one run, byte for byte ($(find "$D/arr" -type f | wc -l) files)"
fi
echo "PASS"
