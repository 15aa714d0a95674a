#!/usr/bin/env python3
"""An independent KITTI tracking reader for `vista render --rig --traffic` runs.

Written from the KITTI tracking devkit's readme, not from vista's writer:
tracking/label_NN/0000.txt holds one sequence, one object per line, 17
space-separated columns (an 18th, the score, only in results): frame, track
id, type ('Car', 'Van', 'Truck', 'Pedestrian', 'Person_sitting', 'Cyclist',
'Tram', 'Misc', 'DontCare'; vista adds 'Bus'), truncated (an integer level 0,
1, 2), occluded (0 .. 3), alpha, bbox left top right bottom (0-based
pixels), dimensions h w l, location x y z, rotation_y. vista's documented
extras read here: tracking/tracks.json (track id -> SUMO id, class,
instance id), instance_NN/*.npy (uint32 instance ids per pixel: kind =
id >> 28, vehicle 11, pedestrian 12; index = id & (2^28 - 1)) and
boxes_3d/*.json (per seen instance its world box centre and velocity).

Checks: every line parses with values in range; a track keeps its type and
its box dimensions (1 cm) in every frame of every camera; its line's bbox is
exactly the extent of its instance id's pixels in that frame's instance image
(the instance id is tracks.json's for the track); between consecutive frames
a vehicle's world box centre moves by its mean velocity times the frame
interval (2 cm beyond half the velocity's change times the interval: SUMO's
poses are linear between its samples, so the velocity may change once
inside it); and at least one vehicle (a type other than Pedestrian) is
followed over >= --min-frames consecutive frames (by any camera). With
--vista it makes the run first: a generated city, `vista traffic` (SUMO),
a path riding one of its cars and a rig of four cameras. Exit 0 when every
check passes, 1 otherwise, 77 without SUMO. Python's standard library only.
"""
import argparse
import array
import ast
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

TYPES = {"Car", "Van", "Truck", "Bus", "Pedestrian", "Person_sitting", "Cyclist", "Tram", "Misc", "DontCare"}
KIND_VEHICLE, KIND_PEDESTRIAN = 11, 12

CAM = {"width": 160, "height": 100, "fx": 80, "fy": 80, "cx": 79.5, "cy": 49.5}
RIG = {"sensors": [
    {"name": "front", "type": "pinhole", "rate_hz": 10, "pose": {"x": 0.5, "z": 0.3}, "intrinsics": CAM,
     "channels": ["instance", "boxes"]},
    {"name": "rear", "type": "pinhole", "rate_hz": 10, "pose": {"x": -0.5, "z": 0.3, "yaw_deg": 180},
     "intrinsics": CAM, "channels": ["instance", "boxes"]},
    {"name": "left", "type": "pinhole", "rate_hz": 10, "pose": {"y": 0.5, "z": 0.3, "yaw_deg": 90},
     "intrinsics": CAM, "channels": ["instance", "boxes"]},
    {"name": "right", "type": "pinhole", "rate_hz": 10, "pose": {"y": -0.5, "z": 0.3, "yaw_deg": -90},
     "intrinsics": CAM, "channels": ["instance", "boxes"]},
]}


class Failures:
    def __init__(self):
        self.items = []

    def check(self, ok, message):
        if not ok:
            self.items.append(message)
        return ok


def read_tracking(path, fails):
    """The lines of one sequence file as dicts."""
    rows = []
    for n, line in enumerate(open(path), 1):
        c = line.split()
        if not fails.check(len(c) in (17, 18), f"{path}:{n}: {len(c)} columns, expected 17 (or 18 with a score)"):
            continue
        try:
            r = {"frame": int(c[0]), "track": int(c[1]), "type": c[2], "truncated": int(c[3]),
                 "occluded": int(c[4]), "alpha": float(c[5]), "bbox": [float(x) for x in c[6:10]],
                 "dims": [float(x) for x in c[10:13]], "loc": [float(x) for x in c[13:16]], "ry": float(c[16])}
        except ValueError as e:
            fails.check(False, f"{path}:{n}: {e}")
            continue
        fails.check(r["type"] in TYPES, f"{path}:{n}: type {r['type']}")
        fails.check(r["truncated"] in (0, 1, 2), f"{path}:{n}: truncated {r['truncated']} is not a level 0, 1, 2")
        fails.check(r["occluded"] in (0, 1, 2, 3), f"{path}:{n}: occluded {r['occluded']}")
        fails.check(abs(r["alpha"]) <= math.pi + 0.01 and abs(r["ry"]) <= math.pi + 0.01, f"{path}:{n}: angles")
        fails.check(r["track"] >= 0, f"{path}:{n}: track id {r['track']}")
        rows.append(r)
    return rows


def load_npy_u32(path):
    """A 2D little-endian uint32 .npy file (format 1.0): (rows, columns, flat values)."""
    data = open(path, "rb").read()
    if data[:6] != b"\x93NUMPY":
        raise SystemExit(f"{path}: not a .npy file")
    hl = int.from_bytes(data[8:10], "little")
    header = ast.literal_eval(data[10:10 + hl].decode("latin1"))
    if header["descr"] != "<u4" or header["fortran_order"] or len(header["shape"]) != 2:
        raise SystemExit(f"{path}: expected a 2D <u4 array, got {header}")
    values = array.array("I")
    values.frombytes(data[10 + hl:])
    if sys.byteorder != "little":
        values.byteswap()
    rows, cols = header["shape"]
    if len(values) != rows * cols:
        raise SystemExit(f"{path}: {len(values)} values for shape {header['shape']}")
    return rows, cols, values


def extent(image, iid):
    """The inclusive pixel extent [left, top, right, bottom] of an id, None when it has no pixel."""
    rows, cols, values = image
    box = None
    for i, v in enumerate(values):
        if v == iid:
            x, y = i % cols, i // cols
            box = [x, y, x, y] if box is None else [min(box[0], x), min(box[1], y), max(box[2], x), max(box[3], y)]
    return box


def close(a, b, tol):
    return all(abs(x - y) <= tol for x, y in zip(a, b))


def longest_run(frames):
    best = run = 0
    last = None
    for f in sorted(frames):
        run = run + 1 if last is not None and f == last + 1 else 1
        best = max(best, run)
        last = f
    return best


def check_run(run, min_frames):
    fails = Failures()
    rig = json.load(open(os.path.join(run, "rig.json")))
    names = {f["frame"]: f["name"] for f in rig["frames"]}
    times = {f["frame"]: f["t_s"] for f in rig["frames"]}
    tracks = {t["track_id"]: t for t in json.load(open(os.path.join(run, "tracking", "tracks.json")))["tracks"]}
    seen = {}    # track -> frames
    types, dims = {}, {}
    lines = 0
    for cam, rel in rig["tracking"]["labels"].items():
        k = next(s["index"] for s in rig["sensors"] if s["name"] == cam)
        rows = read_tracking(os.path.join(run, rel), fails)
        by_frame = {}
        for r in rows:
            by_frame.setdefault(r["frame"], []).append(r)
        for f, rs in sorted(by_frame.items()):
            if not fails.check(f in names, f"{cam}: frame {f} is not a frame of the run"):
                continue
            ids = load_npy_u32(os.path.join(run, f"instance_{k:02d}", names[f] + ".npy"))
            for r in rs:
                lines += 1
                t = r["track"]
                if not fails.check(t in tracks, f"{cam} frame {f}: track {t} is not in tracks.json"):
                    continue
                iid = tracks[t]["instance_id"]
                fails.check(iid >> 28 in (KIND_VEHICLE, KIND_PEDESTRIAN) and iid & ((1 << 28) - 1) == t,
                            f"track {t}: instance id {iid} is not an agent's with index {t}")
                box = extent(ids, iid)
                if not fails.check(box is not None, f"{cam} frame {f}: track {t} has no pixel"):
                    continue
                fails.check(close(box, r["bbox"], 0.006),
                            f"{cam} frame {f}: track {t} bbox {r['bbox']}, its pixels span {box}")
                fails.check(types.setdefault(t, r["type"]) == r["type"],
                            f"track {t} changes type: {types[t]} -> {r['type']}")
                fails.check(close(dims.setdefault(t, r["dims"]), r["dims"], 0.011),
                            f"track {t} changes dimensions: {dims[t]} -> {r['dims']}")
                seen.setdefault(t, set()).add(f)
    # Motion: a vehicle's world centre against its velocity (boxes_3d) between consecutive frames.
    boxes = {}
    for f, name in names.items():
        p = os.path.join(run, "boxes_3d", name + ".json")
        if os.path.exists(p):
            boxes[f] = {b["id"]: b for b in json.load(open(p))["boxes"]}
    worst_motion = 0.0
    steps = 0
    for t, frames in seen.items():
        if types[t] == "Pedestrian":
            continue
        iid = tracks[t]["instance_id"]
        for f in sorted(frames):
            a, b = boxes.get(f, {}).get(iid), boxes.get(f + 1, {}).get(iid)
            if a is None or b is None:
                continue
            dt = times[f + 1] - times[f]
            moved = [q - p for p, q in zip(a["world"]["center"], b["world"]["center"])]
            says = [0.5 * (p + q) * dt for p, q in zip(a["world"]["velocity"], b["world"]["velocity"])]
            # SUMO's poses are linear between its samples: where the velocity changes inside the
            # interval, the mean of the two velocities errs by at most half the change times dt.
            change = math.dist(a["world"]["velocity"], b["world"]["velocity"])
            err = math.dist(moved, says) - 0.5 * change * dt
            worst_motion = max(worst_motion, err)
            steps += 1
            fails.check(err <= 0.02, f"track {t} frames {f}->{f + 1}: moved {moved}, velocity says {says}")
    vehicles = {t: longest_run(fr) for t, fr in seen.items() if types[t] != "Pedestrian"}
    best = max(vehicles.values(), default=0)
    fails.check(best >= min_frames, f"no vehicle followed over {min_frames} consecutive frames (longest {best})")
    fails.check(steps > 0, "no vehicle seen in two consecutive frames")
    stats = {"lines": lines, "tracks": len(seen), "vehicles": len(vehicles), "longest_vehicle_run": best,
             "vehicles_over_min": sum(1 for n in vehicles.values() if n >= min_frames),
             "motion_steps": steps, "worst_motion_m": round(worst_motion, 4)}
    print("kitti_tracking_check:", json.dumps(stats))
    for m in fails.items[:40]:
        print("FAIL:", m)
    return 1 if fails.items else 0


def busiest_ride(fcd, seconds, radius=60.0):
    """The car (type "car" in SUMO's FCD) present for at least `seconds` from its first sample
    with the most other agents within `radius` metres over those seconds (ties by id): a ride
    that sees traffic, whatever the demand's mix. None when no car qualifies."""
    first, last, company = {}, {}, {}
    for step in ET.parse(fcd).getroot():
        t = float(step.get("time"))
        agents = [(a.get("id"), a.get("type"), float(a.get("x")), float(a.get("y"))) for a in step]
        for aid, kind, x, y in agents:
            first.setdefault(aid, t)
            last[aid] = t
            if kind != "car" or t > first[aid] + seconds:
                continue
            company[aid] = company.get(aid, 0) + sum(
                1 for bid, _, bx, by in agents if bid != aid and math.hypot(bx - x, by - y) < radius)
    rides = [a for a in company if last[a] - first[a] >= seconds]
    return min(rides, key=lambda a: (-company[a], a)) if rides else None


def render(vista, d, frames, seed):
    def run(*args):
        r = subprocess.run([vista, *map(str, args)], capture_output=True, text=True)
        if r.returncode != 0:
            raise SystemExit(f"vista {' '.join(map(str, args))} failed ({r.returncode}): {r.stderr}")
    city, traffic, path, rig, out = (os.path.join(d, n) for n in ("city.osgb", "traffic", "ego.csv", "rig.json", "out"))
    with open(rig, "w") as f:
        json.dump(RIG, f)
    run("gen", "--size", 700, "--detail", 0, "--seed", 5, "-q", "-o", city)
    run("traffic", city, "--vehicles", 300, "--pedestrians", 30, "--duration", 120, "--seed", 4, "-q", "-o", traffic)
    if seed is None:
        ride = busiest_ride(os.path.join(traffic, "fcd.xml"), frames / 10 + 1)
        if ride is None:
            raise SystemExit(f"no car of the traffic rides for {frames / 10 + 1} s")
        seed_or_ego = ["--ego", ride]
    else:
        seed_or_ego = ["--seed", seed]
    run("path", city, "--traffic", traffic, *seed_or_ego, "--duration", frames / 10 + 1, "--dt", 0.1, "-o", path)
    run("render", city, "--path", path, "--rig", rig, "--traffic", traffic, "--frames", frames,
        "--sampling", "consecutive", "-q", "--out", out)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--vista", help="make a run with traffic with this vista binary, then check it")
    ap.add_argument("--run", help="check an existing rig run with traffic")
    ap.add_argument("--min-frames", type=int, default=50, help="consecutive frames a vehicle must be followed over")
    ap.add_argument("--frames", type=int, default=60, help="with --vista: frames rendered (10 Hz)")
    ap.add_argument("--seed", type=int, help="with --vista: picks the car the path rides (default: the car with the most agents around it)")
    a = ap.parse_args()
    if a.run:
        return check_run(a.run, a.min_frames)
    if not a.vista:
        ap.error("give --vista or --run")
    if not (shutil.which("sumo") and shutil.which("netconvert")):
        print("kitti_tracking_check: SUMO is not installed; skipped")
        return 77
    with tempfile.TemporaryDirectory() as d:
        return check_run(render(a.vista, d, a.frames, a.seed), a.min_frames)


if __name__ == "__main__":
    sys.exit(main())
