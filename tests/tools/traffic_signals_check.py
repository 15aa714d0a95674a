#!/usr/bin/env python3
"""Checks that the vehicles of a traffic directory (`vista traffic`) obey its
traffic lights, from SUMO's own files alone (no vista code):

  DIR/city.net.xml   which junction link (traffic light id, link index) each
                     internal lane starts (<connection via tl linkIndex>);
  DIR/signals.xml    each light's state string at every switch;
  DIR/fcd.xml        every vehicle's lane, position and speed at every step.

  red crossings  a vehicle passes from a lane into a signalised link while
                 the link's light is red ('r' or red-yellow 'u') both at the
                 last step before and the first step after: must be 0;
  red stops      a vehicle stands (speed < 0.1 m/s at two consecutive steps)
                 with its front within --stop-line metres of the end of its
                 lane while the link it takes next is red; at least
                 --min-red-stops of them.

With --ego ID --path CSV (a path of `vista path --traffic DIR --ego ID`), also
checks that the path stands still (moves less than 1 cm a sample) through every
red stop of that vehicle (between the two standing steps), and fails when the
vehicle has none.

Exit status: 0 the checks pass, 1 a check fails, 2 the input cannot be read.
Usage: traffic_signals_check.py DIR [--min-red-stops 1] [--ego ID --path CSV] [--json OUT]
"""
import argparse
import bisect
import csv
import json
import math
import os
import sys
import xml.etree.ElementTree as ET

RED = set("ru")


class InputError(Exception):
    pass


def parse(path):
    try:
        return ET.parse(path).getroot()
    except (ET.ParseError, OSError) as e:
        raise InputError(f"cannot read {path}: {e}")


def read_net(path):
    """({internal lane id: (tl, link index)}, {lane id: length})"""
    root = parse(path)
    links, lengths = {}, {}
    for edge in root.iter("edge"):
        for lane in edge.iter("lane"):
            lengths[lane.get("id")] = float(lane.get("length", "0"))
    for c in root.iter("connection"):
        if c.get("tl") is not None and c.get("via") is not None:
            links[c.get("via")] = (c.get("tl"), int(c.get("linkIndex")))
    return links, lengths


def read_signals(path):
    """{tl: ([times], [states])}"""
    out = {}
    for s in parse(path).iter("tlsState"):
        times, states = out.setdefault(s.get("id"), ([], []))
        times.append(float(s.get("time")))
        states.append(s.get("state"))
    return out


def state_at(signals, tl, index, t):
    times, states = signals.get(tl, ([], []))
    i = bisect.bisect_right(times, t + 1e-9) - 1
    if i < 0 or index >= len(states[i]):
        return None
    return states[i][index]


def read_tracks(path):
    """{vehicle id: [(t, lane, pos, speed, x, y)]}"""
    tracks = {}
    try:
        time = None
        for _, el in ET.iterparse(path, events=("start", "end")):
            if el.tag == "timestep" and time is None:
                time = float(el.get("time"))
            elif el.tag == "timestep":
                time = None
                el.clear()
            elif el.tag == "vehicle" and el.get("lane") is not None:
                tracks.setdefault(el.get("id"), []).append(
                    (time, el.get("lane"), float(el.get("pos")), float(el.get("speed")), float(el.get("x")),
                     float(el.get("y"))))
    except ET.ParseError as e:
        raise InputError(f"{path} is not well-formed XML: {e}")
    return tracks


def analyse(tracks, links, lengths, signals, stop_line):
    crossings, red_crossings, red_stops = 0, [], {}
    for vid, samples in tracks.items():
        for (t0, l0, p0, v0, _, _), (t1, l1, _, _, _, _) in zip(samples, samples[1:]):
            if l0.startswith(":") or l1 not in links:
                continue
            crossings += 1
            tl, idx = links[l1]
            if state_at(signals, tl, idx, t0) in RED and state_at(signals, tl, idx, t1) in RED:
                red_crossings.append({"vehicle": vid, "time": t1, "tl": tl, "link": idx})
        # Stops at the stop line: the next internal lane after a standstill names the link.
        for i, (t, lane, pos, speed, _, _) in enumerate(samples):
            if lane.startswith(":") or speed >= 0.1 or pos < lengths.get(lane, 1e9) - stop_line:
                continue
            nxt = next((s[1] for s in samples[i + 1:] if s[1] != lane), None)
            if nxt not in links:
                continue
            tl, idx = links[nxt]
            # A standstill: this sample and the next both stand, at the same place.
            if i + 1 >= len(samples) or samples[i + 1][3] >= 0.1 or samples[i + 1][1] != lane:
                continue
            if state_at(signals, tl, idx, t) in RED:
                red_stops.setdefault(vid, {}).setdefault(tl, []).append((t, samples[i + 1][0]))
    return crossings, red_crossings, red_stops


def check_ego(path_csv, stops):
    """The path stands still (< 1 cm a sample) at every time the ego stood at a red light."""
    try:
        with open(path_csv, newline="", encoding="utf-8") as f:
            rows = [(float(r["t_s"]), float(r["x_m"]), float(r["y_m"])) for r in csv.DictReader(f)]
    except (OSError, KeyError, ValueError) as e:
        raise InputError(f"cannot read the path {path_csv}: {e}")
    if len(rows) < 2:
        raise InputError(f"the path {path_csv} has fewer than two samples")
    t_first = min(a for spans in stops.values() for a, _ in spans) if stops else None
    # The path's t_s is the traffic's clock (the FCD's time), as the stop times are.
    moved = []
    for tl, spans in stops.items():
        for a, b in spans:
            inside = [r for r in rows if a - 1e-6 <= r[0] <= b + 1e-6]
            for p, q in zip(inside, inside[1:]):
                d = math.hypot(q[1] - p[1], q[2] - p[2])
                if d >= 0.01:
                    moved.append({"tl": tl, "from_s": a, "to_s": b, "moved_m": d})
    return {"red_stops_checked": sum(len(ts) for ts in stops.values()), "moved": moved[:10],
            "first_red_stop_s": t_first, "pass": bool(stops) and not moved}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("dir")
    ap.add_argument("--min-red-stops", type=int, default=1)
    ap.add_argument("--stop-line", type=float, default=3.0)
    ap.add_argument("--ego")
    ap.add_argument("--path")
    ap.add_argument("--json")
    opt = ap.parse_args(argv)
    try:
        with open(os.path.join(opt.dir, "traffic.json"), encoding="utf-8") as f:
            files = json.load(f)["files"]
        links, lengths = read_net(os.path.join(opt.dir, files["net"]))
        signals = read_signals(os.path.join(opt.dir, files["signals"]))
        tracks = read_tracks(os.path.join(opt.dir, files["fcd"]))
        crossings, red_crossings, red_stops = analyse(tracks, links, lengths, signals, opt.stop_line)
        events = sum(len(j) for j in red_stops.values())
        res = {"vehicles": len(tracks), "signalised_crossings": crossings, "red_crossings": len(red_crossings),
               "red_crossing_examples": red_crossings[:10], "red_stop_events": events,
               "vehicles_with_red_stops": sorted(red_stops, key=lambda v: (len(v), v))[:20]}
        res["pass"] = not red_crossings and events >= opt.min_red_stops and crossings > 0
        if opt.ego:
            if not opt.path:
                raise InputError("--ego needs --path")
            stops = red_stops.get(opt.ego, {})
            res["ego"] = check_ego(opt.path, stops)
            res["pass"] = res["pass"] and res["ego"]["pass"]
    except (InputError, KeyError, OSError, ValueError) as e:
        print(f"traffic_signals_check: {e}", file=sys.stderr)
        return 2
    text = json.dumps(res, indent=2)
    if opt.json:
        with open(opt.json, "w", encoding="utf-8") as f:
            f.write(text + "\n")
    print(text)
    return 0 if res["pass"] else 1


if __name__ == "__main__":
    sys.exit(main())
