#!/usr/bin/env python3
"""Checks a traffic directory (`vista traffic`) against its own OpenDRIVE.

Evaluates the centre line of every driving lane of DIR/city.xodr from the XML
alone with the independent evaluator xodr_check.py (reference line, lane
offset and widths), then reads SUMO's floating-car data DIR/fcd.xml (SUMO's
x, y minus the network offset of DIR/traffic.json) and measures, for every
vehicle sample, the distance to the nearest driving-lane centre line:

  on lane   at least --min-share of the vehicle samples lie within
            --tolerance metres of a lane centre line;
  heading   of the samples whose whole body is on a lane of a road outside
            junctions (SUMO's lane and position along it, against the vehicle's
            length), the same share heads along that lane (SUMO's angle against the centre
            line's direction, within --max-heading-deg, either direction
            of travel);
  agents    every agent has a known type and the file is well formed.

SUMO reports a vehicle at the middle of its front bumper, which lies on the
lane's centre line while the vehicle follows the lane; samples taken while a
vehicle changes lanes or turns are the ones allowed off the line.

Exit status: 0 the checks pass, 1 a check fails, 2 the input cannot be read.

Usage: traffic_check.py DIR [--tolerance 0.10] [--min-share 0.99] [--json OUT]
"""
import argparse
import json
import math
import os
import sys
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import xodr_check  # noqa: E402  (the independent evaluator)

DRIVING = xodr_check.DRIVING_TYPES
CELL = 4.0          # grid cell of the segment index, metres
SAMPLE_STEP = 0.5   # spacing of the centre-line samples, metres
KNOWN_TYPES = {"car", "van", "bus", "truck", "bicycle"}


def lane_centres(net):
    """(polyline [(x, y), ...], in a junction) of every driving lane's centre line."""
    lines = []
    for road in net.roads.values():
        for sec in road.sections:
            ids = [i for i, lane in sec.lanes.items() if i != 0 and lane.type in DRIVING]
            if not ids:
                continue
            n = max(2, int(math.ceil((sec.end - sec.s) / SAMPLE_STEP)) + 1)
            pts = {i: [] for i in ids}
            for k in range(n):
                s = sec.s + (sec.end - sec.s) * k / (n - 1)
                s = min(s, sec.end - 1e-9) if k == n - 1 else s
                b = road.border_points(sec, s)
                for i in ids:
                    (xi, yi, _), (xo, yo, _) = b[i]
                    pts[i].append((0.5 * (xi + xo), 0.5 * (yi + yo)))
            lines.extend((p, road.junction != "-1") for p in pts.values())
    return lines


class SegmentGrid:
    def __init__(self, lines, reach):
        self.cells = {}
        self.segs = []
        for line, junction in lines:
            for a, b in zip(line, line[1:]):
                idx = len(self.segs)
                self.segs.append((a, b, junction))
                x0, x1 = min(a[0], b[0]) - reach, max(a[0], b[0]) + reach
                y0, y1 = min(a[1], b[1]) - reach, max(a[1], b[1]) + reach
                for cx in range(int(math.floor(x0 / CELL)), int(math.floor(x1 / CELL)) + 1):
                    for cy in range(int(math.floor(y0 / CELL)), int(math.floor(y1 / CELL)) + 1):
                        self.cells.setdefault((cx, cy), []).append(idx)

    def near(self, x, y, tolerance):
        """(distance of the closest segment in reach or inf, [(direction, in a junction)] of the
        segments within tolerance)."""
        best, close = math.inf, []
        for idx in self.cells.get((int(math.floor(x / CELL)), int(math.floor(y / CELL))), ()):
            (ax, ay), (bx, by), junction = self.segs[idx]
            dx, dy = bx - ax, by - ay
            len2 = dx * dx + dy * dy
            u = 0.0 if len2 == 0 else max(0.0, min(1.0, ((x - ax) * dx + (y - ay) * dy) / len2))
            d = math.hypot(ax + u * dx - x, ay + u * dy - y)
            best = min(best, d)
            if d <= tolerance:
                close.append((math.atan2(dy, dx), junction))
        return best, close


def vehicle_lengths(path):
    """{vType id: length} of the demand file."""
    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError) as e:
        raise xodr_check.InputError(f"cannot read {path}: {e}")
    return {t.get("id"): float(t.get("length", "5")) for t in root.iter("vType")}


def read_fcd(path, off_x, off_y, lengths):
    """Vehicle samples (x, y, heading radians CCW from +x, whole body on one road lane) and the
    count of persons. The body is on one lane when SUMO reports a lane outside junctions
    (not ':...') and a position along it of at least the vehicle's length."""
    samples, persons = [], 0
    try:
        for _, el in ET.iterparse(path, events=("end",)):
            if el.tag == "vehicle":
                vtype = el.get("type")
                if vtype not in KNOWN_TYPES:
                    raise xodr_check.InputError(f"{path}: vehicle {el.get('id')} has the unknown type {vtype!r}")
                x, y = float(el.get("x")) - off_x, float(el.get("y")) - off_y
                heading = math.radians(90.0 - float(el.get("angle")))
                lane, pos = el.get("lane", ":"), float(el.get("pos", "0"))
                samples.append((x, y, heading, not lane.startswith(":") and pos >= lengths.get(vtype, 0.0)))
                el.clear()
            elif el.tag == "person":
                persons += 1
                el.clear()
            elif el.tag == "timestep":
                el.clear()
    except ET.ParseError as e:
        raise xodr_check.InputError(f"{path} is not well-formed XML: {e}")
    except (TypeError, ValueError) as e:
        raise xodr_check.InputError(f"{path}: a sample lacks a numeric x, y or angle ({e})")
    return samples, persons


def check(directory, tolerance, min_share, max_heading_deg):
    try:
        with open(os.path.join(directory, "traffic.json"), encoding="utf-8") as f:
            manifest = json.load(f)
    except (OSError, ValueError) as e:
        raise xodr_check.InputError(f"cannot read {directory}/traffic.json: {e}")
    off_x, off_y = manifest.get("net_offset", [0.0, 0.0])
    net = xodr_check.load(os.path.join(directory, manifest["files"]["xodr"]))
    grid = SegmentGrid(lane_centres(net), max(tolerance, 1.0))
    lengths = vehicle_lengths(os.path.join(directory, manifest["files"]["demand"]))
    samples, persons = read_fcd(os.path.join(directory, manifest["files"]["fcd"]), off_x, off_y, lengths)
    within, on_roads, along, distances = 0, 0, 0, []
    for x, y, heading, whole_body in samples:
        d, close = grid.near(x, y, tolerance)
        distances.append(d)
        if d > tolerance:
            continue
        within += 1
        # The heading is the body's (rear to front bumper): on a junction's
        # curve it differs from the lane's tangent at the front, so it is
        # checked where the whole body is on a road between junctions.
        if not whole_body or any(junction for _, junction in close):
            continue
        on_roads += 1
        if any(math.degrees(abs(math.remainder(heading - direction, math.pi))) <= max_heading_deg
               for direction, _ in close):  # either direction of travel
            along += 1
    distances.sort()
    n = len(samples)

    def pct(p):
        return distances[min(n - 1, int(p * n))] if n else None
    result = {
        "vehicle_samples": n, "person_samples": persons,
        "within_tolerance": within, "share_within": within / n if n else 0.0,
        "samples_on_roads": on_roads, "heading_along": along, "share_along": along / on_roads if on_roads else 0.0,
        "tolerance_m": tolerance, "min_share": min_share,
        "distance_m": {"p50": pct(0.5), "p90": pct(0.9), "p99": pct(0.99)},
    }
    result["pass"] = n > 0 and result["share_within"] >= min_share and result["share_along"] >= min_share
    return result


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("dir")
    ap.add_argument("--tolerance", type=float, default=0.10)
    ap.add_argument("--min-share", type=float, default=0.99)
    ap.add_argument("--max-heading-deg", type=float, default=10.0)
    ap.add_argument("--json")
    opt = ap.parse_args(argv)
    try:
        res = check(opt.dir, opt.tolerance, opt.min_share, opt.max_heading_deg)
    except (xodr_check.InputError, KeyError) as e:
        print(f"traffic_check: {e}", file=sys.stderr)
        return 2
    text = json.dumps(res, indent=2)
    if opt.json:
        with open(opt.json, "w", encoding="utf-8") as f:
            f.write(text + "\n")
    print(text)
    return 0 if res["pass"] else 1


if __name__ == "__main__":
    sys.exit(main())
