#!/usr/bin/env python3
"""An independent reader of the traffic-light state labels of `vista render --rig --traffic` runs.

Written from the label format (docs/formats.md "Traffic-light labels") and
SUMO's own files, not from vista's writer: traffic_lights_NN/NNNNNN.txt holds
one line per traffic-light head camera NN sees in that frame,
"head state left top right bottom pixels instance_id" (state green, amber,
red-amber, red or off; the box in inclusive pixel indices; instance_id =
8 << 28 | head, the value of the head's pixels in instance_NN/NNNNNN.npy);
rig.json gives each frame's name and time t_s and each camera's folders.

The expected lamp comes from the traffic directory alone:
  DIR/city.net.xml  a signalised junction link is an internal lane carrying
                    <param key="signalID" value="HEAD"/> (netconvert keeps the
                    OpenDRIVE <signal id>), and the <connection via="LANE"
                    tl="LIGHT" linkIndex="I"/> through that lane;
  DIR/signals.xml   <tlsState time id state/>: a light's state string from
                    that time on, one letter per link index.
A head shows green when any of its links is green (G, g), else amber (y, Y),
else red-amber (u), else red (r, R, s), else off; before its light's first
record, or without links, off.

Checks: every line parses, its instance id is the head's traffic-light id,
its box and pixel count are exactly those of the id's pixels in the frame's
instance image, and its state is the lamp SUMO's files give at the frame's
time; every traffic-light id in an instance image has a line (and so a head
out of view or hidden has none: lines and visible heads are the same set);
at least --min-labels lines, --min-states different states, and a head
labelled in one frame and absent (no pixel, no line) in another. With --vista
it makes the runs first (a generated city, `vista traffic` with SUMO, a path
riding a car that stops at a red light, a rig of two cameras, and a one-camera
`vista render --channels instance` along the same path: traffic_lights/ and
cameras.json instead of rig.json), and checks that the same rig without
--traffic writes no traffic-light labels. Exit 0 when every check
passes, 1 otherwise, 77 without SUMO (or without a display and xvfb-run). Python's standard library only.
"""
import argparse
import array
import ast
import bisect
import json
import os
import shutil
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

KIND_TRAFFIC_LIGHT = 8
STATES = ("green", "amber", "red-amber", "red", "off")

CAM = {"width": 160, "height": 100, "fx": 80, "fy": 80, "cx": 79.5, "cy": 49.5}
RIG = {"sensors": [
    {"name": "front", "type": "pinhole", "rate_hz": 2, "pose": {"x": 0.5, "z": 0.3}, "intrinsics": CAM,
     "channels": ["instance", "boxes"]},
    {"name": "right", "type": "pinhole", "rate_hz": 2, "pose": {"y": -0.5, "z": 0.3, "yaw_deg": -45},
     "intrinsics": CAM, "channels": ["instance", "boxes"]},
]}


class Failures:
    def __init__(self):
        self.items = []

    def check(self, ok, message):
        if not ok:
            self.items.append(message)
        return ok


def read_heads(traffic):
    """{head: [(light, link index)]} from the network's signalised internal lanes."""
    root = ET.parse(os.path.join(traffic, "city.net.xml")).getroot()
    lane_heads = {}
    for edge in root.iter("edge"):
        for lane in edge.iter("lane"):
            for p in lane.iter("param"):
                if p.get("key") == "signalID":
                    lane_heads.setdefault(lane.get("id"), []).append(int(p.get("value")))
    heads = {}
    for c in root.iter("connection"):
        via, tl, index = c.get("via"), c.get("tl"), c.get("linkIndex")
        if via is None or tl is None or index is None:
            continue
        for h in lane_heads.get(via, []):
            heads.setdefault(h, []).append((tl, int(index)))
    return heads


def read_states(traffic):
    """{light: ([times], [state strings])} in file order."""
    lights = {}
    for _, e in ET.iterparse(os.path.join(traffic, "signals.xml")):
        if e.tag == "tlsState":
            times, states = lights.setdefault(e.get("id"), ([], []))
            times.append(float(e.get("time")))
            states.append(e.get("state"))
            e.clear()
    return lights


def lamp(heads, lights, head, t):
    letters = ""
    for light, index in heads.get(head, []):
        times, states = lights.get(light, ([], []))
        i = bisect.bisect_right(times, t) - 1
        if i >= 0 and index < len(states[i]):
            letters += states[i][index]
    if any(c in "Gg" for c in letters):
        return "green"
    if any(c in "yY" for c in letters):
        return "amber"
    if "u" in letters:
        return "red-amber"
    if any(c in "rRs" for c in letters):
        return "red"
    return "off"


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
    return rows, cols, values


def light_extents(image):
    """{traffic-light instance id: [left, top, right, bottom, pixels]} of an instance image."""
    rows, cols, values = image
    out = {}
    for i, v in enumerate(values):
        if v >> 28 != KIND_TRAFFIC_LIGHT:
            continue
        x, y = i % cols, i // cols
        b = out.get(v)
        out[v] = [x, y, x, y, 1] if b is None else [min(b[0], x), min(b[1], y), max(b[2], x), max(b[3], y), b[4] + 1]
    return out


def views(run, fails):
    """(camera, labels folder, instance folder, [(frame, name, t_s)]) of a rig run (rig.json: each
    camera listing boxes) or of a one-camera run (cameras.json: traffic_lights/ beside instance/)."""
    if os.path.exists(os.path.join(run, "rig.json")):
        rig = json.load(open(os.path.join(run, "rig.json")))
        out = []
        for s in rig["sensors"]:
            if "boxes" not in s.get("channels", []):
                continue
            dirs = s.get("dirs", {})
            if not fails.check(dirs.get("traffic_lights") is not None,
                               f"{s['name']}: lists boxes but has no traffic_lights folder"):
                continue
            frames = [(f["frame"], f["name"], f["t_s"]) for f in rig["frames"] if s["name"] in f["sensors"]]
            out.append((s["name"], dirs["traffic_lights"], dirs["instance"], frames))
        return out
    cams = json.load(open(os.path.join(run, "cameras.json")))
    return [("camera", "traffic_lights", "instance", [(f["frame"], f["name"], f["t_s"]) for f in cams["frames"]])]


def check_run(run, traffic, min_labels, min_states):
    fails = Failures()
    heads, lights = read_heads(traffic), read_states(traffic)
    labels, states = 0, {}
    seen = {}  # head -> (camera, frame) with a line
    frames_checked = set()
    for cam, lights_dir, inst_dir, frames in views(run, fails):
        for frame, name, t in frames:
            path = os.path.join(run, lights_dir, name + ".txt")
            if not fails.check(os.path.exists(path), f"{path} is missing"):
                continue
            visible = light_extents(load_npy_u32(os.path.join(run, inst_dir, name + ".npy")))
            frames_checked.add((cam, frame))
            listed = set()
            for n, line in enumerate(open(path), 1):
                c = line.split()
                where = f"{path}:{n}"
                if not fails.check(len(c) == 8, f"{where}: {len(c)} columns, expected 8"):
                    continue
                try:
                    head, box, iid = int(c[0]), [int(x) for x in c[2:7]], int(c[7])
                except ValueError as e:
                    fails.check(False, f"{where}: {e}")
                    continue
                state = c[1]
                labels += 1
                fails.check(state in STATES, f"{where}: state {state}")
                fails.check(iid == (KIND_TRAFFIC_LIGHT << 28 | head), f"{where}: instance id {iid} is not head {head}'s")
                fails.check(iid not in listed, f"{where}: head {head} listed twice")
                listed.add(iid)
                fails.check(visible.get(iid) == box, f"{where}: box and pixels {box}, the instance image has "
                                                    f"{visible.get(iid)}")
                want = lamp(heads, lights, head, t)
                fails.check(state == want, f"{where}: head {head} at t={t}: {state}, SUMO's files say {want}")
                states[state] = states.get(state, 0) + 1
                seen.setdefault(head, set()).add((cam, frame))
            for iid in visible:
                fails.check(iid in listed, f"{path}: head {iid & ((1 << 28) - 1)} has pixels but no line")
    fails.check(labels >= min_labels, f"{labels} labels, expected at least {min_labels}")
    fails.check(len(states) >= min_states, f"states seen {sorted(states)}, expected at least {min_states} kinds")
    # A head labelled in some frame and absent from another frame of the same camera has no line there.
    absent = [(h, k) for h, fr in seen.items() for k in frames_checked if k not in fr]
    fails.check(absent, "no head is out of view in any frame (the absence of a label is not exercised)")
    stats = {"labels": labels, "heads": len(seen), "states": states, "frames": len(frames_checked),
             "absent_head_frames": len(absent), "linked_heads": len(heads)}
    print("traffic_light_labels_check:", json.dumps(stats, sort_keys=True))
    for m in fails.items[:40]:
        print("FAIL:", m)
    return 1 if fails.items else 0


def run_vista(vista, *args, display=False):
    """Runs vista; `display`: the command draws with OpenGL (under xvfb-run -a when DISPLAY is not set)."""
    prefix = ["xvfb-run", "-a"] if display and not os.environ.get("DISPLAY") else []
    r = subprocess.run([*prefix, vista, *map(str, args)], capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"vista {' '.join(map(str, args))} failed ({r.returncode}): {r.stderr}")


def render(vista, d, frames):
    city, traffic, path, rig = (os.path.join(d, n) for n in ("city.osgb", "traffic", "ego.csv", "rig.json"))
    with open(rig, "w") as f:
        json.dump(RIG, f)
    run_vista(vista, "gen", "--size", 700, "--detail", 0, "--seed", 5, "-q", "-o", city)
    run_vista(vista, "traffic", city, "--vehicles", 200, "--pedestrians", 0, "--duration", 120, "--seed", 4, "-q",
              "-o", traffic)
    # Ride a vehicle that stops at a red light (traffic_signals_check.py, from SUMO's files): its
    # front camera watches the heads of that junction switch.
    stops = os.path.join(d, "signals.json")
    subprocess.run([sys.executable, os.path.join(os.path.dirname(os.path.abspath(__file__)), "traffic_signals_check.py"),
                    traffic, "--json", stops], capture_output=True)
    riders = json.load(open(stops)).get("vehicles_with_red_stops", [])
    if not riders:
        raise SystemExit("traffic_light_labels_check: no vehicle of the traffic stops at a red light")
    run_vista(vista, "path", city, "--traffic", traffic, "--ego", riders[0], "--duration", frames / 2, "--dt", 0.5,
              "-o", path)
    samples = sum(1 for _ in open(path)) - 1
    out = os.path.join(d, "out")
    run_vista(vista, "render", city, "--path", path, "--rig", rig, "--traffic", traffic, "--frames",
              min(frames, samples), "--sampling", "consecutive", "-q", "--out", out)
    camera = os.path.join(d, "camera")
    run_vista(vista, "render", city, "--path", path, "--traffic", traffic, "--frames", min(frames, samples),
              "--sampling", "consecutive", "--size", "160x100", "--channels", "instance", "-q", "--out", camera,
              display=True)
    plain = os.path.join(d, "plain")
    run_vista(vista, "render", city, "--path", path, "--rig", rig, "--frames", 2, "--sampling", "consecutive", "-q",
              "--out", plain)
    return out, camera, traffic, plain


def check_plain(plain):
    """A run without --traffic: no traffic-light folder, no traffic_lights entry naming one."""
    extra = [n for n in os.listdir(plain) if n.startswith("traffic_lights")]
    rig = json.load(open(os.path.join(plain, "rig.json")))
    named = [s["name"] for s in rig["sensors"] if s.get("dirs", {}).get("traffic_lights") is not None]
    if extra or named:
        print(f"FAIL: a run without --traffic has traffic-light labels: {extra} {named}")
        return 1
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--vista", help="make a run with traffic with this vista binary, then check it")
    ap.add_argument("--run", help="check an existing rig run with traffic (with --traffic DIR)")
    ap.add_argument("--traffic", help="with --run: the run's traffic directory")
    ap.add_argument("--min-labels", type=int, default=20, help="labels the run must hold")
    ap.add_argument("--min-states", type=int, default=2, help="different lamp states the labels must show")
    ap.add_argument("--frames", type=int, default=120, help="with --vista: frames rendered (2 Hz)")
    a = ap.parse_args()
    if a.run:
        if not a.traffic:
            ap.error("--run needs --traffic")
        return check_run(a.run, a.traffic, a.min_labels, a.min_states)
    if not a.vista:
        ap.error("give --vista or --run")
    if not (shutil.which("sumo") and shutil.which("netconvert")):
        print("traffic_light_labels_check: SUMO is not installed; skipped")
        return 77
    if not os.environ.get("DISPLAY") and not shutil.which("xvfb-run"):
        print("traffic_light_labels_check: no DISPLAY and no xvfb-run for the one-camera render; skipped")
        return 77
    with tempfile.TemporaryDirectory() as d:
        out, camera, traffic, plain = render(a.vista, d, a.frames)
        return (check_run(out, traffic, a.min_labels, a.min_states) |
                check_run(camera, traffic, a.min_labels, a.min_states) | check_plain(plain))


if __name__ == "__main__":
    sys.exit(main())
