#!/usr/bin/env python3
"""Writes docs/measurements/effects.md (Markdown) and the Pareto SVGs from the measurements of
docs/tools/effects.sh. Standard library only; PSNR of saved frames via image_psnr.

usage: effects_report.py --out OUT_DIR --psnr IMAGE_PSNR --md FILE.md --img IMG_DIR
                         [--invocation TEXT] [--elapsed SECONDS]
"""
import argparse
import csv
import json
import math
import os
import statistics
import subprocess
import sys

ap = argparse.ArgumentParser()
ap.add_argument("--out", required=True)
ap.add_argument("--psnr", required=True)
ap.add_argument("--md", required=True)
ap.add_argument("--img", required=True)
ap.add_argument("--invocation", default="docs/tools/effects.sh")
ap.add_argument("--elapsed", type=float, default=float("nan"))
ap.add_argument("--stamp", required=True,
                help="the block's first line: docs/tools/lib.sh doc_stamp (version, commit, machine, load average)")
A = ap.parse_args()

BENCH = os.path.join(A.out, "bench")
GEN = os.path.join(A.out, "gen")
IDENTICAL = 99.0  # image_psnr prints 99 for identical images


def die(msg):
    sys.exit(f"effects_report.py: error: {msg}")


def load(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError) as e:
        die(f"cannot read {path}: {e}")


_S, _G = {}, {}


def S(name):
    if name not in _S:
        _S[name] = load(os.path.join(BENCH, name, "summary.json"))
    return _S[name]


def G(name):
    if name not in _G:
        _G[name] = load(os.path.join(GEN, name + ".json"))
    return _G[name]


def M(name, mode):
    m = S(name)["modes"].get(mode)
    if m is None:
        die(f"bench {name} has no mode {mode}")
    return m


def rows(name, mode=None):
    with open(os.path.join(BENCH, name, "frames.csv")) as f:
        r = list(csv.DictReader(f))
    if not r:
        die(f"empty frames.csv in {name}")
    return [x for x in r if mode is None or x["mode"] == mode]


def stages(row):
    out = {}
    for kv in row["stages_ms"].split(";"):
        if "=" in kv:
            k, v = kv.split("=", 1)
            out[k] = float(v)
    return out


_P = {}


def psnr(a, b):
    key = (a, b)
    if key not in _P:
        r = subprocess.run([A.psnr, a, b], capture_output=True, text=True)
        if r.returncode != 0 or not r.stdout.split():
            die(f"image_psnr {a} {b} failed: {r.stderr.strip()}")
        _P[key] = float(r.stdout.split()[0])
    return _P[key]


def frames_psnr(run, mode, ref, ref_mode="full"):
    """Median (and min) over frames of PSNR of run's MODE frames vs ref's REF_MODE frames."""
    d, rd = os.path.join(BENCH, run, "frames"), os.path.join(BENCH, ref, "frames")
    files = sorted(f for f in os.listdir(d) if f.endswith(f"_{mode}.png"))
    if not files:
        die(f"no saved {mode} frames in {run}")
    vals = []
    for f in files:
        rf = os.path.join(rd, f[: -len(f"_{mode}.png")] + f"_{ref_mode}.png")
        if not os.path.exists(rf):
            die(f"reference frame missing: {rf}")
        vals.append(psnr(os.path.join(d, f), rf))
    return statistics.median(vals), min(vals), len(vals)


def f1(x):
    return "—" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.1f}"


def f2(x):
    return "—" if x is None else f"{x:.2f}"


def db(x):
    return "identical" if x >= IDENTICAL else f"{x:.1f}"


def pct(new, old):
    return "—" if not old else f"{100.0 * (new - old) / old:+.0f} %"


def ratio(new, old):
    return "—" if not old else f"{new / old:.2f}"


def mt(n):
    return f"{n / 1e6:.2f} M"


def paired_median_ratio(a, mode_a, b, mode_b, col):
    """Median over frames of a[col]/b[col] for the same frame index (same path): run a's mode_a
    against run b's mode_b (one run's mode and its +clear twin, or two runs)."""
    ra = {r["frame"]: float(r[col]) for r in rows(a, mode_a)}
    rb = {r["frame"]: float(r[col]) for r in rows(b, mode_b)}
    v = [ra[k] / rb[k] for k in ra if k in rb and rb[k] > 0]
    return statistics.median(v) if v else None


# ----------------------------------------------------------------------------- SVG Pareto plot
def nice_ticks(lo, hi, n=6):
    if hi <= lo:
        hi = lo + 1
    raw = (hi - lo) / n
    mag = 10 ** math.floor(math.log10(raw))
    step = min((s * mag for s in (1, 2, 2.5, 5, 10) if s * mag >= raw), default=10 * mag)
    t = math.floor(lo / step) * step
    out = [round(t, 10)]
    while out[-1] < hi - 1e-9:
        t += step
        out.append(round(t, 10))
    return out


def esc(s):
    return s.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def pareto_svg(path, title, points):
    """points: list of dict(x=ms, y=psnr dB, label, series). Front = not dominated (less time,
    more PSNR). PSNR >= 99 (identical to the reference) is drawn on a separate top row."""
    W, H, L, R, T, B = 720, 440, 70, 170, 50, 55
    colours = {"full": "#1f77b4", "hybrid": "#d62728"}
    finite = [p["y"] for p in points if p["y"] < IDENTICAL]
    ylo = min(finite) if finite else 0.0
    yhi = max(finite) if finite else 50.0
    pad = max(1.0, 0.08 * (yhi - ylo))
    yt = nice_ticks(ylo - pad, yhi + pad)
    y0, y1 = yt[0], yt[-1]
    xs = [p["x"] for p in points]
    xt = nice_ticks(0, max(xs) * 1.1)
    x0, x1 = xt[0], xt[-1]
    top_row = T + 12  # where "identical" points go
    plot_top = T + 40

    def X(x):
        return L + (x - x0) / (x1 - x0) * (W - L - R)

    def Y(y):
        if y >= IDENTICAL:
            return top_row
        return plot_top + (y1 - y) / (y1 - y0) * (H - B - plot_top)

    front = []
    for p in points:
        dominated = any((q["x"] <= p["x"] and q["y"] >= p["y"]) and (q["x"] < p["x"] or q["y"] > p["y"])
                        for q in points)
        if not dominated:
            front.append(p)
    front.sort(key=lambda p: p["x"])
    o = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" viewBox="0 0 {W} {H}" '
         f'font-family="sans-serif" font-size="12">',
         f'<rect width="{W}" height="{H}" fill="white"/>',
         f'<text x="{W / 2 - R / 2 + L / 2}" y="22" text-anchor="middle" font-size="15">{esc(title)}</text>']
    # grid + axes
    for t in yt:
        o.append(f'<line x1="{L}" y1="{Y(t):.1f}" x2="{W - R}" y2="{Y(t):.1f}" stroke="#e4e4e4"/>')
        o.append(f'<text x="{L - 6}" y="{Y(t) + 4:.1f}" text-anchor="end">{t:g}</text>')
    for t in xt:
        o.append(f'<line x1="{X(t):.1f}" y1="{plot_top}" x2="{X(t):.1f}" y2="{H - B}" stroke="#e4e4e4"/>')
        o.append(f'<text x="{X(t):.1f}" y="{H - B + 16}" text-anchor="middle">{t:g}</text>')
    o.append(f'<line x1="{L}" y1="{top_row}" x2="{W - R}" y2="{top_row}" stroke="#bbb" stroke-dasharray="2,3"/>')
    o.append(f'<text x="{L - 6}" y="{top_row + 4}" text-anchor="end">ref</text>')
    o.append(f'<rect x="{L}" y="{plot_top}" width="{W - L - R}" height="{H - B - plot_top}" fill="none" stroke="#444"/>')
    o.append(f'<text x="{L + (W - L - R) / 2}" y="{H - 14}" text-anchor="middle">frame time, median (ms per frame)</text>')
    o.append(f'<text transform="translate(18,{plot_top + (H - B - plot_top) / 2}) rotate(-90)" '
             f'text-anchor="middle">PSNR vs reference, median over frames (dB)</text>')
    # front
    if len(front) > 1:
        pts = " ".join(f"{X(p['x']):.1f},{Y(p['y']):.1f}" for p in front)
        o.append(f'<polyline points="{pts}" fill="none" stroke="#2ca02c" stroke-width="2" stroke-dasharray="6,4"/>')
    # markers first, then labels placed greedily where they overlap no marker and no earlier label
    boxes = [(X(p["x"]) - 6, Y(p["y"]) - 6, X(p["x"]) + 6, Y(p["y"]) + 6) for p in points]
    labels = []
    for p in sorted(points, key=lambda p: (-p["y"], p["x"])):
        x, y = X(p["x"]), Y(p["y"])
        wd, ht = 6.3 * len(p["label"]) + 2, 12
        best = None
        for dx, dy in ((8, -7), (8, 12), (-8 - wd, -7), (-8 - wd, 12), (8, -19), (-wd / 2, -12), (-wd / 2, 22),
                       (8, 24), (-8 - wd, -19), (-8 - wd, 24), (8, -31), (8, 36)):
            bx0, by1 = x + dx, y + dy
            box = (bx0, by1 - ht + 2, bx0 + wd, by1 + 2)
            if box[0] < 2 or box[2] > W - R + 60 or box[1] < T - 8 or box[3] > H - B + 2:
                continue
            hits = sum(1 for b in boxes + [l[0] for l in labels]
                       if not (box[2] < b[0] or box[0] > b[2] or box[3] < b[1] or box[1] > b[3]))
            if best is None or hits < best[0]:
                best = (hits, box, bx0, by1)
            if hits == 0:
                break
        if best is None:
            best = (0, (x + 8, y - 17, x + 8 + wd, y - 5), x + 8, y - 7)
        labels.append((best[1], best[2], best[3], p))
    for p in points:
        c = colours.get(p["series"], "#555")
        x, y = X(p["x"]), Y(p["y"])
        on = p in front
        if p["series"] == "hybrid":
            o.append(f'<rect x="{x - 5:.1f}" y="{y - 5:.1f}" width="10" height="10" fill="{c if on else "white"}" '
                     f'stroke="{c}" stroke-width="2"/>')
        else:
            o.append(f'<circle cx="{x:.1f}" cy="{y:.1f}" r="5.5" fill="{c if on else "white"}" stroke="{c}" stroke-width="2"/>')

    for _, lx_, ly_, p in labels:
        o.append(f'<text x="{lx_:.1f}" y="{ly_:.1f}" fill="{colours.get(p["series"], "#555")}" font-size="11">'
                 f'{esc(p["label"])}</text>')
    # legend
    lx, ly = W - R + 14, plot_top + 10
    o.append(f'<circle cx="{lx + 6}" cy="{ly}" r="5.5" fill="{colours["full"]}"/>'
             f'<text x="{lx + 18}" y="{ly + 4}">full (raster)</text>')
    o.append(f'<rect x="{lx + 1}" y="{ly + 17}" width="10" height="10" fill="{colours["hybrid"]}"/>'
             f'<text x="{lx + 18}" y="{ly + 26}">hybrid</text>')
    o.append(f'<line x1="{lx}" y1="{ly + 44}" x2="{lx + 14}" y2="{ly + 44}" stroke="#2ca02c" stroke-width="2" '
             f'stroke-dasharray="6,4"/><text x="{lx + 18}" y="{ly + 48}">Pareto front</text>')
    o.append(f'<text x="{lx}" y="{ly + 70}" font-size="11">filled = on the front</text>')
    o.append(f'<text x="{lx}" y="{ly + 86}" font-size="11">hollow = dominated</text>')
    o.append(f'<text x="{lx}" y="{ly + 102}" font-size="11">top row: identical</text>')
    o.append(f'<text x="{lx}" y="{ly + 116}" font-size="11">to the reference</text>')
    o.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(o) + "\n")
    return front


# ----------------------------------------------------------------------------- document
md = []
w = md.append


def load_of(name):
    m = S(name).get("machine", {})
    return m.get("load_avg_1min_start", float("nan"))


def fm(name, mode="full"):
    return M(name, mode)["frame_ms_median"]


def tri(name, mode="full"):
    return M(name, mode)["triangles_median"]


plain = S("plain")
mach = plain["machine"]
loads = []
for d in sorted(os.listdir(BENCH)):
    if os.path.exists(os.path.join(BENCH, d, "summary.json")):
        m = S(d).get("machine", {})
        loads += [m.get("load_avg_1min_start"), m.get("load_avg_1min_end")]
loads = [x for x in loads if x is not None]
threads = mach.get("hardware_threads", 2)
busy = max(loads) > 1.5 * threads

# Benches of the 2 km car path with the plain geometry and no per-frame work: their spread is load noise.
SAME = [("plain", "plain city"), ("materials", "materials city (same triangles, other colours)"),
        ("haze2k_car_aa", "haze city with --effects none"), ("plain_repeat", "plain city again, last")]
nf = [fm(n) for n, _ in SAME]
nh = [fm(n, "hybrid") for n, _ in SAME]

w("# Effects declared by the scene: cost and quality")
w("")
w("Regenerated by this command, run from the repository root (it also rewrites the pictures and plots in docs/img/):")
w("")
w("```sh")
w("docs/tools/effects.sh [OUT_DIR] [VISTA_BIN]      # defaults: a temp dir (removed afterwards), build/vista")
w("```")
w("")
w("<!-- effects:begin -->")
w(A.stamp)
w("")
w(f"This run: `{A.invocation}`; {A.elapsed / 60.0:.1f} min of measurements. "
  f"Machine (summary.json): {mach.get('cpu', '?')}, {threads} hardware threads, "
  f"`{mach.get('gl_renderer', '?')}`; 1-minute load average during the benches {min(loads):.1f} – {max(loads):.1f}.")
w("")
w("Every 2 km city is `vista gen --params data/default.json --effects SPEC` (seed 1); the 4 km city adds `--size 4000`, the "
  "knob sweeps of the baked effects `--size 1000`. Every walkthrough is `vista bench CITY --seed 3 --kind car --frames 24 "
  "--size 640x480` (fly where said), modes interleaved per frame, PSNR on luma. Generation times are single runs. "
  "Each bench's load average is given next to its times.")
w("")
w("**Timing noise.** " + ("The machine was busy with other work during this run (load above the core count), so "
  if busy else "") + "frame times carry run-to-run noise; the same geometry with no per-frame work measured: " +
  "; ".join(f"{lab} full {fm(n):.1f} / hybrid {fm(n, 'hybrid'):.1f} ms (load {load_of(n):.1f})" for n, lab in SAME) +
  f". Frame-time differences inside that band (full {min(nf):.1f}–{max(nf):.1f} ms, hybrid {min(nh):.1f}–{max(nh):.1f} ms) "
  "are noise; triangles per frame and rays per frame are exact.")
w("")
w("| | |")
w("|---|---|")
w("| ![sun shadows](../img/effect_shadows.png) | ![haze](../img/effect_haze.png) |")
w("| `sun_shadows`, fly-over | `haze` 1500 m, fly-over |")
w("| ![glass](../img/effect_glass.png) | ![night](../img/effect_night.png) |")
w("| `glass`, car | `night`, car |")
w("")
w("The first `full` frame of the seed 3 path, 640x480, 2 km city.")
w("")

# ---- 1. cost per effect
EFFECTS = ["sun_shadows", "ambient_occlusion", "night", "materials", "glass", "haze"]
KIND = {"sun_shadows": "baked", "ambient_occlusion": "baked", "materials": "baked",
        "night": "baked lights, run-time sky", "glass": "run time", "haze": "run time"}
gp = G("plain")
w("## 1. What each effect costs")
w("")
w(f"Plain city (`--effects none`): {gp['seconds']['total']:.1f} s to generate, {mt(gp['triangles'])} triangles "
  f"({mt(gp['stored_triangles'])} stored). Off = the plain city, on = the city generated with the one effect at its "
  "defaults, same car path.")
w("")
w("| effect | kind | generation s (+ vs plain) | of which lighting s | baked rays | triangles (× plain) "
  "| full triangles/frame off → on | full ms off → on (ratio) | hybrid ms off → on (ratio) "
  "| effect's own ms/frame full / hybrid / raycast (frames it ran) | picture change: PSNR on vs off | load |")
w("|---|---|---|---|---|---|---|---|---|---|---|---|")
free_effects = []
own_ms = {}
for e in EFFECTS:
    g = G(e)
    bl = g.get("baked_lighting") or {}
    light = g["seconds"]["stages"].get("lighting")
    fo, fn = fm("plain"), fm(e)
    ho, hn = fm("plain", "hybrid"), fm(e, "hybrid")
    own, runs = [], None
    for mode in ("full", "hybrid", "raycast"):
        em = M(e, mode).get("effects_ms", {})
        er = M(e, mode).get("effect_runs", {})
        if em:
            own.append(" + ".join(f"{v:.2f}" + ("" if len(em) == 1 else f" {k}") for k, v in sorted(em.items())))
            runs = max(er.values()) if er else runs
        else:
            own.append("0")
    own_ms[e] = own
    own_s = " / ".join(own) + (f" ({runs}/{S(e)['frames']})" if runs is not None else " (nothing per frame)")
    if not any(M(e, m).get("effects_ms") for m in ("full", "hybrid", "raycast")):
        free_effects.append(e)
    pm, _, _ = frames_psnr(e, "full", "plain")
    w(f"| `{e}` | {KIND[e]} | {g['seconds']['total']:.1f} (+{g['seconds']['total'] - gp['seconds']['total']:.1f}) "
      f"| {f1(light)} | {mt(bl['rays']) if bl.get('rays') else '0'} "
      f"| {mt(g['triangles'])} (×{g['triangles'] / gp['triangles']:.2f}) | {tri('plain'):.0f} → {tri(e):.0f} "
      f"| {fo:.1f} → {fn:.1f} ({ratio(fn, fo)}) | {ho:.1f} → {hn:.1f} ({ratio(hn, ho)}) | {own_s} | {db(pm)} "
      f"| {load_of(e):.1f} |")
w("")
w(f"**Free at run time because they are baked:** {', '.join('`' + e + '`' for e in free_effects)}. Nothing of theirs runs "
  "per frame (no entry in `effects_ms`); their only frame cost is the extra triangles: `sun_shadows`, "
  "`ambient_occlusion` and `night` refine surfaces where the light changes "
  f"(×{G('sun_shadows')['triangles'] / gp['triangles']:.2f}, ×{G('ambient_occlusion')['triangles'] / gp['triangles']:.2f}, "
  f"×{G('night')['triangles'] / gp['triangles']:.2f} triangles), `materials` adds none "
  f"(×{G('materials')['triangles'] / gp['triangles']:.2f}), so its frame time differs from the plain city's only by noise. "
  "`night`'s run-time part, the night sky, has no `effects_ms` entry: it costs nothing measurable. "
  "The run-time effects are `glass` (the reflection pass, run only on frames with glass on screen: "
  f"{own_ms['glass'][0]} ms per frame it ran in full) and `haze` ({own_ms['haze'][0]} ms in full, "
  f"{own_ms['haze'][1]} ms in hybrid, {own_ms['haze'][2]} ms in the every-pixel ray caster).")
w("")
w("The whole-frame ms columns mix the effect with load noise (see above): read them with the triangle column. "
  "\"Picture change\" is the median PSNR of the full frames with the effect vs the plain city's: how visible the effect "
  "is on this path (lower = bigger change).")
w("")

# ---- 2. quality knobs
w("## 2. Quality knobs vs a reference with the knob at its maximum")
w("")
w("The baked knobs (`sun_shadows`, `ambient_occlusion`) are swept on the 1 km centre of the same parameters "
  "(`--params data/default.json --size 1000`, seed 1, car path seed 3 of that city): references at 2 km would add "
  "about ten minutes. \"off\" is that city without the effect. The run-time knobs (`glass`, `haze`) use the 2 km city "
  "of section 1, benched again with `--effects '{...}'`.")
w("")
w("PSNR: each run's frames vs the reference run's `full` frames, frame by frame, median (and min) over the 24 frames "
  "(`image_psnr`, luma). The hybrid column compares hybrid frames with the reference's full frames, so it includes "
  "the hybrid's own far-field error. In the plots, x = median frame time, y = that PSNR, full and hybrid points pooled; "
  "the Pareto front (dashed, filled points) holds the runs no other run beats in both. Runs identical to the reference "
  "sit on the top row.")
w("")

KNOBS = {
    "sun_shadows": dict(
        title="sun_shadows resolution_m, 1 km city (ref: 0.5 m, 16 samples)",
        ref="ss_ref", baked=True,
        runs=[("off (no effect)", "off", "plain1k"), ("8 m", "8 m", "ss_r8"), ("4 m", "4 m", "ss_r4"),
              ("2 m (default)", "2 m", "ss_r2"), ("1 m", "1 m", "ss_r1"),
              ("ref: 0.5 m, 16 samples", "ref 0.5 m", "ss_ref")]),
    "ambient_occlusion": dict(
        title="ambient_occlusion samples, 1 km city (ref: 64)",
        ref="ao_s64", baked=True,
        runs=[("off (no effect)", "off", "plain1k"), ("4", "4", "ao_s4"), ("16 (default)", "16", "ao_s16"),
              ("64 = ref", "64 ref", "ao_s64")]),
    "glass": dict(
        title="glass ray_budget, 2 km city (ref: 1e8 rays/frame)",
        ref="glass_b100000000", baked=False,
        runs=[("0", "0", "glass_b0"), ("2000", "2000", "glass_b2000"), ("10000", "10000", "glass_b10000"),
              ("50000 (default)", "50000", "glass"), ("1e8 = ref", "1e8 ref", "glass_b100000000")]),
    "haze": dict(
        title="haze visibility_m, 2 km city (ref: 1e6 m)",
        ref="haze_v1000000", baked=False,
        runs=[("500 m", "500 m", "haze_v500"), ("1500 m (default)", "1500 m", "haze"),
              ("5000 m", "5000 m", "haze_v5000"), ("1e6 m = ref", "1e6 m ref", "haze_v1000000")]),
}
KS = {}
for e, k in KNOBS.items():
    svg = f"effects_pareto_{e}.svg"
    w(f"### `{e}`")
    w("")
    if k["baked"]:
        w("| knob | generation s | lighting s | baked rays | triangles | full triangles/frame | full ms | hybrid ms "
          "| PSNR full vs ref (min) | PSNR hybrid vs ref | load |")
        w("|---|---|---|---|---|---|---|---|---|---|---|")
    else:
        extra = "reflection rays/frame, mean (max)" if e == "glass" else "hybrid rays/frame (median)"
        w(f"| knob | full ms | hybrid ms | effect's own ms/frame full / hybrid | {extra} | PSNR full vs ref (min) "
          "| PSNR hybrid vs ref | load |")
        w("|---|---|---|---|---|---|---|---|")
    pts = []
    for label, short, run in k["runs"]:
        f_ms, h_ms = fm(run), fm(run, "hybrid")
        pf, pfmin, _ = frames_psnr(run, "full", k["ref"])
        ph, _, _ = frames_psnr(run, "hybrid", k["ref"])
        pts.append(dict(x=f_ms, y=pf, label=short, series="full"))
        pts.append(dict(x=h_ms, y=ph, label=short, series="hybrid"))
        KS[(e, short)] = dict(full=f_ms, hybrid=h_ms, pf=pf, ph=ph, run=run)
        if k["baked"]:
            g = G(run)
            bl = g.get("baked_lighting") or {}
            KS[(e, short)].update(gen=g["seconds"]["total"], tris=g["triangles"])
            w(f"| {label} | {g['seconds']['total']:.1f} | {f1(g['seconds']['stages'].get('lighting'))} "
              f"| {mt(bl.get('rays', 0))} | {mt(g['triangles'])} | {tri(run):.0f} | {f_ms:.1f} | {h_ms:.1f} "
              f"| {db(pf)} ({db(pfmin)}) | {db(ph)} | {load_of(run):.1f} |")
        else:
            em = lambda mode: M(run, mode).get("effects_ms", {}).get(e, 0.0)
            if e == "glass":
                mx = max(float(r["rays_cast"]) for r in rows(run, "full"))
                ex = f"{M(run, 'full')['reflection_rays_mean']:.0f} ({mx:.0f})"
            else:
                ex = f"{M(run, 'hybrid')['rays_per_frame_median']:.0f}"
            w(f"| {label} | {f_ms:.1f} | {h_ms:.1f} | {em('full'):.2f} / {em('hybrid'):.2f} | {ex} "
              f"| {db(pf)} ({db(pfmin)}) | {db(ph)} | {load_of(run):.1f} |")
    front = pareto_svg(os.path.join(A.img, svg), k["title"], pts)
    w("")
    w(f"![{e}: PSNR vs frame time](../img/{svg})")
    w("")
    w("Pareto front: " + ", ".join(f"{p['series']} {p['label']}" for p in front) +
      ". Frame-time gaps smaller than the noise band above do not order the points.")
    w("")

w("Reading the knobs:")
w("")
ss = {s: KS[("sun_shadows", s)] for s in ("off", "8 m", "4 m", "2 m", "1 m", "ref 0.5 m")}
w(f"- `sun_shadows`: PSNR vs the 0.5 m / 16-sample reference climbs {ss['8 m']['pf']:.1f} → {ss['4 m']['pf']:.1f} → "
  f"{ss['2 m']['pf']:.1f} → {ss['1 m']['pf']:.1f} dB from 8 m to 1 m (off: {ss['off']['pf']:.1f} dB) while the "
  f"city grows from {mt(ss['8 m']['tris'])} to {mt(ss['1 m']['tris'])} triangles ({mt(ss['ref 0.5 m']['tris'])} at the "
  f"reference) and generation from {ss['8 m']['gen']:.0f} to {ss['1 m']['gen']:.0f} s ({ss['ref 0.5 m']['gen']:.0f} s).")
ao = {s: KS[("ambient_occlusion", s)] for s in ("off", "4", "16", "64 ref")}
ao_note = ""
if ao["4"]["tris"] > ao["16"]["tris"]:
    ao_note = (f" Fewer samples make the city *larger*: 4 samples give {mt(ao['4']['tris'])} triangles against "
               f"{mt(ao['16']['tris'])} at 16 and {mt(ao['64 ref']['tris'])} at 64 — the noisier occlusion estimate "
               "makes the refinement split surfaces where nothing changes — so 4 samples lose on quality, "
               "frame time and (nearly) generation time at once.")
w(f"- `ambient_occlusion`: {ao['4']['pf']:.1f} dB at 4 samples, {ao['16']['pf']:.1f} dB at 16 (default) vs the "
  f"64-sample reference (off: {ao['off']['pf']:.1f} dB); generation {ao['4']['gen']:.0f} / {ao['16']['gen']:.0f} / "
  f"{ao['64 ref']['gen']:.0f} s." + ao_note)
gl = [(s, KS[("glass", s)]) for s in ("0", "2000", "10000", "50000", "1e8 ref")]
ident = [s.replace(" ref", "") for s, v in gl if v["pf"] >= IDENTICAL]
gref = M("glass_b100000000", "full")
gmax = max(float(r["rays_cast"]) for r in rows("glass_b100000000", "full"))
w(f"- `glass`: this path needs {gref['reflection_rays_mean']:.0f} reflection rays per frame on average and "
  f"{gmax:.0f} at most ({gref['glass_pixels_mean']:.0f} glass pixels on average at 640x480), so the budgets "
  f"{', '.join(ident)} all give the reference picture; a budget of 0 (base colour only) is "
  f"{KS[('glass', '0')]['pf']:.1f} dB from it and 2000 rays {KS[('glass', '2000')]['pf']:.1f} dB. The glass pass "
  "costs a few ms per frame it runs whatever the budget above the need." +
  (" With budget 0 the frames are pixel-identical to the plain city's: glass without reflection rays looks like "
   "no glass at all." if frames_psnr("glass_b0", "full", "plain")[1] >= IDENTICAL else ""))
w("- `haze`: the reference (1e6 m) is practically no haze, so this PSNR measures how much the haze changes the picture, "
  "not an error: visibility is an artistic knob. Its quality figure is the hybrid vs full agreement (section 5), "
  "its payoff is section 3.")
w("- Baked knobs cost nothing per frame beyond their triangles; their price is generation time and, through the "
  "triangle count, raster time in `full`.")
w("")

# ---- 3. haze payoff
w("## 3. The haze payoff: rays and time with haze 1500 m vs none")
w("")
w("The hazy city benched on the same path in one run with `--also-clear`: each mode with the city's haze (1500 m) "
  "and without it (its `+clear` twin) render every frame one right after the other, the side that goes first "
  "alternating. Same-frame ratio = median over frames of (haze / none) for the same frame, which cancels the path "
  "and the machine's drift.")
w("")
w("| city | path | hybrid rays/frame, mean: haze / none | hybrid triangles/frame, median: haze / none "
  "| far pixels hitting geometry, mean: haze / none "
  "| hybrid `rays` + `horizon` stages ms: haze / none | hybrid `haze` stage ms | hybrid ms: haze / none (same-frame ratio) "
  "| full triangles/frame, median: haze / none | full ms: haze / none (same-frame ratio) | load |")
w("|---|---|---|---|---|---|---|---|---|---|---|")
# One run each with --also-clear: the modes with the city's haze and their clear twins (MODE+clear)
# render every frame one right after the other, so the same-frame ratios share the machine's drift.
HZ = [("2 km", "car", "haze2k_car"), ("2 km", "fly", "haze2k_fly"), ("4 km", "car", "haze4k_car"),
      ("4 km", "fly", "haze4k_fly"), ("8 km", "car", "haze8k_car"), ("8 km", "fly", "haze8k_fly")]


def mean_rays(run, mode):
    r = rows(run, mode)
    return sum(float(x["rays_cast"]) for x in r) / max(1, len(r))


def twin_ratio(run, mode, col):
    """MODE against its clear twin (MODE+clear) on the same frames of one run."""
    return paired_median_ratio(run, mode, run, mode + "+clear", col)


res3 = []
for city, kind, run in HZ:
    hon, hoff = M(run, "hybrid"), M(run, "hybrid+clear")
    ron, roff = mean_rays(run, "hybrid"), mean_rays(run, "hybrid+clear")
    hit_on, hit_off = hon["pixels"]["ray_hit"]["mean_count"], hoff["pixels"]["ray_hit"]["mean_count"]
    tr = twin_ratio(run, "hybrid", "frame_ms")
    ftr = twin_ratio(run, "full", "frame_ms")
    ton, toff = tri(run), tri(run, "full+clear")
    hton, htoff = tri(run, "hybrid"), tri(run, "hybrid+clear")
    rs_on = hon["stages_ms"].get("rays", 0) + hon["stages_ms"].get("horizon", 0)
    rs_off = hoff["stages_ms"].get("rays", 0) + hoff["stages_ms"].get("horizon", 0)
    w(f"| {city} | {kind} | {ron:.0f} / {roff:.0f} ({pct(ron, roff)}) "
      f"| {hton:.0f} / {htoff:.0f} | {hit_on:.0f} / {hit_off:.0f} "
      f"| {rs_on:.1f} / {rs_off:.1f} | {hon['stages_ms'].get('haze', 0):.2f} "
      f"| {fm(run, 'hybrid'):.1f} / {fm(run, 'hybrid+clear'):.1f} ({f2(tr)}) | {ton:.0f} / {toff:.0f} ({pct(ton, toff)}) "
      f"| {fm(run):.1f} / {fm(run, 'full+clear'):.1f} ({f2(ftr)}) | {load_of(run):.1f} |")
    ta = {r["frame"]: r["triangles"] for r in rows(run, "full")}
    tb = {r["frame"]: r["triangles"] for r in rows(run, "full+clear")}
    ndiff = sum(1 for k in ta if k in tb and ta[k] != tb[k])
    res3.append(dict(city=city, kind=kind, ron=ron, roff=roff, tr=tr, ftr=ftr, ton=ton, toff=toff,
                     hton=hton, htoff=htoff,
                     hit_on=hit_on, hit_off=hit_off, ndiff=ndiff, n=len(ta)))
w("")
w("How the hybrid hazes: the far field's rays stop where their own eye-plane depth reaches the visibility and the "
  "horizon stage ignores, per column, geometry beyond what that column's pixels can reach before it, so sky pixels "
  "over geometry beyond the visibility get no ray; the near field is drawn without haze and hazed in one pass over "
  "the pixels and depth the hybrid reads back anyway (`haze` stage), which costs less on a CPU rasteriser than a "
  "per-fragment program. `full` hazes in the rasteriser (a GLSL program) and its far plane stops at the visibility.")
w("")
w("**Rays.** Each side's split chooses its near distance from its own prices. With haze a far ray stops at the "
  "visibility and the sky over what lies beyond needs none, so the rays per frame move both ways with the near "
  "field: in (more rays, fewer triangles: " +
  (", ".join(f"{r['city']} {r['kind']}" for r in res3 if r["ron"] > 1.01 * r["roff"] and r["hton"] < r["htoff"])
   or "no run") + ") or out (fewer rays, more triangles: " +
  (", ".join(f"{r['city']} {r['kind']}" for r in res3 if r["ron"] < 0.99 * r["roff"] and r["hton"] > r["htoff"])
   or "no run") + "). Far pixels that hit geometry move by " +
  ", ".join(f"{r['city']} {r['kind']} {r['hit_on'] - r['hit_off']:+.0f}" for r in res3) +
  " per frame: hits beyond the visibility become haze, and the rest follow the near distance.")
w("")
# The band of a same-frame ratio: the A/A run's deviation, and never under 3 %.
AA = twin_ratio("haze2k_car_aa", "hybrid", "frame_ms")
TBAND = max(1.03, AA or 1.0, 1.0 / (AA or 1.0))
faster = [r for r in res3 if r["tr"] is not None and r["tr"] * TBAND < 1]
slower = [r for r in res3 if r["tr"] is not None and r["tr"] > TBAND]
w(f"**Time** (same-frame hybrid ratios haze / none; the same run with `--effects none` on the 2 km car path, an "
  f"A/A run, reads {f2(AA)}, and a ratio within {TBAND:.2f} either way of 1 counts as noise): " +
  ("faster beyond the noise on " + ", ".join(f"{r['city']} {r['kind']} ({f2(r['tr'])})" for r in faster) + "; "
   if faster else "faster beyond the noise on no run; ") +
  ("slower beyond the noise on " + ", ".join(f"{r['city']} {r['kind']} ({f2(r['tr'])})" for r in slower) + "; "
   if slower else "slower beyond the noise on no run; ") +
  "within the noise on " + (", ".join(f"{r['city']} {r['kind']} ({f2(r['tr'])})" for r in res3
                                      if r not in faster and r not in slower) or "no run") + ". "
  "Where nothing lies beyond the visibility the haze pass is the whole difference.")
w("")
if tri_drop := [r for r in res3 if r["toff"] and r["ton"] < 0.95 * r["toff"]]:
    w("**The raster path profits where geometry lies beyond 1500 m:** " +
      ", ".join(f"{r['city']} {r['kind']}: {pct(r['ton'], r['toff'])} triangles per frame in full "
                f"(same-frame time ratio {f2(r['ftr'])})" for r in tri_drop) +
      ". " + ("Elsewhere the median triangle count does not move (" +
              ", ".join(f"{r['city']} {r['kind']}: {r['ndiff']} of {r['n']} frames differ in triangles"
                        for r in res3 if r not in tri_drop) +
              "): little or no geometry lies beyond 1500 m in view." if len(tri_drop) < len(res3) else ""))
else:
    w("The full raster draws the same triangles with and without haze on these paths: no geometry beyond 1500 m is "
      "in view, so there is nothing for the haze to save.")
w("")

# ---- 4. glass in view
w("## 4. A frame with no glass in view casts no reflection ray")
w("")
w("From frames.csv of the glass city, `full` rows: every ray `full` casts is a reflection ray, and a frame ran the "
  "glass pass when its `stages_ms` include `reflect`. Budget 0 is the control.")
w("")
w("| run | frames | frames that ran the glass pass (glass on screen) | frames with reflection rays "
  "| pass frames without rays | frames without the pass but with rays | glass pixels (mean) | reflection rays (mean) |")
w("|---|---|---|---|---|---|---|---|")
GLR = [("car, budget 50000", "glass"), ("fly, budget 50000", "glass_fly"), ("car, budget 0", "glass_b0")]
viol = 0
for label, run in GLR:
    fr = rows(run, "full")
    g = [("reflect" in stages(r)) for r in fr]
    ray = [float(r["rays_cast"]) > 0 for r in fr]
    n = len(fr)
    bad = sum(1 for a, b in zip(g, ray) if b and not a)
    viol += bad
    w(f"| {label} | {n} | {sum(g)} ({100 * sum(g) / n:.0f} %) | {sum(ray)} ({100 * sum(ray) / n:.0f} %) "
      f"| {sum(1 for a, b in zip(g, ray) if a and not b)} | {bad} "
      f"| {M(run, 'full')['glass_pixels_mean']:.0f} | {M(run, 'full')['reflection_rays_mean']:.0f} |")
fly = rows("glass_fly", "full")
fly_g = sum("reflect" in stages(r) for r in fly)
car = rows("glass", "full")
car_g = sum("reflect" in stages(r) for r in car)
w("")
w(("The fly-over sees glass in every frame, so it cannot show a glass-free frame; " if fly_g == len(fly) else
   f"Neither path sees glass all the time: the car path has {len(car) - car_g} and the fly-over {len(fly) - fly_g} "
   f"of {len(fly)} frames without glass on screen; ") +
  ("none of the frames without glass cast a reflection ray." if viol == 0 else
   f"**{viol} frames without glass cast reflection rays.**") +
  f" With budget 0 the pass never runs and no ray is cast although glass is on screen "
  f"({M('glass_b0', 'full')['glass_pixels_mean']:.0f} glass pixels per frame on average).")
w("")

# ---- 5. agreement
w("## 5. Raster vs ray caster agreement per effect")
w("")
w("`psnr_db_median` (and min over frames) of hybrid and raycast vs `full` of the same bench, 2 km city, car path; "
  "target: hybrid median ≥ 40 dB.")
w("")
w("| city | hybrid PSNR median (min) | raycast PSNR median (min) | hybrid median ≥ 40 dB |")
w("|---|---|---|---|")
low, lowmin = [], []
for e in ["plain"] + EFFECTS:
    h, r = M(e, "hybrid"), M(e, "raycast")
    ok = h["psnr_db_median"] >= 40
    if not ok:
        low.append(e)
    if h["psnr_db_min"] < 40:
        lowmin.append(f"`{e}` ({h['psnr_db_min']:.1f} dB)")
    w(f"| {'plain (no effect)' if e == 'plain' else '`' + e + '`'} | {h['psnr_db_median']:.1f} ({h['psnr_db_min']:.1f}) "
      f"| {r['psnr_db_median']:.1f} ({r['psnr_db_min']:.1f}) | {'yes' if ok else '**no**'} |")
w("")
fl = [("glass", "glass_fly"), ("haze 1500 m", "haze2k_fly")]
w("Fly-over, hybrid: " + "; ".join(
    f"{lab} {M(run, 'hybrid')['psnr_db_median']:.1f} dB (min {M(run, 'hybrid')['psnr_db_min']:.1f})" for lab, run in fl) + ".")
w("")
w(("Every hybrid median reaches the 40 dB target" if not low else
   "**Below the 40 dB target:** " + ", ".join(low)) +
  ("; single frames fall below 40 dB with " + ", ".join(lowmin) + "." if lowmin else "; so does every frame."))
w("")
w("## 6. Run-time effects only save: the hybrid per path kind")
w("")
w("The hybrid (`--near auto`) with each run-time effect against the same frames without it, on car, walk and fly "
  "paths of the 2 km city (glass marked): haze at three visibilities, the night sky, and glass where it is "
  "off-screen (frames on which no reflection pass ran; on-screen the pass is the effect's own work, section 1). "
  "Each row is one bench run with `--also-clear`: the hybrid with the effect and without it render every frame one "
  "right after the other, the side that goes first alternating, so the machine's drift falls on both; the ratio is "
  "the median over frames of (with / without) on the same frame. A row over 1.03 in its first run is run twice "
  "more and counts with each frame's median over the three runs (column runs): the adaptive split learns its "
  "own prices on each side, so one run moves by about 5 %, as the night rows (no per-frame work) show. The `haze` "
  "stage is the haze of the drawn near field, a task beside the far field's serial stages "
  "(`build/tests/bench/bench_far_field --benchmark_filter=HazeCovered` times it alone); the traced far pixels are "
  "hazed inside the ray tasks as they are written. Regenerated with the rest of this page, or alone by "
  "`docs/tools/effects_haze.sh [OUT_DIR] [VISTA_BIN]` (150 frames a row).")
w("<!-- effects:end -->")
w("")
w("<!-- effects-haze:begin -->")
w("<!-- effects-haze:end -->")
w("")
w("Raw data of a run: OUT_DIR/bench/NAME/{summary.json,frames.csv,frames/}, OUT_DIR/gen/NAME.json (--stats), "
  "every command in OUT_DIR/commands.log.")

with open(A.md, "w") as f:
    f.write("\n".join(md) + "\n")
print(f"wrote {A.md}", file=sys.stderr)
