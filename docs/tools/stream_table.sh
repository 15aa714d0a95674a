#!/usr/bin/env bash
# Regenerates the streaming table of docs/measurements/paging.md: long car
# drives through paged cities of growing size, the city streamed around the
# camera (`vista bench --paged-stream`). For each city side in SIZES a paged
# city (`vista gen --size S -o cS.paged`), for each drive length in
# DURATIONS a car path that keeps going (`vista path cS.paged --kind car
# --route tour --duration SECONDS`), then one streamed bench of that path
# (`vista bench cS.paged --path P.csv --paged-stream --modes MODES`, its
# frames spread over the whole drive) under GNU time. Per row: the peak RSS
# (GNU time and the bench's own), the peak resident region file bytes, the
# median and p99 frame time of the first mode (and the p99 of the frames
# during which a region arrived against the others), the regions loaded and
# unloaded, and the bytes read per km driven. The block between
# <!-- stream-table:begin --> and <!-- stream-table:end --> of
# docs/measurements/paging.md is replaced only when every step succeeded.
# Cities, paths and benches already in OUT_DIR are kept (resumable; delete
# them to measure again).
#
# usage: docs/tools/stream_table.sh [OUT_DIR] [VISTA_BIN]
#   env: SIZES (city sides in metres, default "2000 8000 16000 32000" = 4 .. 1,024 km²;
#          64000 adds 4,096 km²),
#        DURATIONS (drive lengths in minutes, default "1 10 30"),
#        MODES (bench modes, default hybrid; when the binary does not stream
#          one of them, the run falls back to FALLBACK_MODES among those it
#          names as streaming, and the table says which modes ran),
#        FALLBACK_MODES (default raycast), CITY_SEED (default 1), SEED (path
#        seed, default 5), FRAMES (default 120), SAMPLING (default spread),
#        IMAGE (default 640x480), RADIUS (--paged-radius; default vista's),
#        REGION (--region-size of the cities; default vista's 2000),
#        BENCH_ARGS (more bench flags, split at white space, e.g.
#          "--memory-budget 2" or "--paged-wait")
# Needs python3, /usr/bin/time (GNU time) and, without a display, xvfb-run.
# The 32 km city takes about 12 minutes to generate and 4.3 GB of disk; each
# bench renders FRAMES frames per mode.
set -euo pipefail
source "$(dirname "$0")/lib.sh"
doc_setup stream_table.sh stream 1280x1024x24 "$@"
DOC_TMP_FILES=(docs/measurements/.paging.md.tmp)
SIZES=${SIZES:-"2000 8000 16000 32000"}
DURATIONS=${DURATIONS:-"1 10 30"}
MODES=${MODES:-hybrid}
FALLBACK_MODES=${FALLBACK_MODES:-raycast}
CITY_SEED=${CITY_SEED:-1}
SEED=${SEED:-5}
FRAMES=${FRAMES:-120}
SAMPLING=${SAMPLING:-spread}
IMAGE=${IMAGE:-640x480}
RADIUS=${RADIUS:-}
REGION=${REGION:-}
BENCH_ARGS=${BENCH_ARGS:-}
INVOCATION="SIZES='$SIZES' DURATIONS='$DURATIONS' MODES=$MODES CITY_SEED=$CITY_SEED SEED=$SEED FRAMES=$FRAMES SAMPLING=$SAMPLING IMAGE=$IMAGE"
[ -n "$RADIUS" ] && INVOCATION+=" RADIUS=$RADIUS"
[ -n "$REGION" ] && INVOCATION+=" REGION=$REGION"
[ -n "$BENCH_ARGS" ] && INVOCATION+=" BENCH_ARGS='$BENCH_ARGS'"
INVOCATION+=" docs/tools/stream_table.sh"
[ -x /usr/bin/time ] || die "GNU time (/usr/bin/time) is needed for the peak RSS"
read -r -a bench_args <<<"$BENCH_ARGS"
gen_args=()
[ -n "$REGION" ] && gen_args+=(--region-size "$REGION")
reach_args=()
[ -n "$RADIUS" ] && reach_args+=(--paged-radius "$RADIUS")
mkdir -p "$OUT"
: >"$OUT/commands.log"

# bench_once SIZE TAG MODES: one streamed bench into OUT/bSIZE_TAG; returns vista's exit code.
bench_once() {
  local s=$1 tag=$2 modes=$3 d="$OUT/b$1_$2"
  rm -rf "$d"
  local cmd=("$VISTA" bench "$OUT/c$s.paged" --path "$OUT/p${s}_$tag.csv" --paged-stream --modes "$modes"
    --frames "$FRAMES" --sampling "$SAMPLING" --size "$IMAGE" ${reach_args[@]+"${reach_args[@]}"}
    ${bench_args[@]+"${bench_args[@]}"} --out "$d" -q)
  echo "${cmd[*]}" >>"$OUT/commands.log"
  local rc=0
  "${XVFB[@]}" /usr/bin/time -v "${cmd[@]}" 2>"$OUT/b${s}_$tag.time" || rc=$?
  return "$rc"
}

for s in $SIZES; do
  city="$OUT/c$s.paged"
  if [ -s "$OUT/c$s.gen.json" ] && [ -s "$city/manifest.json" ]; then
    log "gen $s m: done before, kept"
  else
    rm -rf "$city" "$OUT/c$s.gen.json"
    log "gen $s m"
    cmd=("$VISTA" gen --size "$s" --seed "$CITY_SEED" ${gen_args[@]+"${gen_args[@]}"} -q -o "$city"
      --stats "$OUT/c$s.gen.json")
    echo "${cmd[*]}" >>"$OUT/commands.log"
    "${cmd[@]}" 2>"$OUT/c$s.gen.err" || die "gen $s failed: $(tail -3 "$OUT/c$s.gen.err")"
  fi
  for m in $DURATIONS; do
    secs=$(python3 -c "import sys; v = float(sys.argv[1]) * 60; print(int(v) if v == int(v) else v)" "$m")
    tag="${m}min"
    p="$OUT/p${s}_$tag.csv"
    if [ ! -s "$p" ]; then
      log "path $s m, $m min"
      cmd=("$VISTA" path "$city" --kind car --route tour --seed "$SEED" --duration "$secs" -o "$p")
      echo "${cmd[*]}" >>"$OUT/commands.log"
      "${cmd[@]}" 2>"$OUT/p${s}_$tag.err" || die "path $s $m min failed: $(tail -3 "$OUT/p${s}_$tag.err")"
    fi
    d="$OUT/b${s}_$tag"
    if [ -s "$d/summary.json" ] && [ -s "$OUT/b${s}_$tag.time" ] && [ -s "$OUT/b${s}_$tag.modes" ]; then
      log "bench $s m, $m min: done before, kept"
      continue
    fi
    log "bench $s m, $m min ($MODES)"
    modes=$MODES rc=0
    bench_once "$s" "$tag" "$modes" || rc=$?
    if [ "$rc" = 2 ] && grep -q "does not stream a paged city" "$OUT/b${s}_$tag.time"; then
      # This binary does not stream MODES: run the fallback modes it names as streaming.
      streaming=$(sed -n 's/.*(modes that do: \([^)]*\)).*/\1/p' "$OUT/b${s}_$tag.time" | head -1 | tr -d ' ')
      modes=$(python3 -c "import sys; ok = sys.argv[2].split(','); print(','.join(m for m in sys.argv[1].split(',') if m in ok))" \
        "$FALLBACK_MODES" "$streaming")
      [ -n "$modes" ] || die "bench $s: this vista streams only '$streaming', none of FALLBACK_MODES=$FALLBACK_MODES"
      log "bench $s m, $m min: '$MODES' does not stream here (streaming modes: $streaming); running $modes"
      rc=0
      bench_once "$s" "$tag" "$modes" || rc=$?
    fi
    [ "$rc" = 0 ] || die "bench $s $m min failed: $(tail -3 "$OUT/b${s}_$tag.time")"
    echo "$modes" >"$OUT/b${s}_$tag.modes"
  done
done

log "table"
python3 - "$OUT" "$INVOCATION" "$SIZES" "$DURATIONS" >"$OUT/table.md" <<'EOF'
import csv, json, math, re, sys
out, invocation, sizes, durations = sys.argv[1], sys.argv[2], sys.argv[3].split(), sys.argv[4].split()


def rss_mb(path):
    m = re.search(r"Maximum resident set size \(kbytes\): (\d+)", open(path).read())
    return int(m.group(1)) / 1024 if m else float("nan")


def pct(values, q):
    """The q-th percentile (nearest rank) of values; nan when empty."""
    if not values:
        return float("nan")
    v = sorted(values)
    return v[max(0, math.ceil(q / 100 * len(v)) - 1)]


def fmt(v, nd=1):
    return "—" if v is None or v != v else f"{v:,.{nd}f}"


def driven_km(path_csv):
    with open(path_csv) as f:
        rows = list(csv.DictReader(f))
    km = 0.0
    for a, b in zip(rows, rows[1:]):
        km += math.hypot(float(b["x_m"]) - float(a["x_m"]), float(b["y_m"]) - float(a["y_m"])) / 1000
    return km


rows, medians = [], {}
for s in sizes:
    for m in durations:
        tag = f"{m}min"
        b = json.load(open(f"{out}/b{s}_{tag}/summary.json"))
        modes = open(f"{out}/b{s}_{tag}.modes").read().strip()
        # The measured mode: the first of the run's modes (the summary lists the `full` reference first).
        first = modes.split(",")[0].strip()
        with open(f"{out}/b{s}_{tag}/frames.csv") as f:
            frames = [r for r in csv.DictReader(f) if r["mode"] == first]
        ms = [float(r["frame_ms"]) for r in frames]
        arrived = [float(r["frame_ms"]) for r in frames if int(r["regions_arrived"] or 0) > 0]
        rest = [float(r["frame_ms"]) for r in frames if int(r["regions_arrived"] or 0) == 0]
        st = b.get("paged", {}).get("stream", {})
        km = driven_km(f"{out}/p{s}_{tag}.csv")
        med = pct(ms, 50)
        medians[(s, m)] = med
        rows.append(dict(s=int(s), m=m, km=km, modes=modes, first=first, rss=rss_mb(f"{out}/b{s}_{tag}.time"),
                         own=(b.get("memory", {}) or {}).get("peak_rss_mb"), st=st, med=med, p99=pct(ms, 99),
                         p99a=pct(arrived, 99), n_a=len(arrived), p99r=pct(rest, 99)))
base = sizes[0]
print(f"Command: `{invocation}` (cities from `vista gen --size S --seed N -q -o cS.paged`; paths from "
      "`vista path cS.paged --kind car --route tour --seed M --duration SECONDS`; benches from "
      "`vista bench cS.paged --path P.csv --paged-stream --modes MODES --frames F --sampling R --size WxH`). "
      "Frame times are the first listed mode's (not the `full` reference's), over its frames; \"with arrivals\" are the frames during which a "
      "region finished loading.")
print()
print("| side (km) | area (km²) | drive (min) | driven (km) | modes | peak RSS (MB) | bench's peak RSS (MB) "
      "| peak resident region files (MB) | median ms | p99 ms | p99 ms with arrivals (frames) | p99 ms others "
      f"| median vs {int(base) / 1000:g} km | regions loaded | unloads | MB read | MB read per km | frames waited |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
for r in rows:
    km_side = r["s"] / 1000
    st = r["st"]
    read_mb = st.get("bytes_read", 0) / 1e6
    per_km = read_mb / r["km"] if r["km"] > 0 else float("nan")
    b = medians.get((base, r["m"]))
    ratio = "—" if not b or b != b or r["med"] != r["med"] else f"{r['med'] / b:.2f}x"
    print(f"| {km_side:g} | {km_side ** 2:g} | {r['m']} | {r['km']:.2f} | {r['modes']} | {fmt(r['rss'], 0)} "
          f"| {fmt(r['own'], 0)} | {fmt(st.get('peak_resident_file_bytes', float('nan')) / 1e6, 0)} "
          f"| {fmt(r['med'])} | {fmt(r['p99'])} | {fmt(r['p99a'])} ({r['n_a']}) | {fmt(r['p99r'])} | {ratio} "
          f"| {st.get('loads', '—')} | {st.get('unloads', '—')} | {fmt(read_mb, 0)} | {fmt(per_km, 1)} "
          f"| {st.get('frames_waited', '—')} |")
EOF
cat "$OUT/table.md"

doc_replace_block docs/measurements/paging.md stream-table "$OUT/table.md"
log "done: docs/measurements/paging.md updated"
