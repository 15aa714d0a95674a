#!/usr/bin/env bash
# Regenerates docs/measurements/raw-rays.md: the far field's ray stage against
# raw Embree on exactly the rays real hybrid frames cast.
#   1. a city from data/default.json (2 km);
#   2. `vista bench` hybrid on a car, a walk and a fly path (--seed 11, 640x480,
#      FRAMES frames each) with --dump-rays: one ray set per frame;
#   3. bench_raw_rays on each path's ray sets: raw rtcIntersect1, raw
#      rtcIntersect8 (the stage's packets and dense packets), intersectMany,
#      direction generation and the in-frame path castPrimaryRays, one core and
#      all cores, repetitions interleaved at random in one process (medians);
#   4. docs/measurements/raw-rays.md written from those numbers (python below).
#
# usage: docs/tools/raw_rays.sh [OUT_DIR] [VISTA_BIN]   (run from anywhere)
#   OUT_DIR   working directory (default: a new temp dir, removed at the end)
#   VISTA_BIN the vista binary (default build/vista); bench_raw_rays is taken
#             from <dir of VISTA_BIN>/tests/bench/ (override: BENCH_RAW_RAYS=...).
# Environment: FRAMES (default 6), REPS (benchmark repetitions, default 10),
# MIN_TIME (seconds per repetition, default 0.5), REUSE_RAYS=1 (keep the ray
# sets and bench output of an earlier run in OUT_DIR; only step 3 and 4 run,
# e.g. after a change to the ray stage). Needs python3 and, without a
# display, xvfb-run. About 10 minutes on 2 cores. docs/measurements/raw-rays.md is replaced
# only when every step succeeded.
set -euo pipefail

INVOCATION="docs/tools/raw_rays.sh OUT build/vista"  # the page names the command, not this run's paths
source "$(dirname "$0")/lib.sh"
doc_setup raw_rays.sh rawrays 1280x1024x24 "$@"
DOC_TMP_FILES=(docs/measurements/.raw-rays.md.tmp)
RAW=${BENCH_RAW_RAYS:-$(dirname "$VISTA")/tests/bench/bench_raw_rays}
FRAMES=${FRAMES:-6}
REPS=${REPS:-10}
MIN_TIME=${MIN_TIME:-0.5}

[ -x "$RAW" ] || die "bench_raw_rays not found: $RAW (build it: ninja bench_raw_rays)"

mkdir -p "$OUT"
if [ -s "$OUT/commands.log" ]; then cp "$OUT/commands.log" "$OUT/commands.prev"; fi
: > "$OUT/commands.log"
run() { echo "$*" >> "$OUT/commands.log"; "$@"; }
cat /proc/loadavg > "$OUT/load_start.txt"

CITY="$OUT/city.osgb"
GEN=("$VISTA" gen --params data/default.json -o "$CITY" -q)
if [ -s "$CITY" ]; then
  log "reusing $CITY (made by: ${GEN[*]})"
  echo "${GEN[*]}" >> "$OUT/commands.log"
else
  log "gen data/default.json"
  run "${GEN[@]}" || die "gen failed"
fi
for kind in car walk fly; do
  if [ "${REUSE_RAYS:-0}" = 1 ] && [ -s "$OUT/bench/$kind/frames.csv" ]; then
    log "reusing the $kind rays of an earlier run (REUSE_RAYS=1)"
    grep -h " --kind $kind " "$OUT/commands.prev" >> "$OUT/commands.log" || true
  else
    log "bench hybrid, $kind path, $FRAMES frames, dumping rays"
    rm -rf "$OUT/rays/$kind" "$OUT/bench/$kind"
    run "${XVFB[@]}" "$VISTA" bench "$CITY" --seed 11 --kind "$kind" --frames "$FRAMES" --size 640x480 --modes hybrid \
      --dump-rays "$OUT/rays/$kind" --out "$OUT/bench/$kind" -q || die "bench $kind failed"
  fi
  log "bench_raw_rays on the $kind rays"
  run "$RAW" --city "$CITY" --rays "$OUT/rays/$kind" --benchmark_repetitions="$REPS" \
    --benchmark_enable_random_interleaving=true --benchmark_min_time="$MIN_TIME" \
    --benchmark_report_aggregates_only=true --benchmark_out="$OUT/raw_$kind.json" --benchmark_out_format=json \
    > "$OUT/raw_$kind.txt" 2> "$OUT/raw_$kind.err" || { cat "$OUT/raw_$kind.err" >&2; die "bench_raw_rays $kind failed"; }
done
cat /proc/loadavg > "$OUT/load_end.txt"

log "writing docs/measurements/raw-rays.md"
DOC_STAMP=$(doc_stamp) python3 - "$OUT" "$INVOCATION" "$REPS" "$MIN_TIME" "$FRAMES" "$VISTA" "$RAW" > "$REPO/docs/measurements/.raw-rays.md.tmp" <<'PY'
import csv, json, os, sys
out, invocation, reps, min_time, frames, vista, raw = sys.argv[1:8]
kinds = ["car", "walk", "fly"]

def medians(kind):
    """Median over repetitions of every benchmark: name (e.g. Raw8/threads:0, Interleaved) -> entry."""
    j = json.load(open(f"{out}/raw_{kind}.json"))
    m = {}
    for b in j["benchmarks"]:
        if b.get("aggregate_name") == "median":
            m[b["run_name"].replace("BM_", "").replace("/real_time", "")] = b
    return j["context"], m

def bench_stage(kind):
    """Rays the dumped hybrid frames traced and their Stage::Rays ms as `vista bench` timed them."""
    ms = 0.0
    for row in csv.DictReader(open(f"{out}/bench/{kind}/frames.csv")):
        if row["mode"] == "hybrid":
            ms += float(dict(kv.split("=") for kv in row["stages_ms"].split(";") if kv).get("rays", 0))
    n = sum((os.path.getsize(f"{out}/rays/{kind}/{f}") - 112) // 4 for f in os.listdir(f"{out}/rays/{kind}"))
    return n, ms

def cpu_model():
    for line in open("/proc/cpuinfo"):
        if line.startswith("model name"):
            return line.split(":", 1)[1].strip()
    return "unknown"

def err_line(kind, prefix):
    for line in open(f"{out}/raw_{kind}.err"):
        if line.startswith("bench_raw_rays: " + prefix):
            return line.strip()[len("bench_raw_rays: "):]
    return ""

data = {k: medians(k) for k in kinds}
ctx = data["car"][0]
one = {k: data[k][1]["Interleaved"] for k in kinds}  # counters <Variant>_ns: CPU ns per ray, one core
P = print
P("# The ray stage against raw Embree")
P()
P(f"Regenerate: `{invocation}` (about 10 minutes on 2 cores). Every number below is written by that")
P("script from the measurements of one run; the commands it ran are listed at the end.")
P()
P("How close does the far field's ray stage come to what Embree alone")
P("can do on the same rays? `vista bench --dump-rays` writes the pixel list each hybrid frame traced")
P("(`FarField::lastTraced()`, one `RaySet` file per frame: camera + pixels, runtime/engine/ray_set.h);")
P("`bench_raw_rays` (tests/bench/bench_raw_rays.cpp) rebuilds the city's `RayScene`, turns every set into")
P("the stage's own rays (`primaryRays`, bit for bit) and times, on exactly those rays:")
P()
P("| variant | what it runs |")
P("|---|---|")
P("| raw rtcIntersect1 | `rtcIntersect1` one ray at a time on the `RayScene`'s own Embree scene (`embreeScene()`), rays from precomputed arrays |")
P("| raw rtcIntersect8 | `rtcIntersect8` in the stage's packets (`coherentRuns`: a run per dense row, sparse rows share packets), SoA lanes filled from precomputed arrays, TBB over runs as the stage |")
P("| raw rtcIntersect8, plain loop | the same without TBB (one core) |")
P("| raw rtcIntersect8 + colour | the same plus every hit's colour through `RayScene::hitColor` (the fetch and interpolation of the prelit corner colours) |")
P("| raw rtcIntersect8, full packets | `rtcIntersect8` on every 8 consecutive rays of the list regardless of rows |")
P("| intersectMany | `RayScene::intersectMany` on the stage's runs: the wrapper (lane fill; per hit the colour, the normal and the `RayHit`) |")
P("| directions | `primaryRays`: the rays' directions from the pixel list (the stage's double-precision arithmetic, plus the arrays' allocation) |")
P("| in-frame stage | `castPrimaryRays` on the pixel list: what `raysStage` runs (directions, `intersectMany`, shading, colour writes, TBB over runs) |")
P()
P("*One thread*: every variant in a one-worker TBB arena (as `--threads 1`), interleaved frame by frame in")
P("one benchmark (the order rotates from frame to frame), each call timed by the thread's CPU clock, so the")
P("variants see the same machine load; medians over repetitions. *All threads*: one benchmark per variant in")
P("the default arena (every core: what the frame uses), wall time, repetitions interleaved at random by Google")
P(f"Benchmark in the same process; medians. {reps} repetitions, at least {min_time} s each.")
P()
P("<!-- raw-rays:begin -->")
P(os.environ["DOC_STAMP"])
P()
P("The *all threads* table (wall time) shares the cores with whatever else runs (the load average above); the")
P("ratios measured side by side are what count, and the one-thread ratios are the steadier ones.")
P()
P(f"Machine: {cpu_model()}, {ctx['num_cpus']} cores; Embree 3; city `data/default.json` (2 km); "
  f"paths `--seed 11`, 640x480, {frames} frames per path")
P("(spread over the path), hybrid with its defaults (near 100 m, horizon on, cache bypassed: unlimited budget).")
P()

verdicts = {}
def table(title, get):
    P(f"## Rays/s, {title}")
    P()
    P("| path | rays per frame | raw rtcIntersect1 | raw rtcIntersect8 (stage packets) | in-frame stage | stage / better raw |")
    P("|---|---|---|---|---|---|")
    for k in kinds:
        n, r1, r8, st = get(k)
        best = max(r1, r8)
        pct = 100.0 * st / best
        verdicts[(k, title)] = pct
        P(f"| {k} | {n:,.0f} | {r1/1e6:.2f} M | {r8/1e6:.2f} M | {st/1e6:.2f} M | "
          f"**{pct:.0f} %** of {'rtcIntersect8' if r8 >= r1 else 'rtcIntersect1'} |")
    P()

def one_row(k):
    c = one[k]
    return c["rays"] / c["frames"], 1e9 / c["Raw1_ns"], 1e9 / c["Raw8_ns"], 1e9 / c["Stage_ns"]

def all_row(k):
    m = data[k][1]
    st = m["Stage/threads:0"]
    return (st["rays"] / st["frames"], m["Raw1/threads:0"]["items_per_second"], m["Raw8/threads:0"]["items_per_second"],
            st["items_per_second"])

table("one thread", one_row)
table("all threads (as in the frame)", all_row)

P("## In `vista bench` itself")
P()
P("The same frames as the bench timed them (`Stage::Rays` in frames.csv, all threads, interleaved with the")
P("`full` and hybrid GL draws of llvmpipe, which use the same cores and caches; frames.csv's rays stage also")
P("includes the hit-list and class writes of `raysStage`):")
P()
P("| path | rays (all frames) | rays stage ms (sum) | rays/s | vs in-frame stage, all threads |")
P("|---|---|---|---|---|")
for k in kinds:
    n, ms = bench_stage(k)
    st = data[k][1]["Stage/threads:0"]["items_per_second"]
    rs = n / (ms / 1000.0) if ms > 0 else float("nan")
    P(f"| {k} | {n:,} | {ms:.1f} | {rs/1e6:.2f} M | {100.0 * rs / st:.0f} % |")
P()

P("## Where the rest goes (one thread, CPU ns per ray, from the variants)")
P()
P("Each column is one measured variant or the difference of two (all from the interleaved one-thread")
P("benchmark), not an estimate, so a row adds up to the in-frame stage: Embree = raw rtcIntersect8 in the")
P("stage's packets in a plain loop; TBB = the same in a one-worker arena with `parallel_for` over runs minus")
P("the plain loop; colour fetch = raw + colour minus raw (both under TBB); rest of the wrapper (lane fill,")
P("normal, `RayHit`) = intersectMany minus raw + colour; directions = the directions variant; shading = the")
P("in-frame stage minus intersectMany minus directions (sky colour of misses, colour and hit-list writes, the")
P("per-task arrays). Shares are of the in-frame stage's time. Misses: the share of rays that hit nothing")
P("(each computes a sky colour in the shading).")
P()
P("| path | Embree | TBB | colour fetch | rest of the wrapper | directions | shading | in-frame stage | misses |")
P("|---|---|---|---|---|---|---|---|---|")
parts = {}
for k in kinds:
    c = one[k]
    stage = c["Stage_ns"]
    parts[k] = {"Embree": c["Raw8Serial_ns"], "TBB": c["Raw8_ns"] - c["Raw8Serial_ns"],
                "colour fetch": c["Raw8Color_ns"] - c["Raw8_ns"], "the rest of the wrapper": c["Many_ns"] - c["Raw8Color_ns"],
                "directions": c["Dirs_ns"], "shading": stage - c["Many_ns"] - c["Dirs_ns"]}
    cell = lambda v: f"{v:.1f} ({100.0 * v / stage:.0f} %)"
    hits = int(err_line(k, "hits").split(",")[0].split()[-1])
    P(f"| {k} | " + " | ".join(cell(v) for v in parts[k].values()) + f" | {stage:.1f} | {100.0 * (1 - hits / c['rays']):.0f} % |")
P()
P("Differences smaller than the spread of their two variants can come out slightly negative.")
P()
P("Packet fill: the stage cuts its pixel list into runs at row changes (a run closes once it holds a packet), so")
P("a dense row is one run and only its last packet is partly filled. Filling every packet instead (8")
P("consecutive rays regardless of rows) makes packets that straddle row breaks:")
P()
P("| path | stage packets filled | raw rtcIntersect8, stage packets (ns/ray) | full packets across rows (ns/ray) |")
P("|---|---|---|---|")
for k in kinds:
    c = one[k]
    P(f"| {k} | {100.0 * c['packet_fill']:.1f} % | {c['Raw8_ns']:.1f} | {c['Raw8Dense_ns']:.1f} |")
P()

P("## Verdict")
P()
below = [(k, t) for (k, t), v in verdicts.items() if v < 70.0]
if not below:
    P("The in-frame stage reaches at least 70 % of the better raw Embree variant on every path, on one thread and on all.")
else:
    P("At least 70 % of the better raw variant except: " +
      ", ".join(f"{k} ({t}: {verdicts[(k, t)]:.0f} %)" for k, t in below) + ".")
P()
P("Where the rest goes, one thread:")
P()
for k in kinds:
    p = parts[k]
    overhead = {n: v for n, v in p.items() if n != "Embree"}
    big = max(overhead, key=overhead.get)
    total = sum(overhead.values())
    P(f"- {k}: {total:.1f} ns per ray beyond Embree itself ({100.0 * total / one[k]['Stage_ns']:.0f} % of the stage); "
      f"the largest part is {big} ({overhead[big]:.1f} ns per ray).")
P()
P("Sanity check (bench_raw_rays, before timing): every variant traces the same rays, so their hit counts agree:")
P()
for k in kinds:
    P(f"- {k}: {err_line(k, 'hits')}")
P()
P("<!-- raw-rays:end -->")
P()
P("## Commands")
P()
P("```")
for line in open(f"{out}/commands.log"):
    line = line.rstrip().replace(raw, "build/tests/bench/bench_raw_rays").replace(vista, "build/vista")
    P(line.replace(out, "OUT"))
P("```")
PY
mv "$REPO/docs/measurements/.raw-rays.md.tmp" "$REPO/docs/measurements/raw-rays.md"
log "done: docs/measurements/raw-rays.md"
