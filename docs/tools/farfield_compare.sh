#!/usr/bin/env bash
# Regenerates the measured block of docs/measurements/farfield-compare.md:
# the far-field representations side by side on one city, the same view
# cells and the same walkthrough paths — full (all geometry, frustum-culled
# 40 m chunks), osglod (stock osg::LOD + osgUtil::Simplifier, the best
# conventional draw vista has), hybrid (ray-cast far field), impostor (baked
# point impostors, thesis ch. 5) and lodmesh (baked textured depth meshes,
# Chen et al. 2003): frame time median / p95, PSNR against `full` and against
# the supersampled reference, storage, bake time, peak memory, the analogue
# of Chen03 Table 6 and of thesis Table 5.1. The block between
# <!-- farfield-compare:begin --> and <!-- farfield-compare:end --> is
# replaced only when every step succeeded; the verdict around it is prose.
#
# What it runs (every command goes to OUT/commands.log):
#  1. vista gen --params $PARAMS (default data/town.json, 1.2 km).
#  2. The cells the paths visit: a mesh bake with no meshes (--min-triangles
#     2000000000: cells only, a few seconds) opened by `vista bench --modes
#     lodmesh` at 80x60 on each path; the "cell N" notes of frames.csv list
#     the cells (lodmesh falls back to the nearest cell, so the list also
#     covers frames between cells). Baking only these cells keeps the run at
#     about 30 minutes on the shared 2-core machine (load average 6-9; about
#     an hour and a half more for the whole town with points); both
#     representations bake the same cells.
#  3. vista bake --cells LIST (points, then --representation mesh), --jobs
#     $JOBS, --stats; wall time and peak RSS by /usr/bin/time.
#  4. Per path kind: one bench with every mode interleaved frame by frame
#     (reference full: frame times, PSNR vs full), one with --reference
#     ssaa:$SSAA (PSNR vs the supersampled full render).
#  5. Memory: per mode a short bench (--frames 4) of `full` + that mode alone;
#     summary.json memory.peak_rss_mb.
#
# Resumable: every finished step leaves its output in OUT (default
# ./farfield-compare-out) and is skipped on a rerun; delete a file to redo it.
#
# usage: docs/tools/farfield_compare.sh [OUT_DIR] [VISTA_BIN]
#   env: PARAMS (default data/town.json), KINDS (default "car walk"), SEED (path seed, default 1),
#        FRAMES (default 64), SAMPLING (default runs:8), SIZE (default 640x480), SSAA (default 4),
#        JOBS (bake threads, default 2)
# Needs python3, /usr/bin/time and, without a display, xvfb-run.
set -euo pipefail
source "$(dirname "$0")/lib.sh"
doc_setup farfield_compare.sh fcompare 1280x1024x24 "${1:-farfield-compare-out}" "${2:-build/vista}"
DOC_TMP_FILES=(docs/measurements/.farfield-compare.md.tmp)
PARAMS=${PARAMS:-data/town.json}
KINDS=${KINDS:-"car walk"}
SEED=${SEED:-1}
FRAMES=${FRAMES:-64}
SAMPLING=${SAMPLING:-runs:8}
SIZE=${SIZE:-640x480}
SSAA=${SSAA:-4}
JOBS=${JOBS:-2}
MODES=full,osglod,hybrid,impostor,lodmesh
INVOCATION="PARAMS=$PARAMS KINDS='$KINDS' SEED=$SEED FRAMES=$FRAMES SAMPLING=$SAMPLING SIZE=$SIZE SSAA=$SSAA JOBS=$JOBS docs/tools/farfield_compare.sh OUT $(basename "$VISTA")"
[ -x /usr/bin/time ] || die "/usr/bin/time is needed (bake wall time and peak memory)"
[ -f "$PARAMS" ] || die "PARAMS: no such file: $PARAMS"

mkdir -p "$OUT/bench" "$OUT/bake"
touch "$OUT/commands.log"
run() {  # run CMD...: logged, under the display wrapper when one is needed
  echo "$*" >> "$OUT/commands.log"
  "${XVFB[@]}" "$@"
}

# 1. the city
if [ ! -s "$OUT/city.osgb" ]; then
  log "gen $PARAMS"
  run "$VISTA" gen --params "$PARAMS" -o "$OUT/city.osgb" -q || die "gen failed"
else log "city: done before, kept"; fi

# 2. the cells of the paths
if [ ! -s "$OUT/bake/probe.osgb" ] || [ ! -s "$OUT/bake/probe.json" ]; then
  log "probe bake (cells only)"
  run "$VISTA" bake "$OUT/city.osgb" -o "$OUT/bake/probe.osgb" --representation mesh --min-triangles 2000000000 \
    --stats "$OUT/bake/probe.json" --jobs "$JOBS" -q || die "probe bake failed"
fi
for k in $KINDS; do
  d="$OUT/bench/probe_$k"
  if [ ! -s "$d/frames.csv" ]; then
    log "probe bench $k"
    rm -rf "$d"
    run "$VISTA" bench "$OUT/city.osgb" --baked-mesh "$OUT/bake/probe.osgb" --seed "$SEED" --kind "$k" --frames "$FRAMES" \
      --sampling "$SAMPLING" --size 80x60 --modes lodmesh --worst 0 --out "$d" -q || die "probe bench $k failed"
  fi
done
if [ ! -s "$OUT/cells.txt" ]; then
  for k in $KINDS; do grep -o 'cell [0-9]*' "$OUT/bench/probe_$k/frames.csv" || true; done | awk '{print $2}' | sort -n -u |
    paste -s -d, - > "$OUT/cells.tmp"
  [ -s "$OUT/cells.tmp" ] || die "the paths visit no view cell"
  mv "$OUT/cells.tmp" "$OUT/cells.txt"
fi
CELLS=$(cat "$OUT/cells.txt")
log "cells: $CELLS"

# 3. the two bakes of the same cells
bake() {  # bake NAME [options...]
  local name=$1; shift
  if [ -s "$OUT/bake/$name.osgb" ] && [ -s "$OUT/bake/$name.time" ]; then log "bake $name: done before, kept"; return; fi
  log "bake $name ($*)"
  echo "/usr/bin/time -f '%e %M' $VISTA bake $OUT/city.osgb -o $OUT/bake/$name.osgb --cells $CELLS --jobs $JOBS --stats $OUT/bake/$name.json -q $*" \
    >> "$OUT/commands.log"
  /usr/bin/time -f '%e %M' -o "$OUT/bake/$name.time.tmp" "$VISTA" bake "$OUT/city.osgb" -o "$OUT/bake/$name.osgb" --cells "$CELLS" \
    --jobs "$JOBS" --stats "$OUT/bake/$name.json" -q "$@" || die "bake $name failed"
  mv "$OUT/bake/$name.time.tmp" "$OUT/bake/$name.time"
}
bake points
bake mesh --representation mesh

# 4. and 5. the benches
bench() {  # bench NAME KIND MODES FRAMES [flags...]
  local name=$1 kind=$2 modes=$3 frames=$4; shift 4
  local d="$OUT/bench/$name"
  if [ -s "$d/summary.json" ]; then log "bench $name: done before, kept"; return; fi
  rm -rf "$d"
  log "bench $name ($kind, $modes, $frames frames $*)"
  run "$VISTA" bench "$OUT/city.osgb" --baked "$OUT/bake/points.osgb" --baked-mesh "$OUT/bake/mesh.osgb" --seed "$SEED" \
    --kind "$kind" --frames "$frames" --sampling "$SAMPLING" --size "$SIZE" --modes "$modes" --worst 0 --out "$d" -q "$@" ||
    die "bench $name failed"
  [ -s "$d/summary.json" ] || die "bench $name wrote no summary.json"
}
for k in $KINDS; do
  bench "main_$k" "$k" "$MODES" "$FRAMES"
  bench "ssaa_$k" "$k" "$MODES" "$FRAMES" --reference "ssaa:$SSAA"
done
first=${KINDS%% *}
for m in ${MODES//,/ }; do bench "mem_$m" "$first" "$m" 4; done

log "report"
DOC_STAMP=$(doc_stamp) python3 - "$OUT" "$REPO/docs/measurements/farfield-compare.md" "$REPO/docs/measurements/.farfield-compare.md.tmp" "$INVOCATION" "$KINDS" "$MODES" "$SSAA" \
  "$PARAMS" <<'PY'
import json, os, re, statistics, sys
out, doc, tmp, invocation, kinds, modes, ssaa, params = sys.argv[1:]
kinds, modes = kinds.split(), modes.split(",")
J = lambda *p: json.load(open(os.path.join(out, *p)))
def summary(name): return J("bench", name, "summary.json")
def mb(b): return b / 1048576.0
def med(v): return statistics.median(v) if v else 0.0
cells = open(os.path.join(out, "cells.txt")).read().strip()
ncells = len(cells.split(","))
city_bytes = os.path.getsize(os.path.join(out, "city.osgb"))
bakes = {}
for name in ("points", "mesh"):
    st = J("bake", name + ".json")
    wall, rss = open(os.path.join(out, "bake", name + ".time")).read().split()[-2:]
    bakes[name] = dict(stats=st, wall=float(wall), rss_mb=float(rss) / 1024.0,
                       bytes=os.path.getsize(os.path.join(out, "bake", name + ".osgb")))
pts, msh = bakes["points"], bakes["mesh"]
# Per cell: points (impostor) and triangles (mesh) drawn for that cell's far field.
cell_points, cell_mesh_tri = {}, {}
for s in pts["stats"]["impostor_stats"]: cell_points[s["cell"]] = cell_points.get(s["cell"], 0) + s["points"]
for s in msh["stats"]["impostor_stats"]: cell_mesh_tri[s["cell"]] = cell_mesh_tri.get(s["cell"], 0) + s["triangles"]
def frames(name):
    rows = []
    with open(os.path.join(out, "bench", name, "frames.csv")) as f:
        head = f.readline().strip().split(",")
        for line in f:
            v = line.rstrip("\n").split(",")
            rows.append(dict(zip(head, v)))
    return rows
def points_per_frame(name):  # median points drawn by `impostor` (the cell in its notes)
    v = []
    for r in frames(name):
        if r["mode"] != "impostor": continue
        m = re.search(r"cell (\d+)", r.get("notes", ""))
        v.append(cell_points.get(int(m.group(1)), 0) if m else 0)
    return med(v)
L = []
L.append("<!-- farfield-compare:begin -->")
L.append(os.environ["DOC_STAMP"])
L.append("")
L.append(f"Generated by `{invocation}` (commands: OUT/commands.log). City: `{params}` "
         f"({mb(city_bytes):.1f} MB city file); {ncells} view cells baked, the cells the paths visit: {cells}.")
L.append("")
for k in kinds:
    m, s = summary(f"main_{k}"), summary(f"ssaa_{k}")
    L.append(f"### Walkthrough `{k}`")
    L.append("")
    L.append(f"`{m['command'].replace(out + '/', 'OUT/')}` (frame times, PSNR vs `full`) and the same with `--reference ssaa:{ssaa}` (PSNR vs the "
             f"{ssaa}x{ssaa} supersampled `full`). {m['size'][0]}x{m['size'][1]}, {m['frames']} frames ({m['sampling']}), "
             f"modes interleaved frame by frame; load average {m['machine'].get('load_avg_1min_start', '?')} → "
             f"{m['machine'].get('load_avg_1min_end', '?')}.")
    L.append("")
    L.append("| mode | frame ms median | p95 | speed-up vs full (median of ratios) | PSNR vs full med / min (dB) | "
             f"PSNR vs ssaa:{ssaa} med / min (dB) | triangles (median) | points (median) | draw calls | set-up (ms) |")
    L.append("|---|---:|---:|---:|---:|---:|---:|---:|---:|---|")
    for mode in m["mode_order"]:
        a, b = m["modes"][mode], s["modes"][mode]
        vsf = "—" if mode == "full" else f"{a['psnr_db_median']:.1f} / {a['psnr_db_min']:.1f}"
        setup = ", ".join(f"{n} {v:.0f}" for n, v in a.get("setup_ms", {}).items() if n != "load") or "—"
        npts = f"{points_per_frame(f'main_{k}'):,.0f}" if mode == "impostor" else "—"
        L.append(f"| {mode} | {a['frame_ms_median']:.1f} | {a['frame_ms_p95']:.1f} | "
                 f"{a['speedup_vs_full_median_of_ratios']:.2f}x | {vsf} | {b['psnr_db_median']:.1f} / {b['psnr_db_min']:.1f} | "
                 f"{a['triangles_median']:,.0f} | {npts} | {a['draw_calls_median']:.0f} | {setup} |")
    L.append("")
# Storage, bake, memory.
L.append("### Storage, bake time, memory")
L.append("")
L.append(f"Bake: `/usr/bin/time vista bake city.osgb --cells LIST --jobs N --stats ...` per representation, the same {ncells} cells. "
         "Memory: peak RSS of `vista bench --modes MODE --frames 4` (the bench always runs `full` too, as the reference).")
L.append("")
fullmem = summary("mem_full")["memory"]["peak_rss_mb"]
L.append("| mode | extra data on disk | per view cell | bake wall s (sum of cell times s) | bake peak RSS MB | "
         "bench peak RSS MB (over full alone) |")
L.append("|---|---:|---:|---:|---:|---:|")
for mode in modes:
    mem = summary(f"mem_{mode}")["memory"]["peak_rss_mb"]
    memtxt = f"{mem:.0f}" + ("" if mode == "full" else f" ({mem - fullmem:+.0f})")
    if mode in ("impostor", "lodmesh"):
        b = pts if mode == "impostor" else msh
        extra = b["bytes"] - city_bytes
        L.append(f"| {mode} | {mb(extra):.1f} MB (file {mb(b['bytes']):.1f} MB) | {mb(extra) / ncells:.2f} MB | "
                 f"{b['wall']:.0f} ({b['stats']['cell_bake_s_sum']:.0f}) | {b['rss_mb']:.0f} | {memtxt} |")
    else:
        note = {"full": "none", "osglod": "none (simplified at set-up)", "hybrid": "none (Embree BVH at set-up)"}[mode]
        L.append(f"| {mode} | {note} | — | — | — | {memtxt} |")
L.append("")
allcells = J("bake", "probe.json")["cells"]
L.append(f"Whole city, extrapolated from these {ncells} cells (per-cell means; the city has {allcells} view cells): point impostors "
         f"about {mb(pts['bytes'] - city_bytes) / ncells * allcells:,.0f} MB and {pts['stats']['cell_bake_s_sum'] / ncells * allcells / 60 / 2:,.0f} "
         f"min of baking on 2 cores; textured depth meshes about {mb(msh['bytes'] - city_bytes) / ncells * allcells:,.0f} MB and "
         f"{msh['stats']['cell_bake_s_sum'] / ncells * allcells / 60 / 2:,.1f} min. The path cells are busier than the average cell "
         "(streets through the centre), so these are upper estimates.")
L.append("")
# Chen03 Table 6 analogue.
L.append("### Analogue of Chen et al. 2003, Table 6")
L.append("")
L.append("Chen's Table 6 lists, per scene, the frame rate of brute-force rendering, of view-frustum culling and of "
         "their method, the speed-ups and the PSNR. Here `full` *is* view-frustum culling (OSG culls the 40 m chunks "
         "against the frustum); vista has no draw without culling, so brute force is estimated: all the city's "
         "triangles at the triangle rate `full` reached in the same frames (`full` ms x city triangles / triangles "
         "drawn by full, per-frame medians).")
L.append("")
L.append("| path | mode | frame ms | speed-up over brute force (est.) | speed-up over frustum culling (full) | PSNR vs full dB | "
         f"PSNR vs ssaa:{ssaa} dB |")
L.append("|---|---|---:|---:|---:|---:|---:|")
for k in kinds:
    m, s = summary(f"main_{k}"), summary(f"ssaa_{k}")
    f = m["modes"]["full"]
    brute = f["frame_ms_median"] * m["city_triangles"] / max(f["triangles_median"], 1)
    L.append(f"| {k} | brute force (est.) | {brute:.0f} | 1.00x | {f['frame_ms_median'] / brute:.2f}x | — | — |")
    for mode in m["mode_order"]:
        a, b = m["modes"][mode], s["modes"][mode]
        L.append(f"| {k} | {mode} | {a['frame_ms_median']:.1f} | {brute / a['frame_ms_median']:.2f}x | "
                 f"{a['speedup_vs_full_median_of_ratios']:.2f}x | "
                 f"{'—' if mode == 'full' else format(a['psnr_db_median'], '.1f')} | {b['psnr_db_median']:.1f} |")
L.append("")
# Thesis Table 5.1 analogue, both representations.
L.append("### Analogue of thesis Table 5.1 (per street end of the baked cells)")
L.append("")
L.append("Median (min – max) over the street ends that got an impostor or a mesh, from the bakes' `--stats`. "
         "The thesis' three scenes: 80,341 / 87,665 / 31,252 points, 2.35 – 2.8 points per screen pixel, "
         "1.6 / 1.75 / 0.6 MB, 22 – 41 minutes per impostor (2001).")
L.append("")
def rng(v, fmt="{:,.0f}"):
    return f"{fmt.format(med(v))} ({fmt.format(min(v))} – {fmt.format(max(v))})" if v else "—"
pi, mi = pts["stats"]["impostor_stats"], msh["stats"]["impostor_stats"]
L.append("| | point impostors | textured depth meshes |")
L.append("|---|---|---|")
L.append(f"| street ends with a far field | {len(pi)} | {len(mi)} |")
L.append(f"| far-field triangles replaced | {rng([s['far_triangles'] for s in pi])} | {rng([s['far_triangles'] for s in mi])} |")
L.append(f"| LDI samples → after removal | {rng([s['ldi_samples'] for s in pi])} → {rng([s['after_removal'] for s in pi])} | — |")
L.append(f"| points / mesh triangles | {rng([s['points'] for s in pi])} | {rng([s['triangles'] for s in mi])} |")
L.append(f"| textured points / mesh image | {rng([s['textured_points'] for s in pi])} | "
         f"{rng([s['image'][0] * s['image'][1] for s in mi])} px |")
L.append(f"| points per screen pixel (distinct) | {rng([s['points_per_screen_pixel'] for s in pi], '{:.2f}')} | — |")
L.append(f"| memory (MB) | {rng([s['memory_mb'] for s in pi], '{:.2f}')} | {rng([s['memory_mb'] for s in mi], '{:.2f}')} |")
L.append(f"| bake time per end (s) | {rng([s['bake_s'] for s in pi], '{:.1f}')} | {rng([s['bake_s'] for s in mi], '{:.2f}')} |")
L.append("")
# Raster costs on this machine and a GPU estimate.
L.append("### Raster cost on this machine, and what a GPU would change")
L.append("")
L.append("Per-frame medians of the first path. llvmpipe cost per triangle = draw ms / triangles of `full`; the points' "
         "share of `impostor` = its draw ms minus the draw ms of `lodmesh`, which draws the same tiles (the same cells) "
         "and a few thousand mesh triangles instead of the points. GPU column: the same primitive counts at assumed rates "
         "of a mid-range desktop GPU (1 G triangles/s, 2 G one-pixel points/s, 10 us of CPU per draw call); fragments are "
         f"not limiting at {summary(f'main_{kinds[0]}')['size'][0]}x{summary(f'main_{kinds[0]}')['size'][1]} (0.3 M pixels "
         "at a few G fragments/s). `hybrid` keeps its CPU far-field stages (horizon, cache, rays, composite, opacity, seam: "
         "measured here). An estimate, not a measurement.")
L.append("")
m = summary(f"main_{kinds[0]}")
f = m["modes"]["full"]
ns_tri = 1e6 * f["draw_ms_median"] / max(f["triangles_median"], 1)
L.append(f"llvmpipe: {ns_tri:.0f} ns per triangle drawn by `full` ({f['draw_ms_median']:.1f} ms for {f['triangles_median']:,.0f}).")
npts = points_per_frame(f"main_{kinds[0]}")
imp, lm = m["modes"]["impostor"], m["modes"]["lodmesh"]
pt_ms = imp["draw_ms_median"] - lm["draw_ms_median"]
if npts > 0:
    L.append(f"`impostor` draws {imp['draw_ms_median']:.1f} ms, `lodmesh` {lm['draw_ms_median']:.1f} ms: {pt_ms:.1f} ms for "
             f"{npts:,.0f} points → about {max(pt_ms, 0) / npts * 1e6:.0f} ns per point on llvmpipe.")
L.append("")
L.append("| mode | triangles | points | draw calls | llvmpipe frame ms (measured) | GPU frame ms (estimate) |")
L.append("|---|---:|---:|---:|---:|---:|")
for mode in m["mode_order"]:
    a = m["modes"][mode]
    p = npts if mode == "impostor" else 0
    cpu = sum(v for k, v in a.get("stages_ms", {}).items() if k in ("horizon", "cache", "rays", "composite", "opacity", "seam"))
    gpu = a["triangles_median"] / 1e6 + p / 2e6 + a["draw_calls_median"] * 0.01 + cpu
    note = f" (of which {cpu:.1f} CPU far field)" if cpu > 0 else ""
    L.append(f"| {mode} | {a['triangles_median']:,.0f} | {p:,.0f} | {a['draw_calls_median']:.0f} | {a['frame_ms_median']:.1f} | "
             f"{gpu:.1f}{note} |")
L.append("<!-- farfield-compare:end -->")
block = "\n".join(L)
text = open(doc).read() if os.path.exists(doc) else "# Far-field representations side by side\n\n<!-- farfield-compare:begin -->\n<!-- farfield-compare:end -->\n"
b0, b1 = text.find("<!-- farfield-compare:begin -->"), text.find("<!-- farfield-compare:end -->")
if b0 < 0 or b1 < 0: sys.exit("docs/measurements/farfield-compare.md has no farfield-compare markers")
text = text[:b0] + block + text[b1 + len("<!-- farfield-compare:end -->"):]
open(tmp, "w").write(text)
PY
mv "$REPO/docs/measurements/.farfield-compare.md.tmp" "$REPO/docs/measurements/farfield-compare.md"
log "docs/measurements/farfield-compare.md written ($OUT/commands.log has every command)"
