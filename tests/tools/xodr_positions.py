#!/usr/bin/env python3
"""Replays a path's OpenDRIVE lane positions on a .xodr file.

Reads a path CSV (t_s,x_m,y_m,z_m,heading_deg,pitch_deg) and its lane
positions (t_s,road_id,lane_id,s_m,t_offset_m, written by
`vista path --xodr-positions`), evaluates every (road, lane, s, t_offset)
from the XML alone with the independent evaluator xodr_check.py (reference
line at s, laneOffset and lane widths at s: the lane's centre, then
t_offset across it) and checks, per sample:

  match      the evaluated point lies within --tolerance metres of the
             path's x, y (both world coordinates);
  in lane    |t_offset| < half the lane's width at s;
  driving    the lane is of a driving type.

With --vista BIN --city CITY.osgb it first makes the paths itself: one car
path per --seeds entry and --rules entry (rht, lht: `vista path --lht`),
written with --xodr-positions into a temporary folder, and checks each.

Exit status: 0 all samples pass, 1 a sample fails (the first offenders are
listed), 2 the input cannot be read.

Usage: xodr_positions.py FILE.xodr PATH.csv POSITIONS.csv [--tolerance 0.05]
       [--min-connecting N]
       xodr_positions.py FILE.xodr --vista BIN --city CITY.osgb [--seeds 1,2,3]
       [--rules rht,lht] [--duration 60] [--tolerance 0.05] [--min-connecting N]
"""
import argparse
import csv
import math
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import xodr_check  # noqa: E402  (the independent evaluator; its checks are not used here)


def read_rows(path, header):
    try:
        with open(path, newline="") as f:
            rows = list(csv.reader(f))
    except OSError as e:
        raise xodr_check.InputError(f"cannot read {path}: {e.strerror}")
    if not rows or rows[0] != header:
        raise xodr_check.InputError(f"{path}: the header is not {','.join(header)}")
    return rows[1:]


def lane_point(net, road_id, lane_id, s, t_offset):
    """(x, y, half width, lane type) of the point t_offset from the centre of lane lane_id at s."""
    road = net.roads.get(str(road_id))
    if road is None:
        raise KeyError(f"road {road_id} does not exist")
    if not (-1e-6 <= s <= road.length + 1e-6):
        raise KeyError(f"s = {s} outside road {road_id} (length {road.length})")
    sec = road.sections[road.section_index(s)]
    if lane_id not in sec.lanes or lane_id == 0:
        raise KeyError(f"road {road_id} has no lane {lane_id} at s = {s}")
    ti, to = road.borders(sec, s)[lane_id]
    x, y, h = road.ref(s)[:3]
    t = 0.5 * (ti + to) + t_offset
    return x - t * math.sin(h), y + t * math.cos(h), 0.5 * abs(to - ti), sec.lanes[lane_id].type, road.junction


def replay(net, path_rows, pos_rows, tolerance):
    """Per-sample results: list of failure strings, worst distance, samples on connecting roads."""
    failures = []
    worst = 0.0
    connecting = 0
    if len(path_rows) != len(pos_rows):
        return [f"{len(path_rows)} path samples but {len(pos_rows)} lane positions"], None, 0
    for i, (p, q) in enumerate(zip(path_rows, pos_rows)):
        t_p, x, y = float(p[0]), float(p[1]), float(p[2])
        t_q, road, lane, s, off = float(q[0]), int(q[1]), int(q[2]), float(q[3]), float(q[4])
        where = f"sample {i} (t = {t_q:g} s, road {road}, lane {lane}, s = {s:g})"
        if abs(t_p - t_q) > 1e-6:
            failures.append(f"{where}: time {t_q} differs from the path's {t_p}")
            continue
        try:
            px, py, half, kind, junction = lane_point(net, road, lane, s, off)
        except KeyError as e:
            failures.append(f"{where}: {e.args[0]}")
            continue
        d = math.hypot(px - x, py - y)
        worst = max(worst, d)
        connecting += junction != "-1"
        if d > tolerance:
            failures.append(f"{where}: evaluates to ({px:.4f}, {py:.4f}), {d:.4f} m from the path's ({x}, {y})")
        if not abs(off) < half:
            failures.append(f"{where}: t_offset {off} is not inside the lane (half width {half:.4f} m)")
        if kind not in xodr_check.DRIVING_TYPES:
            failures.append(f"{where}: lane type {kind} is not a driving lane")
    return failures, worst, connecting


def check_files(net, path_csv, positions_csv, tolerance, min_connecting):
    """Replays one path; prints its summary and failures; True when it passes."""
    try:
        path_rows = read_rows(path_csv, ["t_s", "x_m", "y_m", "z_m", "heading_deg", "pitch_deg"])
        pos_rows = read_rows(positions_csv, ["t_s", "road_id", "lane_id", "s_m", "t_offset_m"])
    except xodr_check.InputError as e:
        print(f"xodr_positions: {e}", file=sys.stderr)
        raise
    failures, worst, connecting = replay(net, path_rows, pos_rows, tolerance)
    if connecting < min_connecting:
        failures.append(f"only {connecting} samples on junction connecting roads (at least {min_connecting} asked)")
    print(f"{os.path.basename(positions_csv)}: {len(pos_rows)} samples, worst distance "
          f"{'-' if worst is None else f'{worst:.5f}'} m (tolerance {tolerance} m), {connecting} on connecting roads, "
          f"{len(failures)} failures")
    for f in failures[:20]:
        print("  " + f)
    return not failures


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("xodr")
    ap.add_argument("files", nargs="*", help="PATH.csv POSITIONS.csv (without --vista)")
    ap.add_argument("--tolerance", type=float, default=0.05, help="metres (default 0.05)")
    ap.add_argument("--min-connecting", type=int, default=0,
                    help="fail unless at least this many samples of each path lie on junction connecting roads")
    ap.add_argument("--vista", help="the vista executable: make the paths with `vista path`")
    ap.add_argument("--city", help="with --vista: the city scene file the .xodr was written with")
    ap.add_argument("--seeds", default="1,2,3", help="with --vista: path seeds (default 1,2,3)")
    ap.add_argument("--rules", default="rht", help="with --vista: traffic rules, rht and/or lht (default rht)")
    ap.add_argument("--duration", type=float, default=60.0, help="with --vista: path seconds (default 60)")
    a = ap.parse_args(argv)
    if bool(a.vista) != bool(a.city) or (not a.vista and len(a.files) != 2) or (a.vista and a.files):
        ap.error("give PATH.csv POSITIONS.csv, or --vista BIN --city CITY.osgb")
    try:
        net = xodr_check.load(a.xodr)
        if not a.vista:
            return 0 if check_files(net, a.files[0], a.files[1], a.tolerance, a.min_connecting) else 1
        ok = True
        with tempfile.TemporaryDirectory(prefix="xodr_positions_") as tmp:
            for rule in a.rules.split(","):
                if rule not in ("rht", "lht"):
                    ap.error(f"--rules: {rule} is not rht or lht")
                for seed in a.seeds.split(","):
                    base = os.path.join(tmp, f"{rule}_seed{seed}")
                    cmd = [a.vista, "path", a.city, "--seed", seed, "--duration", str(a.duration),
                           "-o", base + ".path.csv", "--xodr-positions", base + ".lanes.csv"]
                    if rule == "lht":
                        cmd.append("--lht")
                    p = subprocess.run(cmd, capture_output=True, text=True)
                    if p.returncode != 0:
                        print(f"{' '.join(cmd)} failed ({p.returncode}): {p.stderr.strip()}")
                        ok = False
                        continue
                    print(f"{rule} seed {seed}: ", end="")
                    ok = check_files(net, base + ".path.csv", base + ".lanes.csv", a.tolerance, a.min_connecting) and ok
        return 0 if ok else 1
    except xodr_check.InputError as e:
        print(f"xodr_positions: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
