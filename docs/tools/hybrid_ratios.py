#!/usr/bin/env python3
"""Same-frame ratios of `vista bench` runs (frames.csv), for the hybrid's tables and its guard.

  hybrid_ratios.py split LABEL=DIR[:DIR...] ...  Markdown table: the hybrid (--near auto) against its
                                                 fixed choices (raycast = 0 m, hybrid-fixed = the near
                                                 default, full = everything) in each bench DIR;
                                                 LABEL is "city|path"; with several runs a frame's
                                                 ratio is its median over them.
  hybrid_ratios.py effect LABEL=DIR[:DIR...] ...
                                                 Markdown table: the hybrid's frame with an effect
                                                 against the same frames without it, both from one
                                                 bench run with --also-clear (modes hybrid and
                                                 hybrid+clear, interleaved frame by frame); with
                                                 several runs a frame's ratio is its median over them.
  hybrid_ratios.py guard [--limit 1.05] [--flagged] split LABEL=DIR ... effect LABEL=DIR ...
                                                 prints only the rows where the hybrid loses by more
                                                 than the limit; exit status 1 when any row prints.
                                                 --flagged: prints only those rows' LABEL=DIR specs
                                                 ("split SPEC" / "effect SPEC", one a line) and exits 0.

A ratio is the median over frames f of (time of the hybrid on f) / (time of the other on f): the two
measured on the same frame of the same path. Above 1 = the hybrid is slower.
"""
import csv
import statistics
import sys


def load(d):
    """{mode: {frame: (frame_ms, psnr_db, notes, {stage: ms})}} of DIR/frames.csv."""
    out = {}
    with open(f"{d}/frames.csv") as f:
        for r in csv.DictReader(f):
            stages = {}
            for item in filter(None, r["stages_ms"].split(";")):
                k, v = item.split("=")
                stages[k] = float(v)
            out.setdefault(r["mode"], {})[int(r["frame"])] = (float(r["frame_ms"]), float(r["psnr_db"]), r["notes"],
                                                              stages)
    return out


def ratio(a, b):
    """Median over the frames both have of a[f] / b[f] (dicts frame -> ms)."""
    fs = sorted(set(a) & set(b))
    if not fs:
        raise SystemExit("no common frames")
    return statistics.median(a[f] / b[f] for f in fs)


def ms(frames):
    return {f: v[0] for f, v in frames.items()}


def guarded(frames):
    """How many frames the split's guard held an end point (note "near auto: ... by guard")."""
    return sum(1 for _, _, notes, _ in frames.values() if "by guard" in notes)


def cheapest_ratio(runs, mode):
    """Median over frames of the median over runs of hybrid[f] / min(raycast[f], hybrid-fixed[f], full[f])."""
    others = [o for o, _ in SPLIT_OTHERS if all(o in r for r in runs)]
    frames = set.intersection(*(set(r[mode]).intersection(*(set(r[o]) for o in others)) for r in runs))
    if not others or not frames:
        raise SystemExit("no common frames")
    return statistics.median(statistics.median(r[mode][f][0] / min(r[o][f][0] for o in others) for r in runs)
                             for f in frames)


def choices(frames):
    """How many frames the split chose ray casting, a middle distance, everything."""
    c = [0, 0, 0]
    for _, _, notes, _ in frames.values():
        if "near auto: 0 m" in notes:
            c[0] += 1
        elif "near auto: everything" in notes:
            c[2] += 1
        elif "near auto:" in notes:
            c[1] += 1
    return c


SPLIT_OTHERS = [("raycast", "0 m (raycast)"), ("hybrid-fixed", "near default (hybrid-fixed)"),
                ("full", "everything (full)")]


def runs_ratio(runs, mode, other):
    """Median over frames of the median over runs of hybrid[f] / other[f] (one run: ratio())."""
    frames = set.intersection(*(set(r[mode]) & set(r[other]) for r in runs))
    if not frames:
        raise SystemExit("no common frames")
    return statistics.median(statistics.median(r[mode][f][0] / r[other][f][0] for r in runs) for f in frames)


def split_rows(specs):
    rows = []
    for spec in specs:
        label, dirs = spec.split("=", 1)
        city, path = label.split("|")
        runs = [load(d) for d in dirs.split(":")]
        m = runs[0]
        h = m["hybrid"]
        r = {o: runs_ratio(runs, "hybrid", o) for o, _ in SPLIT_OTHERS if o in m}
        best_ms = {o: statistics.median(v[0] for run in runs for v in run[o].values()) for o in r}
        best = min(best_ms, key=best_ms.get)
        psnr = statistics.median(v[1] for v in h.values())
        # The goal: at most 1.03x the cheapest fixed choice on the same frame, at 40 dB or more.
        target, goal = cheapest_ratio(runs, "hybrid"), 1.03
        goal_text = "≤ 1.03× cheapest"
        rows.append(dict(city=city, path=path, h=statistics.median(v[0] for run in runs for v in run["hybrid"].values()),
                         others=best_ms, r=r, best=best, psnr=psnr, choices=choices(h), guarded=guarded(h),
                         ok=target <= goal and psnr >= 40.0, goal=goal_text, target=target, spec=spec))
    return rows


def split_table(rows):
    lines = ["| city | path | hybrid ms | raycast ms | hybrid-fixed ms | full ms | hybrid / raycast | "
             "hybrid / hybrid-fixed | hybrid / full | hybrid / best fixed | hybrid / cheapest, same frame | "
             "hybrid PSNR vs full, median | split: 0 m / middle / everything frames | guard frames | goal | met |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for x in rows:
        o = x["others"]
        lines.append(
            f"| {x['city']} | {x['path']} | {x['h']:.1f} | {o.get('raycast', float('nan')):.1f} | "
            f"{o.get('hybrid-fixed', float('nan')):.1f} | {o.get('full', float('nan')):.1f} | "
            f"{x['r'].get('raycast', float('nan')):.2f} | {x['r'].get('hybrid-fixed', float('nan')):.2f} | "
            f"{x['r'].get('full', float('nan')):.2f} | {x['r'][x['best']]:.2f} ({x['best']}) | {x['target']:.2f} | "
            f"{x['psnr']:.1f} dB | {' / '.join(map(str, x['choices']))} | {x['guarded']} | {x['goal']} | "
            f"{'yes' if x['ok'] else 'no'} |")
    return "\n".join(lines) + "\n"


def effect_rows(specs, mode="hybrid"):
    rows = []
    for spec in specs:
        label, dirs = spec.split("=", 1)
        runs = [load(d) for d in dirs.split(":")]
        # Glass is judged where it is off-screen: frames on which no run's reflection pass ran
        # (on-screen, the pass is the effect's own work, shown in docs/measurements/effects.md).
        frames = set.intersection(*(set(r[mode]) & set(r[mode + "+clear"]) for r in runs))
        if label.startswith("glass"):
            frames = {f for f in frames if all("reflect" not in r[mode][f][3] for r in runs)}
        if not frames:
            continue
        per_frame = {f: statistics.median(r[mode][f][0] / r[mode + "+clear"][f][0] for r in runs) for f in frames}
        haze = [v[3]["haze"] for r in runs for v in r[mode].values() if "haze" in v[3]]
        rows.append(dict(label=label, spec=spec, on=statistics.median(r[mode][f][0] for r in runs for f in frames),
                         off=statistics.median(r[mode + "+clear"][f][0] for r in runs for f in frames),
                         r=statistics.median(per_frame.values()), runs=len(runs),
                         stage=statistics.mean(haze) if haze else 0.0, frames=len(frames)))
    return rows


def effect_table(rows, header):
    cols = header.count("|") + 1
    lines = [f"| {header} | hybrid ms with, median | hybrid ms without, median | same-frame ratio with / without | "
             "haze stage ms, mean | frames compared | runs |",
             "|" + "---|" * (cols + 6)]
    for x in rows:
        lines.append(f"| {x['label']} | {x['on']:.2f} | {x['off']:.2f} | {x['r']:.3f} | {x['stage']:.2f} | "
                     f"{x['frames']} | {x['runs']} |")
    return "\n".join(lines) + "\n"


def main(argv):
    if not argv:
        raise SystemExit(__doc__)
    if argv[0] == "split":
        sys.stdout.write(split_table(split_rows(argv[1:])))
    elif argv[0] == "effect":
        header = "effect | path"
        sys.stdout.write(effect_table(effect_rows(argv[1:]), header))
    elif argv[0] == "guard":
        limit, flagged = 1.05, False
        args = argv[1:]
        while args[:1] in (["--limit"], ["--flagged"]):
            if args[0] == "--limit":
                limit, args = float(args[1]), args[2:]
            else:
                flagged, args = True, args[1:]
        split, effect, cur = [], [], None
        for a in args:
            if a in ("split", "effect"):
                cur = split if a == "split" else effect
            else:
                cur.append(a)
        bad = 0
        runs = lambda spec: len(spec.split("=", 1)[1].split(":"))
        for x in split_rows(split):
            losing = [(o, name) for o, name in SPLIT_OTHERS if o in x["r"] and x["r"][o] > limit]
            if losing and flagged:
                print(f"split {x['spec']}")
            for o, name in losing if not flagged else []:
                print(f"{x['city']} {x['path']}: hybrid is {x['r'][o]:.3f}x the frame time of {name} "
                      f"({runs(x['spec'])} runs)")
            bad += len(losing)
        for x in effect_rows(effect):
            if x["r"] > limit:
                if flagged:
                    print(f"effect {x['spec']}")
                else:
                    print(f"{x['label']}: hybrid with the effect is {x['r']:.3f}x its frame time without it "
                          f"({x['runs']} runs)")
                bad += 1
        return 1 if bad and not flagged else 0
    else:
        raise SystemExit(__doc__)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
