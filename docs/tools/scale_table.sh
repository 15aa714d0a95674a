#!/usr/bin/env bash
# Regenerates the per-size table of docs/measurements/paging.md:
# for each city size, a paged city from `vista gen -o cS.paged` (generation
# time and peak RSS), then one walkthrough of it with `full`, `osglod` and
# `hybrid` interleaved frame by frame (`vista bench cS.paged`: the regions
# within --paged-radius of the path at full detail, the rest of the city at
# its coarse level for the far field), its frame times, PSNR against `full`,
# load and set-up times and the bench's peak RSS (GNU time). The block
# between <!-- scale-table:begin --> and <!-- scale-table:end --> of
# docs/measurements/paging.md is replaced only when every step succeeded.
# Cities and bench outputs already in OUT_DIR are kept (resumable; delete
# them to re-measure).
#
# usage: docs/tools/scale_table.sh [OUT_DIR] [VISTA_BIN]
#   env: SIZES (metres, default "1000 2000 4000 8000 16000 32000" = 1 .. 1,024 km2),
#        CITY_SEED (default 1), SEED (path seed, default 5), KIND (default car),
#        FRAMES (default 16), SAMPLING (default runs:2), IMAGE (default 640x480),
#        MODES (default full,osglod,hybrid), RADIUS (--paged-radius, default 3000),
#        OSGLOD_MAX (largest side in metres benched with osglod, default 4000: its
#        simplifier set-up takes about 17 s per million loaded triangles here)
# Needs python3, /usr/bin/time (GNU time) and, without a display, xvfb-run.
# About 45 minutes on 2 cores with llvmpipe, two thirds of it generating the
# 32 km city (4.3 GB of disk; the 16 km city 2.4 GB).
set -euo pipefail
source "$(dirname "$0")/lib.sh"
doc_setup scale_table.sh scale 1280x1024x24 "$@"
DOC_TMP_FILES=(docs/measurements/.paging.md.tmp)
SIZES=${SIZES:-"1000 2000 4000 8000 16000 32000"}
CITY_SEED=${CITY_SEED:-1}
SEED=${SEED:-5}
KIND=${KIND:-car}
FRAMES=${FRAMES:-16}
SAMPLING=${SAMPLING:-runs:2}
IMAGE=${IMAGE:-640x480}
MODES=${MODES:-full,osglod,hybrid}
RADIUS=${RADIUS:-3000}
OSGLOD_MAX=${OSGLOD_MAX:-4000}
INVOCATION="SIZES='$SIZES' CITY_SEED=$CITY_SEED SEED=$SEED KIND=$KIND FRAMES=$FRAMES SAMPLING=$SAMPLING IMAGE=$IMAGE MODES=$MODES RADIUS=$RADIUS OSGLOD_MAX=$OSGLOD_MAX docs/tools/scale_table.sh"
[ -x /usr/bin/time ] || die "GNU time (/usr/bin/time) is needed for the peak RSS"
mkdir -p "$OUT"
: > "$OUT/commands.log"

for s in $SIZES; do
  city="$OUT/c$s.paged"
  if [ -s "$OUT/c$s.gen.json" ] && [ -s "$city/manifest.json" ]; then
    log "gen $s m: done before, kept"
  else
    rm -rf "$city" "$OUT/c$s.gen.json"
    log "gen $s m"
    cmd=("$VISTA" gen --size "$s" --seed "$CITY_SEED" -q -o "$city" --stats "$OUT/c$s.gen.json")
    echo "${cmd[*]}" >> "$OUT/commands.log"
    /usr/bin/time -v "${cmd[@]}" 2> "$OUT/c$s.gen.time" || die "gen $s failed: $(tail -3 "$OUT/c$s.gen.time")"
  fi
  d="$OUT/b$s"
  if [ -s "$d/summary.json" ] && [ -s "$OUT/b$s.time" ]; then
    log "bench $s m: done before, kept"
  else
    rm -rf "$d"
    modes=$MODES
    if [ "$s" -gt "$OSGLOD_MAX" ]; then modes=$(echo "$MODES" | tr ',' '\n' | grep -vx osglod | paste -sd, -); fi
    log "bench $s m ($modes)"
    cmd=("$VISTA" bench "$city" --seed "$SEED" --kind "$KIND" --frames "$FRAMES" --sampling "$SAMPLING" --size "$IMAGE"
         --modes "$modes" --paged-radius "$RADIUS" --out "$d" -q)
    echo "${cmd[*]}" >> "$OUT/commands.log"
    "${XVFB[@]}" /usr/bin/time -v "${cmd[@]}" 2> "$OUT/b$s.time" || die "bench $s failed: $(tail -3 "$OUT/b$s.time")"
  fi
done

log "table"
python3 - "$OUT" "$INVOCATION" "$SIZES" > "$OUT/table.md" <<'EOF'
import json, os, re, statistics, sys
out, invocation, sizes = sys.argv[1], sys.argv[2], [int(s) for s in sys.argv[3].split()]
def rss_mb(path):
    m = re.search(r"Maximum resident set size \(kbytes\): (\d+)", open(path).read())
    return int(m.group(1)) / 1024 if m else float("nan")
def fmt(v, nd=1):
    return "—" if v is None or v != v else f"{v:,.{nd}f}"
rows, hybrid = [], {}
for s in sizes:
    g = json.load(open(f"{out}/c{s}.gen.json"))
    b = json.load(open(f"{out}/b{s}/summary.json"))
    gen_time = f"{out}/c{s}.gen.time"
    gen_rss = rss_mb(gen_time) if os.path.exists(gen_time) else g.get("peak_rss_mb", float("nan"))
    p, m = b.get("paged", {}), b["modes"]
    setup = m.get("hybrid", {}).get("setup_ms", {})
    def ms(mode, m=m):
        return m[mode]["frame_ms_median"] if mode in m else None
    def psnr(mode, m=m):
        return m[mode]["psnr_db_median"] if mode in m else None
    hybrid[s] = ms("hybrid")
    rows.append((s, g, b, p, gen_rss, rss_mb(f"{out}/b{s}.time"), setup, ms, psnr))
base = 2000 if 2000 in hybrid else sizes[0]
print(f"Command: `{invocation}` (cities from `vista gen --size S --seed N -q -o cS.paged`; walkthroughs from "
      "`vista bench cS.paged --seed M --kind K --frames F --sampling R --size WxH --modes MODES --paged-radius 3000`).")
print()
print("| side (km) | area (km²) | city triangles (M) | gen (s) | gen peak (MB) | regions full + coarse | triangles loaded (M) "
      "| load (s) | BVH + chunking (s) | bench peak RSS (MB) | full ms | osglod ms (PSNR dB) | hybrid ms (PSNR dB) "
      f"| hybrid vs {base / 1000:g} km |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
for s, g, b, p, gen_rss, bench_rss, setup, ms, psnr in rows:
    km, area = s / 1000, (s / 1000) ** 2
    loaded = b.get("city_triangles", 0) / 1e6
    regions = f"{p.get('regions_loaded', 0)} + {p.get('coarse_regions_loaded', 0)} of {p.get('regions_total', 0)}"
    bvh_chunk = (setup.get("bvh", 0) + setup.get("chunking", 0)) / 1000
    load_s = setup.get("load", b.get("load_ms", 0) or 0) / 1000
    osglod = "—" if ms("osglod") is None else f"{fmt(ms('osglod'))} ({fmt(psnr('osglod'))})"
    hyb = "—" if ms("hybrid") is None else f"{fmt(ms('hybrid'))} ({fmt(psnr('hybrid'))})"
    ratio = "—" if hybrid.get(s) is None or not hybrid.get(base) else f"{hybrid[s] / hybrid[base]:.2f}x"
    print(f"| {km:g} | {area:g} | {g['triangles'] / 1e6:.1f} | {g['seconds']['total']:.0f} | {gen_rss:.0f} | {regions} "
          f"| {loaded:.1f} | {load_s:.0f} | {bvh_chunk:.0f} | {bench_rss:.0f} | {fmt(ms('full'))} | {osglod} | {hyb} | {ratio} |")
EOF
cat "$OUT/table.md"

doc_replace_block docs/measurements/paging.md scale-table "$OUT/table.md"
log "done: docs/measurements/paging.md updated"
