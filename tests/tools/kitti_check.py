#!/usr/bin/env python3
"""An independent KITTI / SemanticKITTI reader for `vista render --rig` runs.

Written from the public format descriptions (the KITTI object devkit's
readme, the way pykitti and mmdetection3d read calib.txt, and the
SemanticKITTI API's label layout), not from vista's writer:

- calib.txt: "key: numbers" lines; the first seven are P0, P1, P2, P3,
  R0_rect, Tr_velo_to_cam, Tr_imu_to_velo (mmdetection3d reads them by line
  index, splitting on single spaces). A LiDAR point X reaches camera k's
  pixel through P_k . R0_rect . Tr_velo_to_cam . X.
- label_NN/*.txt: KITTI object lines (type, truncated, occluded, alpha, bbox
  left top right bottom, dimensions h w l, location x y z of the bottom
  centre and rotation_y in the rectified frame), plus vista's 16th column,
  the instance id. Box corners as the devkit builds them: length along x,
  height up (-y), width along z, rotated about y by rotation_y.
- velodyne/*.bin: float32 x, y, z, reflectance; velodyne_time/*.bin: float32
  seconds per point; labels/*.label: uint32, SemanticKITTI class in the
  lower 16 bits, instance in the upper 16; semantic-kitti.yaml: `labels`
  (id -> name); lidar_instance/*.bin: uint32 vista instance id per point,
  and instance_NN/*.npy / depth_NN/*.npy: the camera's instance ids and
  z-depth (vista's documented encoding: kind = id >> 28).

With --vista it generates a small city (flat, then hilly), renders a rig of four pinhole
cameras pitched +-10 degrees and rolled +-5 degrees (and a fisheye) with a
LiDAR, and checks: calib's line order and meaning; every label box of every
camera holds >= 95 % of its instance's LiDAR points (instances with at
least 10 points; a 2 cm margin for the 1 mm rounding of the label text) and
its corners projected with P_k enclose its 2D box (1 px); the SemanticKITTI
class of every LiDAR point that a camera sees (its depth within 2 % of the
camera's depth image) agrees with the kind of the camera's instance id at
that pixel (>= 95 %), and the upper 16 bits name each object instance
with one id, distinct between instances; every point has a time within
the sweep; road and junction surfaces, which overlap where a junction
meets its roads, are the same one for the LiDAR and the cameras (at most
0.1 % of those points see the other surface with no agreeing pixel within
one pixel of their projection). With --run DIR it checks an existing run. Exit 0 when every
check passes, 1 otherwise, 77 without numpy.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

try:
    import numpy as np
except ImportError:  # pragma: no cover
    print("kitti_check: numpy is not installed; skipped")
    sys.exit(77)

RIG = {"sensors": [
    {"name": "front", "type": "pinhole", "rate_hz": 10,
     "pose": {"x": 0.3, "z": 0.4, "pitch_deg": -10, "roll_deg": 5},
     "intrinsics": {"width": 160, "height": 120, "fx": 90, "fy": 90, "cx": 79.5, "cy": 59.5},
     "channels": ["depth", "instance", "boxes"]},
    {"name": "rear", "type": "pinhole", "rate_hz": 10,
     "pose": {"x": -0.5, "y": 0.1, "z": 0.3, "yaw_deg": 180, "pitch_deg": 10, "roll_deg": -5},
     "intrinsics": {"width": 160, "height": 120, "fx": 90, "fy": 90, "cx": 79.5, "cy": 59.5},
     "channels": ["depth", "instance", "boxes"]},
    {"name": "left", "type": "pinhole", "rate_hz": 10,
     "pose": {"y": 0.6, "z": 0.2, "yaw_deg": 80, "pitch_deg": -10, "roll_deg": -5},
     "intrinsics": {"width": 160, "height": 120, "fx": 80, "fy": 85, "cx": 75, "cy": 62},
     "channels": ["depth", "instance", "boxes"]},
    {"name": "right", "type": "pinhole", "rate_hz": 10,
     "pose": {"y": -0.6, "z": 0.2, "yaw_deg": -100, "pitch_deg": 10, "roll_deg": 5},
     "intrinsics": {"width": 160, "height": 120, "fx": 90, "fy": 90, "cx": 79.5, "cy": 59.5},
     "channels": ["depth", "instance", "boxes"]},
    {"name": "fish", "type": "fisheye", "rate_hz": 10, "pose": {"yaw_deg": 90},
     "intrinsics": {"width": 48, "height": 40, "fx": 14, "fy": 14, "cx": 23.5, "cy": 19.5, "max_fov_deg": 190},
     "channels": ["depth"]},
    {"name": "lidar", "type": "lidar", "pose": {"z": 0.5, "yaw_deg": 3},
     "beams": {"count": 32, "min_deg": -25, "max_deg": 5}, "columns": 1024, "max_range_m": 80},
]}

# The SemanticKITTI classes a camera pixel's instance kind allows (kind = id >> 28:
# 0 ground, 1 building, 2 tree, 3 road, 4 junction, 5 sidewalk, 6 park,
# 7 street light, 8 traffic light, 9 traffic sign, 10 car).
ALLOWED = {0: {"terrain"}, 1: {"building"}, 2: {"vegetation", "trunk"}, 3: {"road", "lane-marking"},
           4: {"road", "lane-marking"}, 5: {"sidewalk"}, 6: {"terrain", "vegetation"}, 7: {"pole"},
           8: {"pole"}, 9: {"traffic-sign", "pole"}, 10: {"car"}}
OBJECT_KINDS = {1, 2, 7, 8, 9, 10}
KITTI_ORDER = ["P0", "P1", "P2", "P3", "R0_rect", "Tr_velo_to_cam", "Tr_imu_to_velo"]


class Failures:
    def __init__(self):
        self.items = []

    def check(self, ok, message):
        if not ok:
            self.items.append(message)
        return ok


def read_calib(path):
    """pykitti's way: every "key: numbers" line; and mmdetection3d's: the first seven by index."""
    calib, order = {}, []
    with open(path) as f:
        lines = f.readlines()
    for line in lines:
        if ":" not in line:
            continue
        key, value = line.split(":", 1)
        calib[key] = np.array([float(x) for x in value.split()])
        order.append(key)
    mm = {"P2": np.array([float(x) for x in lines[2].split(" ")[1:13]]).reshape(3, 4),
          "R0_rect": np.array([float(x) for x in lines[4].split(" ")[1:10]]).reshape(3, 3),
          "Tr_velo_to_cam": np.array([float(x) for x in lines[5].split(" ")[1:13]]).reshape(3, 4)}
    return calib, order, mm


def homogeneous(m34):
    return np.vstack([m34.reshape(3, 4), [0, 0, 0, 1]])


def rect4(r0):
    m = np.eye(4)
    m[:3, :3] = r0.reshape(3, 3)
    return m


def read_labels(path):
    out = []
    with open(path) as f:
        for line in f:
            v = line.split()
            if not v:
                continue
            out.append({"type": v[0], "bbox": [float(x) for x in v[4:8]], "h": float(v[8]), "w": float(v[9]),
                        "l": float(v[10]), "loc": np.array([float(x) for x in v[11:14]]), "ry": float(v[14]),
                        "id": int(v[15]) if len(v) > 15 else None, "fields": len(v)})
    return out


def roty(ry):
    c, s = np.cos(ry), np.sin(ry)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def corners(label):
    l, h, w = label["l"], label["h"], label["w"]
    x = [l / 2, l / 2, -l / 2, -l / 2, l / 2, l / 2, -l / 2, -l / 2]
    y = [0, 0, 0, 0, -h, -h, -h, -h]
    z = [w / 2, -w / 2, -w / 2, w / 2, w / 2, -w / 2, -w / 2, w / 2]
    return roty(label["ry"]) @ np.array([x, y, z]) + label["loc"][:, None]


def inside(label, pts_rect, margin):
    q = (pts_rect - label["loc"]) @ roty(label["ry"])  # rows: R^T (p - loc)
    return ((np.abs(q[:, 0]) <= label["l"] / 2 + margin) & (q[:, 1] <= margin) & (q[:, 1] >= -label["h"] - margin)
            & (np.abs(q[:, 2]) <= label["w"] / 2 + margin))


def read_yaml_labels(path):
    """The `labels:` block of a SemanticKITTI config (id: "name" lines)."""
    names, block = {}, None
    with open(path) as f:
        for line in f:
            if not line.startswith(" ") and line.strip():
                block = line.split(":")[0].strip()
                continue
            if block == "labels" and ":" in line:
                k, v = line.split(":", 1)
                names[int(k)] = v.strip().strip('"')
    return names


def check_calib(run, calib, order, mm, rig, fails):
    fails.check(order[:7] == KITTI_ORDER, f"calib.txt line order {order[:7]}, KITTI's is {KITTI_ORDER}")
    fails.check(np.allclose(mm["P2"], calib["P2"].reshape(3, 4)), "mmdetection3d's P2 differs from pykitti's")
    cams = [s for s in rig["rig"]["sensors"] if s["type"] != "lidar"]
    for k in range(len(cams)):
        fails.check(f"P{k}" in calib and calib[f"P{k}"].size == 12, f"calib.txt has no 3x4 P{k}")
    r0 = calib["R0_rect"].reshape(3, 3)
    fails.check(np.allclose(r0 @ r0.T, np.eye(3), atol=1e-9), "R0_rect is not a rotation")
    # The rectified frame is level: its y axis is the vehicle's down (-z).
    lidar = next(s for s in rig["sensors"] if s["name"] == "lidar")
    v2l = np.array(lidar["sensor_to_vehicle"])  # LiDAR -> vehicle
    rect_from_vehicle = rect4(calib["R0_rect"]) @ homogeneous(calib["Tr_velo_to_cam"]) @ np.linalg.inv(v2l)
    down = rect_from_vehicle[:3, :3] @ np.array([0, 0, -1.0])
    fails.check(np.allclose(down, [0, 1, 0], atol=1e-9), f"the rectified frame's y is {down}, not the vehicle's down")


class VehicleTrack:
    """The vehicle's pose at any time between rig frames: rig.json's vehicle_to_world, interpolated linearly."""

    def __init__(self, rig):
        self.t = np.array([f["t_s"] for f in rig["frames"]])
        self.m = np.array([f["vehicle_to_world"] for f in rig["frames"]], dtype=np.float64)

    def covers(self, t):
        return self.t[0] <= t <= self.t[-1] + 1e-9

    def at(self, t):
        """(len(t), 4, 4) poses."""
        i = np.clip(np.searchsorted(self.t, t, side="right") - 1, 0, len(self.t) - 2)
        a = ((t - self.t[i]) / (self.t[i + 1] - self.t[i]))[:, None, None]
        return (1 - a) * self.m[i] + a * self.m[i + 1]


def compensate(xyz, times, t0, track, lidar_to_vehicle):
    """Each point from the LiDAR frame at its firing time to the LiDAR frame at the sweep's start t0."""
    p = np.hstack([xyz, np.ones((len(xyz), 1))])
    world = np.einsum("nij,nj->ni", track.at(t0 + times), (lidar_to_vehicle @ p.T).T)
    back = np.linalg.inv(track.at(np.array([t0]))[0] @ lidar_to_vehicle)
    return (back @ world.T).T[:, :3]


def check_frame(run, name, calib, cams, sk_names, fails, stats, motion=None):
    pts = np.fromfile(os.path.join(run, "velodyne", name + ".bin"), dtype="<f4").reshape(-1, 4)
    n = len(pts)
    times = np.fromfile(os.path.join(run, "velodyne_time", name + ".bin"), dtype="<f4")
    fails.check(times.shape == (n,) and times.min() >= 0 and times.max() < 0.1 + 1e-6,
                f"{name}: velodyne_time has {times.shape} values in [{times.min()}, {times.max()}]")
    fails.check(np.all(np.diff(times) >= 0), f"{name}: point times are not in firing order")
    inst = np.fromfile(os.path.join(run, "lidar_instance", name + ".bin"), dtype="<u4")
    sk = np.fromfile(os.path.join(run, "labels", name + ".label"), dtype="<u4")
    fails.check(inst.shape == (n,) and sk.shape == (n,), f"{name}: per-point files disagree in length")
    sk_class, sk_inst = sk & 0xFFFF, sk >> 16
    unknown = set(np.unique(sk_class).tolist()) - set(sk_names)
    fails.check(not unknown, f"{name}: classes {unknown} are not in semantic-kitti.yaml")
    xyz = pts[:, :3].astype(np.float64)
    if motion:  # the sweep's start pose for every point (KITTI's velodyne is not motion-compensated)
        xyz = compensate(xyz, times.astype(np.float64), *motion)
    xyz1 = np.hstack([xyz, np.ones((n, 1))])
    rect = (rect4(calib["R0_rect"]) @ homogeneous(calib["Tr_velo_to_cam"]) @ xyz1.T).T[:, :3]
    for k in cams:
        P = calib[f"P{k}"].reshape(3, 4)
        label_file = os.path.join(run, f"label_{k:02d}", name + ".txt")
        if not os.path.exists(label_file):
            continue
        for lab in read_labels(label_file):
            fails.check(lab["fields"] == 16, f"{label_file}: {lab['fields']} fields, want 15 + the instance id")
            mine = rect[inst == lab["id"]]
            if len(mine) >= 10:
                frac = inside(lab, mine, 0.02).mean()
                stats["boxes_checked"] += 1
                stats["worst_fraction"] = min(stats["worst_fraction"], frac)
                fails.check(frac >= 0.95, f"{label_file}: instance {lab['id']} ({lab['type']}) box holds "
                            f"{100 * frac:.1f} % of its {len(mine)} LiDAR points")
            c = np.vstack([corners(lab), np.ones(8)])
            q = P @ c
            if np.all(q[2] > 0.1):
                u, v = q[0] / q[2], q[1] / q[2]
                b = lab["bbox"]
                ok = u.min() <= b[0] + 1 and v.min() <= b[1] + 1 and u.max() >= b[2] - 1 and v.max() >= b[3] - 1
                stats["projected_checked"] += 1
                fails.check(ok, f"{label_file}: instance {lab['id']} projected box "
                            f"[{u.min():.1f} {v.min():.1f} {u.max():.1f} {v.max():.1f}] does not enclose bbox {b}")
        check_classes_in_camera(run, name, k, P, rect, sk_class, sk_inst, sk_names, fails, stats, inst)


def check_road_junction(ids, u, v, pix_kinds, point_kinds, stats):
    """Road (kind 3) and junction (kind 4) points whose pixel and its 8 neighbours all name the other surface."""
    both = np.isin(pix_kinds, [3, 4]) & np.isin(point_kinds, [3, 4])
    stats["road_junction_points"] += int(both.sum())
    h, w = ids.shape
    for i in np.nonzero(both & (pix_kinds != point_kinds))[0]:
        nb = ids[max(v[i] - 1, 0):v[i] + 2, max(u[i] - 1, 0):u[i] + 2].astype(np.int64) >> 28
        stats["road_junction_flips"] += int(not (nb == point_kinds[i]).any())


def check_classes_in_camera(run, name, k, P, rect, sk_class, sk_inst, sk_names, fails, stats, inst):
    ids = np.load(os.path.join(run, f"instance_{k:02d}", name + ".npy"))
    depth = np.load(os.path.join(run, f"depth_{k:02d}", name + ".npy"))
    h, w = ids.shape
    q = (P @ np.hstack([rect, np.ones((len(rect), 1))]).T)
    z = q[2]
    front = z > 0.5
    u = np.full(len(z), -1)
    v = np.full(len(z), -1)
    u[front] = np.rint(q[0, front] / z[front]).astype(int)
    v[front] = np.rint(q[1, front] / z[front]).astype(int)
    inimg = front & (u >= 0) & (u < w) & (v >= 0) & (v < h)
    sel = np.nonzero(inimg)[0]
    d = depth[v[sel], u[sel]]
    seen = sel[np.isfinite(d) & (np.abs(d - z[sel]) <= 0.02 * z[sel])]
    if len(seen) == 0:
        return
    pix = ids[v[seen], u[seen]].astype(np.int64)
    kinds = pix >> 28
    check_road_junction(ids, u[seen], v[seen], kinds, inst[seen].astype(np.int64) >> 28, stats)
    names = [sk_names.get(int(c), "?") for c in sk_class[seen]]
    agree = np.array([nm in ALLOWED.get(int(kd), set()) for nm, kd in zip(names, kinds)])
    stats["points_compared"] += len(seen)
    fails.check(agree.mean() >= 0.95, f"{name} camera {k}: SemanticKITTI classes agree with the instance image "
                f"for {100 * agree.mean():.1f} % of {len(seen)} visible points")
    # Upper 16 bits: one id per object instance, distinct between instances; 0 on surfaces.
    obj = np.isin(kinds, list(OBJECT_KINDS)) & agree
    surf = ~np.isin(kinds, list(OBJECT_KINDS)) & agree
    if surf.any():
        fails.check((sk_inst[seen][surf] == 0).mean() >= 0.95, f"{name} camera {k}: surfaces carry instance ids")
    by_pix = {}
    for pid, sid in zip(pix[obj].tolist(), sk_inst[seen][obj].tolist()):
        by_pix.setdefault(pid, []).append(sid)
    firsts = {}
    for pid, sids in by_pix.items():
        common = max(set(sids), key=sids.count)
        fails.check(common != 0 and sids.count(common) >= 0.9 * len(sids),
                    f"{name} camera {k}: instance {pid}'s points carry SemanticKITTI instances {set(sids)}")
        fails.check(common not in firsts, f"{name} camera {k}: instances {pid} and {firsts.get(common)} "
                    f"share SemanticKITTI instance {common}")
        firsts[common] = pid
        stats["instances_compared"] += 1


def check_run(run):
    fails = Failures()
    stats = {"boxes_checked": 0, "projected_checked": 0, "worst_fraction": 1.0, "points_compared": 0,
             "instances_compared": 0, "frames": 0, "road_junction_points": 0, "road_junction_flips": 0}
    rig = json.load(open(os.path.join(run, "rig.json")))
    calib, order, mm = read_calib(os.path.join(run, "calib.txt"))
    check_calib(run, calib, order, mm, rig, fails)
    sk_names = read_yaml_labels(os.path.join(run, "semantic-kitti.yaml"))
    fails.check(sk_names.get(10) == "car" and sk_names.get(40) == "road", "semantic-kitti.yaml lacks car/road")
    cams = [s["index"] for s in rig["sensors"] if "channels" in s and "boxes" in s["channels"]
            and s["dirs"]["kitti_labels"]]
    track = VehicleTrack(rig)
    lidar = next(s for s in rig["sensors"] if s["dirs"].get("points") == "velodyne")
    for f in rig["frames"]:
        if not os.path.exists(os.path.join(run, "velodyne", f["name"] + ".bin")) or not track.covers(f["t_s"] + 0.1):
            continue
        stats["frames"] += 1
        motion = (f["t_s"], track, np.array(lidar["sensor_to_vehicle"]))
        check_frame(run, f["name"], calib, cams, sk_names, fails, stats, motion)
    fails.check(stats["boxes_checked"] >= 8, f"only {stats['boxes_checked']} label boxes had 10 LiDAR points")
    fails.check(stats["points_compared"] >= 1000, f"only {stats['points_compared']} LiDAR points seen by a camera")
    # Coplanar road and junction surfaces: the camera and the LiDAR pick the same one (a point on
    # the boundary may see the other within a pixel; a flip is one with no agreeing neighbour).
    flips, rj = stats["road_junction_flips"], stats["road_junction_points"]
    fails.check(rj >= 1000 and flips <= 0.001 * rj, f"{flips} of {rj} road and junction points flip between "
                "the LiDAR and the cameras (at most 0.1 %)")
    print("kitti_check:", json.dumps(stats))
    for m in fails.items[:40]:
        print("FAIL:", m)
    return 1 if fails.items else 0


def render(vista, d, gen_args=("--size", 400, "--seed", 11), seed=2):
    def run(*args):
        r = subprocess.run([vista, *map(str, args)], capture_output=True, text=True)
        if r.returncode != 0:
            raise SystemExit(f"vista {' '.join(map(str, args))} failed ({r.returncode}): {r.stderr}")
    city, path, rig, out = (os.path.join(d, n) for n in ("city.osgb", "path.csv", "rig.json", "out"))
    with open(rig, "w") as f:
        json.dump(RIG, f)
    run("gen", *gen_args, "-q", "-o", city)
    run("path", city, "--seed", seed, "--duration", 6, "-o", path)
    # Consecutive path samples (1/30 s): rig.json's poses cover every sweep (10 Hz, every third frame).
    run("render", city, "--path", path, "--frames", 10, "--sampling", "consecutive", "--rig", rig, "--out", out, "-q")
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--vista", help="render a test rig with this vista binary, then check it")
    ap.add_argument("--run", help="check an existing rig run")
    a = ap.parse_args()
    if a.run:
        return check_run(a.run)
    if not a.vista:
        ap.error("give --vista or --run")
    # A flat generated city, and a hilly one (the path climbs and descends 25 m hills).
    hilly = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "xodr_hilly.json")
    rc = 0
    for gen_args in (("--size", 400, "--seed", 11), ("--params", hilly, "--size", 400)):
        with tempfile.TemporaryDirectory() as d:
            rc |= check_run(render(a.vista, d, gen_args))
    return rc


if __name__ == "__main__":
    sys.exit(main())
