#!/usr/bin/env python3
"""Checks that long vehicles keep off tight junction turns in a `vista traffic`
directory, reading SUMO's files only (nothing of vista's code):

- every internal lane of city.net.xml that a vehicle class of demand.rou.xml
  may use has a radius at least that class's turning need: the smallest
  radius on which the straight box between a vehicle's front and back cuts
  the inside of the turn by at most --max-cut metres (the sagitta
  R (1 - cos(L / 2R)) of the vehicle's length L), found here by scanning
  radii in 1 cm steps. A lane's radius is that of the circle through its
  bend: the chord between the first and the last vertex where the lane's
  heading turns, over 2 sin(half the heading change); lanes turning by less
  than 10 degrees are straight;
- no vehicle sample of fcd.xml lies on an internal lane closed to its class
  (SUMO routed them around);
- SUMO's statistics.xml reports at most --max-collisions collisions.

Exit 0 when all hold, 1 otherwise (the failures are printed).
Usage: traffic_turns_check.py DIR [--max-cut 1.0] [--max-collisions N]
       [--tolerance 0.5] [--json OUT]
"""
import argparse
import json
import math
import sys
import xml.etree.ElementTree as ET

def points(shape):
    return [tuple(float(v) for v in p.split(",")[:2]) for p in shape.split()]


def bend_radius(pts):
    """Radius of the circle through the lane's bend (chord over angle)."""
    headings = []
    kept = [pts[0]]
    for p in pts[1:]:
        if math.dist(p, kept[-1]) > 1e-6:
            kept.append(p)
    for a, b in zip(kept, kept[1:]):
        headings.append(math.atan2(b[1] - a[1], b[0] - a[0]))
    if len(headings) < 2:
        return math.inf
    turn_at = []  # vertex indices where the heading turns
    total = 0.0
    for i in range(1, len(headings)):
        d = (headings[i] - headings[i - 1] + math.pi) % (2 * math.pi) - math.pi
        total += d
        if abs(d) > 1e-3:
            turn_at.append(i)
    if abs(total) < math.radians(10.0):
        return math.inf
    # The first and the last turning vertex are the ends of the bend: the
    # lane's tangent there is the heading of the part before and after it,
    # so the arc between them turns by the change between those two headings.
    first, last = turn_at[0], turn_at[-1]
    chord = math.dist(kept[first], kept[last])
    angle = abs((headings[last] - headings[first - 1] + math.pi) % (2 * math.pi) - math.pi)
    if angle < 1e-6:
        return math.inf
    return chord / (2.0 * math.sin(0.5 * angle))


def need(length, max_cut):
    r = 0.01
    while r < 1000.0:
        half = length / (2.0 * r)
        if half < math.pi and r * (1.0 - math.cos(half)) <= max_cut:
            return r
        r += 0.01
    return math.inf


def permits(lane, cls):
    allow, disallow = lane.get("allow"), lane.get("disallow")
    if allow is not None:
        return cls in allow.split() or "all" in allow.split()
    if disallow is not None:
        return cls not in disallow.split()
    return True


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dir")
    ap.add_argument("--max-cut", type=float, default=1.0)
    ap.add_argument("--max-collisions", type=int, default=None)
    ap.add_argument("--tolerance", type=float, default=0.5, help="metres of radius the two estimates may differ")
    ap.add_argument("--json")
    a = ap.parse_args()

    types = {}  # vType id -> (vClass, length)
    for vt in ET.parse(a.dir + "/demand.rou.xml").getroot().iter("vType"):
        if vt.get("vClass") != "pedestrian":
            types[vt.get("id")] = (vt.get("vClass"), float(vt.get("length")))
    needs = {cls: need(length, a.max_cut) for cls, length in types.values()}

    failures = []
    closed = {}  # internal lane id -> radius, for lanes closed to some class
    lane_perm = {}
    checked = 0
    for edge in ET.parse(a.dir + "/city.net.xml").getroot().iter("edge"):
        if edge.get("function") != "internal":
            continue
        for lane in edge.iter("lane"):
            r = bend_radius(points(lane.get("shape")))
            lane_perm[lane.get("id")] = lane
            for cls, n in needs.items():
                if permits(lane, cls):
                    checked += 1
                    if r < n - a.tolerance:
                        failures.append(f"{lane.get('id')}: radius {r:.2f} m permits {cls} (needs {n:.2f} m)")
                else:
                    closed.setdefault(lane.get("id"), r)

    on_closed = 0
    for _, el in ET.iterparse(a.dir + "/fcd.xml"):
        if el.tag == "vehicle":
            lane = lane_perm.get(el.get("lane"))
            if lane is not None and not permits(lane, types[el.get("type")][0]):
                on_closed += 1
                if on_closed <= 5:
                    failures.append(f"{el.get('id')} ({el.get('type')}) drives on the closed lane {el.get('lane')}")
        elif el.tag == "timestep":
            el.clear()

    safety = ET.parse(a.dir + "/statistics.xml").getroot().find("safety")
    collisions = int(safety.get("collisions"))
    if a.max_collisions is not None and collisions > a.max_collisions:
        failures.append(f"SUMO reports {collisions} collisions (allowed {a.max_collisions})")

    result = {"needs_m": needs, "lanes_closed": len(closed), "lane_class_pairs_checked": checked,
              "samples_on_closed_lanes": on_closed, "collisions": collisions, "failures": failures}
    if a.json:
        with open(a.json, "w") as f:
            json.dump(result, f, indent=2)
    for f in failures:
        print("FAIL", f)
    print(f"needs {', '.join(f'{c} {n:.2f} m' for c, n in sorted(needs.items()))}; {len(closed)} internal lanes "
          f"closed to some class; {on_closed} samples on closed lanes; {collisions} collisions")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
