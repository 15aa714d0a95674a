#!/usr/bin/env bash
# Regenerates the memory-budget block of docs/measurements/paging.md: what a
# streamed region costs in resident memory per byte of its file, kind of load
# by kind (tests/bench/stream_memory on the city's middle regions: the weights
# of --memory-budget, nodes/render/city_stream.h), and a long car drive through
# a paged city (one per path seed in SEEDS) streamed without a budget and under each budget in BUDGETS
# (`vista bench cS.paged --path P.csv --paged-wait --memory-budget GB
# --save-frames`), each under GNU time. Per run: the peak RSS, what the budget
# left the regions, the run's own memory beside them as it measured it, the
# pager's peak estimate of what it held, the levels
# and chunk parts resident at the end, the median frame time, and the luma PSNR
# of every frame against the same frame of the run without a budget (median,
# least, frames under 50 dB). The frames wait for their regions and use a
# fixed split (MODE hybrid-fixed with --cache-always): a frame then depends on
# the resident regions alone, so the PSNR measures what the budget left out,
# not the adaptive split's own run-to-run choices. The block between
# <!-- stream-budget:begin --> and <!-- stream-budget:end --> is replaced only
# when every step succeeded. A city and path already in OUT_DIR (cS.paged,
# pS_Mmin.csv, as docs/tools/stream_table.sh makes them) are kept.
#
# usage: docs/tools/stream_budget.sh [OUT_DIR] [VISTA_BIN]
#   env: SIZE (city side in metres, default 32000 = 1,024 km²), MINUTES (drive
#        length, default 30), BUDGETS (GB, default "2"), FRAMES (default 30),
#        CITY_SEED (default 1), SEEDS (path seeds, default "5 11"), IMAGE (default
#        640x480), MODE (default hybrid-fixed), MODE_ARGS (default
#        "--cache-always")
# Needs python3, /usr/bin/time (GNU time), the build's tests/bench/stream_memory
# and tests/bench/image_psnr beside VISTA_BIN and, without a display, xvfb-run.
set -euo pipefail
source "$(dirname "$0")/lib.sh"
doc_setup stream_budget.sh budget 1280x1024x24 "$@"
DOC_TMP_FILES=(docs/measurements/.paging.md.tmp)
SIZE=${SIZE:-32000}
MINUTES=${MINUTES:-30}
BUDGETS=${BUDGETS:-2}
FRAMES=${FRAMES:-30}
CITY_SEED=${CITY_SEED:-1}
SEEDS=${SEEDS:-5 11}
IMAGE=${IMAGE:-640x480}
MODE=${MODE:-hybrid-fixed}
MODE_ARGS=${MODE_ARGS:---cache-always}
INVOCATION="SIZE=$SIZE MINUTES=$MINUTES BUDGETS='$BUDGETS' FRAMES=$FRAMES CITY_SEED=$CITY_SEED SEEDS='$SEEDS' IMAGE=$IMAGE MODE=$MODE MODE_ARGS='$MODE_ARGS' docs/tools/stream_budget.sh"
BIN_DIR=$(dirname "$VISTA")
MEMORY_TOOL="$BIN_DIR/tests/bench/stream_memory"
PSNR_TOOL="$BIN_DIR/tests/bench/image_psnr"
[ -x /usr/bin/time ] || die "GNU time (/usr/bin/time) is needed for the peak RSS"
[ -x "$MEMORY_TOOL" ] || die "$MEMORY_TOOL not found (build the stream_memory target)"
[ -x "$PSNR_TOOL" ] || die "$PSNR_TOOL not found (build the image_psnr target)"
read -r -a mode_args <<<"$MODE_ARGS"
mkdir -p "$OUT"
: >"$OUT/commands.log"

city="$OUT/c$SIZE.paged"
if [ -s "$city/manifest.json" ]; then
  log "city $SIZE m: kept"
else
  log "gen $SIZE m"
  cmd=("$VISTA" gen --size "$SIZE" --seed "$CITY_SEED" -q -o "$city")
  echo "${cmd[*]}" >>"$OUT/commands.log"
  "${cmd[@]}" 2>"$OUT/c$SIZE.gen.err" || die "gen failed: $(tail -3 "$OUT/c$SIZE.gen.err")"
fi
# path_for SEED: the drive of that path seed (the streaming table's name for seed 5).
path_for() {
  local seed=$1 p="$OUT/p${SIZE}_${MINUTES}min.csv"
  [ "$seed" = 5 ] || p="$OUT/p${SIZE}_${MINUTES}min_s$seed.csv"
  if [ ! -s "$p" ]; then
    local secs
    secs=$(python3 -c "import sys; print(int(float(sys.argv[1]) * 60))" "$MINUTES")
    local cmd=("$VISTA" path "$city" --kind car --route tour --seed "$seed" --duration "$secs" -o "$p")
    echo "${cmd[*]}" >>"$OUT/commands.log"
    "${cmd[@]}" 2>"$OUT/path.err" || die "path failed: $(tail -3 "$OUT/path.err")"
  fi
  echo "$p"
}

log "stream_memory"
echo "$MEMORY_TOOL $city" >>"$OUT/commands.log"
"$MEMORY_TOOL" "$city" >"$OUT/memory.csv" 2>"$OUT/memory.err" || die "stream_memory failed: $(tail -3 "$OUT/memory.err")"

# bench_run TAG PATH [GB]: one drive into OUT/run_TAG.
bench_run() {
  local tag=$1 path=$2 gb=${3:-}
  local d="$OUT/run_$tag"
  rm -rf "$d"
  local cmd=("$VISTA" bench "$city" --path "$path" --paged-wait --modes "$MODE" "${mode_args[@]}" --frames "$FRAMES"
    --sampling spread --size "$IMAGE" --reference none --save-frames -q --out "$d")
  [ -n "$gb" ] && cmd+=(--memory-budget "$gb")
  echo "${cmd[*]}" >>"$OUT/commands.log"
  "${XVFB[@]}" /usr/bin/time -v "${cmd[@]}" 2>"$OUT/run_$tag.time" || die "bench $tag failed: $(tail -3 "$OUT/run_$tag.time")"
}
for seed in $SEEDS; do
  path=$(path_for "$seed")
  log "path seed $seed: drive without a budget"
  bench_run "s${seed}_none" "$path"
  for gb in $BUDGETS; do
    log "path seed $seed: drive under --memory-budget $gb"
    bench_run "s${seed}_$gb" "$path" "$gb"
    for f in "$OUT/run_s${seed}_none/frames/"*.png; do
      printf '%s %s\n' "$(basename "$f")" "$("$PSNR_TOOL" "$f" "$OUT/run_s${seed}_$gb/frames/$(basename "$f")")"
    done >"$OUT/psnr_s${seed}_$gb.txt"
  done
done

log "table"
python3 - "$OUT" "$INVOCATION" "$BUDGETS" "$MODE" "$SEEDS" >"$OUT/table.md" <<'EOF'
import csv, json, re, statistics, sys
out, invocation, budgets, mode, seeds = sys.argv[1], sys.argv[2], sys.argv[3].split(), sys.argv[4], sys.argv[5].split()


def rss_mb(path):
    m = re.search(r"Maximum resident set size \(kbytes\): (\d+)", open(path).read())
    return int(m.group(1)) / 1024 if m else float("nan")


print(f"Command: `{invocation}`.")
print()
lines = [l for l in open(f"{out}/memory.csv") if l.strip()]
rows = list(csv.DictReader([l for l in lines if not l.startswith("#")]))
print("What a streamed region costs (`stream_memory CITY.paged`: one process per kind of load, the regions "
      "within 3 km of the city's middle loaded at once, resident set growth over their file bytes):")
print()
print("| loads | full levels | coarse levels | chunk parts | region files (MB) | RSS growth (MB) |")
print("|---|---|---|---|---|---|")
for r in rows:
    files = (float(r["full_file_bytes"]) + float(r["coarse_file_bytes"]) + float(r["chunk_part_file_bytes"])) / 1e6
    print(f"| {r['config']} | {r['full_levels']} | {r['coarse_levels']} | {r['chunk_parts']} | {files:,.0f} "
          f"| {float(r['rss_growth_mb']):,.0f} |")
print()
for l in lines:
    if l.startswith("#"):
        print(l.lstrip("# ").strip().capitalize() + ".")
print()
print(f"The drive (`{mode}`, every frame waiting for its regions; PSNR of each frame against the same frame "
      "without a budget):")
print()
print("| path seed | budget (GB) | peak RSS (MB) | left for the regions (MB) | the run's own memory, measured (MB) "
      "| peak estimate held (MB) | full / coarse / chunk parts at the end | loads | median ms | PSNR median (dB) "
      "| PSNR least (dB) | frames under 50 dB |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|")
for seed in seeds:
    for b in ["none"] + budgets:
        tag = f"s{seed}_{b}"
        s = json.load(open(f"{out}/run_{tag}/summary.json"))
        st = s["paged"]["stream"]
        with open(f"{out}/run_{tag}/frames.csv") as f:
            ms = [float(r["frame_ms"]) for r in csv.DictReader(f) if r["mode"] == mode]
        if b == "none":
            p = pl = under = "—"
        else:
            vals = [float(l.split()[1]) for l in open(f"{out}/psnr_{tag}.txt") if l.strip()]
            p = f"{statistics.median(vals):.1f}"
            pl = f"{min(vals):.1f}"
            under = f"{sum(1 for v in vals if v < 50)} of {len(vals)}"
        left = f"{st['budget_bytes'] / 2**20:,.0f}" if st["budget_bytes"] else "—"
        own = f"{st['process_overhead_bytes'] / 2**20:,.0f}" if st.get("process_overhead_bytes") else "—"
        print(f"| {seed} | {b} | {rss_mb(f'{out}/run_{tag}.time'):,.0f} | {left} | {own} "
              f"| {st['peak_resident_estimate_bytes'] / 2**20:,.0f} "
              f"| {st['resident_full_end']} / {st['resident_coarse_end']} / {st['resident_chunk_parts_end']} "
              f"| {st['loads']} | {statistics.median(ms):.1f} | {p} | {pl} | {under} |")
EOF
cat "$OUT/table.md"
doc_replace_block docs/measurements/paging.md stream-budget "$OUT/table.md"
log "docs/measurements/paging.md updated"
