#!/usr/bin/env python3
"""Draws one frame's ground truth onto its image: the 2D boxes of a boxes
JSON file (docs/formats.md, "Boxes") and, optionally, LiDAR points projected
with a KITTI calibration file.

Python 3 standard library only (PNG read and written with zlib), so it runs
wherever python3 does.

  show_frame.py --image rgb/000000.png --boxes boxes/000000.json -o shown.png
  show_frame.py --image rgb.png --boxes boxes.json --lidar lidar.bin --calib calib.txt -o shown.png
  show_frame.py --run rig_run --frame 000003 --camera 0 -o shown.png

--run reads one frame of a `vista render --rig` run for camera NN:
image_NN/FRAME.png, boxes_NN/FRAME.json and, when the first LiDAR fired at
that frame, velodyne/FRAME.bin projected with calib.txt's PNN and
Tr_velo_to_cam (a pinhole camera; a fisheye's PNN is only its pinhole equivalent, so its boxes
are drawn without points).

Boxes: the visible extent (solid, the colour of the instance kind) and the
full projected extent (dashed, same colour); --min-pixels hides boxes with
fewer visible pixels, --no-full hides the dashed extents.
LiDAR (--lidar, --calib): float32 little-endian records x, y, z, intensity
(KITTI's velodyne .bin: x forward, y left, z up, metres), projected as
P * R0_rect * Tr_velo_to_cam * (x, y, z, 1) (P = P2, or PNN with --run;
R0_rect = identity when the file has none) and drawn as 2x2 dots coloured by
range (near red, far blue); points less than 0.5 m in front of the camera
(the third coordinate of that product) are dropped.
--self-test draws a synthetic frame and checks the pixels it sets.
"""
import argparse
import json
import math
import os
import struct
import sys
import tempfile
import zlib

KIND_COLORS = {
    "building": (255, 140, 0),
    "tree": (40, 220, 40),
    "street_light": (255, 255, 0),
    "traffic_light": (255, 0, 255),
    "traffic_sign": (0, 230, 255),
    "car": (255, 30, 30),
}
DEFAULT_COLOR = (255, 255, 255)


class Picture:
    """An 8-bit RGB raster, row 0 at the top."""

    def __init__(self, width, height, pixels=None):
        self.width, self.height = width, height
        self.pixels = pixels if pixels is not None else bytearray(width * height * 3)

    def set(self, x, y, rgb):
        if 0 <= x < self.width and 0 <= y < self.height:
            i = (y * self.width + x) * 3
            self.pixels[i:i + 3] = bytes(rgb)

    def get(self, x, y):
        i = (y * self.width + x) * 3
        return tuple(self.pixels[i:i + 3])


def _paeth(a, b, c):
    p = a + b - c
    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
    if pa <= pb and pa <= pc:
        return a
    return b if pb <= pc else c


def read_png(path):
    """Decodes an 8-bit non-interlaced grey, grey+alpha, RGB or RGBA PNG."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(f"{path}: not a PNG file")
    pos, idat, header = 8, [], None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            break
    if header is None:
        raise ValueError(f"{path}: no IHDR chunk")
    width, height, depth, color, _, _, interlace = header
    channels = {0: 1, 2: 3, 4: 2, 6: 4}.get(color)
    if depth != 8 or channels is None or interlace != 0:
        raise ValueError(f"{path}: only 8-bit non-interlaced grey/RGB(A) PNGs are read "
                         f"(bit depth {depth}, colour type {color}, interlace {interlace})")
    raw = zlib.decompress(b"".join(idat))
    stride = width * channels
    out = bytearray(width * height * 3)
    prev = bytearray(stride)
    for y in range(height):
        ftype = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = prev[i]
            c = prev[i - channels] if i >= channels else 0
            if ftype == 1:
                line[i] = (line[i] + a) & 255
            elif ftype == 2:
                line[i] = (line[i] + b) & 255
            elif ftype == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif ftype == 4:
                line[i] = (line[i] + _paeth(a, b, c)) & 255
        for x in range(width):
            px = line[x * channels:(x + 1) * channels]
            rgb = (px[0], px[0], px[0]) if channels <= 2 else (px[0], px[1], px[2])
            out[(y * width + x) * 3:(y * width + x) * 3 + 3] = bytes(rgb)
        prev = line
    return Picture(width, height, out)


def write_png(picture, path):
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF)

    stride = picture.width * 3
    raw = b"".join(b"\x00" + bytes(picture.pixels[y * stride:(y + 1) * stride]) for y in range(picture.height))
    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", picture.width, picture.height, 8, 2, 0, 0, 0))
           + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(png)
    os.replace(tmp, path)


def draw_rect(pic, u0, v0, u1, v1, rgb, dashed=False):
    """Outline of the pixels [u0, u1] x [v0, v1] (inclusive, clipped to the picture)."""
    u0, v0 = max(0, int(math.floor(u0))), max(0, int(math.floor(v0)))
    u1, v1 = min(pic.width - 1, int(math.ceil(u1))), min(pic.height - 1, int(math.ceil(v1)))
    if u0 > u1 or v0 > v1:
        return
    for x in range(u0, u1 + 1):
        if not dashed or (x // 4) % 2 == 0:
            pic.set(x, v0, rgb)
            pic.set(x, v1, rgb)
    for y in range(v0, v1 + 1):
        if not dashed or (y // 4) % 2 == 0:
            pic.set(u0, y, rgb)
            pic.set(u1, y, rgb)


def draw_boxes(pic, doc, min_pixels=1, full=True):
    drawn = 0
    for box in doc.get("boxes", []):
        if box.get("pixels", 0) < min_pixels:
            continue
        rgb = KIND_COLORS.get(box.get("kind"), DEFAULT_COLOR)
        if full and box.get("full"):
            u0, v0, u1, v1 = box["full"]
            # The full extent's edges in pixel-centre coordinates: the pixels it spans.
            draw_rect(pic, u0 + 0.5, v0 + 0.5, u1 - 0.5, v1 - 0.5, rgb, dashed=True)
        u0, v0, u1, v1 = box["visible"]
        draw_rect(pic, u0, v0, u1, v1, rgb)
        drawn += 1
    return drawn


def read_calib(path, p_name="P2"):
    """KITTI calibration: name -> list of floats ("P2: v v ..."); "P" = the rows of p_name."""
    rows = {}
    with open(path) as f:
        for line in f:
            if ":" in line:
                name, values = line.split(":", 1)
                rows[name.strip()] = [float(v) for v in values.split()]
    for need, count in ((p_name, 12), ("Tr_velo_to_cam", 12)):
        if len(rows.get(need, [])) != count:
            raise ValueError(f"{path}: {need} needs {count} numbers")
    rows["P"] = rows[p_name]
    return rows


def _mat34(v):
    return [v[0:4], v[4:8], v[8:12]]


def project_lidar(points, calib):
    """(u, v, range) of each point in front of the camera: P * R0_rect * Tr_velo_to_cam."""
    P, T = _mat34(calib.get("P", calib.get("P2"))), _mat34(calib["Tr_velo_to_cam"])
    R = calib.get("R0_rect", [1, 0, 0, 0, 1, 0, 0, 0, 1])
    R = [R[0:3], R[3:6], R[6:9]]
    out = []
    for x, y, z, _ in points:
        c = [T[i][0] * x + T[i][1] * y + T[i][2] * z + T[i][3] for i in range(3)]
        c = [R[i][0] * c[0] + R[i][1] * c[1] + R[i][2] * c[2] for i in range(3)]
        h = [P[i][0] * c[0] + P[i][1] * c[1] + P[i][2] * c[2] + P[i][3] for i in range(3)]
        if h[2] < 0.5:
            continue
        out.append((h[0] / h[2], h[1] / h[2], math.sqrt(x * x + y * y + z * z)))
    return out


def read_lidar(path):
    with open(path, "rb") as f:
        data = f.read()
    if len(data) % 16:
        raise ValueError(f"{path}: {len(data)} bytes is not a whole number of 16-byte x, y, z, intensity records")
    return list(struct.iter_unpack("<4f", data))


def range_color(r, far=60.0):
    t = max(0.0, min(1.0, r / far))
    return (int(255 * (1 - t)), int(255 * (1 - abs(2 * t - 1))), int(255 * t))


def draw_points(pic, projected):
    drawn = 0
    for u, v, r in projected:
        x, y = int(round(u)), int(round(v))
        if -1 <= x < pic.width and -1 <= y < pic.height:
            for dx in (0, 1):
                for dy in (0, 1):
                    pic.set(x + dx, y + dy, range_color(r))
            drawn += 1
    return drawn


def show(image, boxes, out, lidar=None, calib=None, min_pixels=1, full=True, p_name="P2"):
    pic = read_png(image)
    with open(boxes) as f:
        doc = json.load(f)
    if doc.get("format") != "vista.boxes":
        raise ValueError(f"{boxes}: not a vista.boxes file")
    if (doc.get("width"), doc.get("height")) != (pic.width, pic.height):
        raise ValueError(f"{boxes}: boxes for {doc.get('width')}x{doc.get('height')}, image is {pic.width}x{pic.height}")
    points = 0
    if lidar:
        if not calib:
            raise ValueError("--lidar needs --calib")
        points = draw_points(pic, project_lidar(read_lidar(lidar), read_calib(calib, p_name)))
    n = draw_boxes(pic, doc, min_pixels, full)
    write_png(pic, out)
    return n, points


def rig_frame_files(run, frame, camera):
    """The files of one rig frame for camera `camera` (an index): image, boxes,
    LiDAR (None when the first LiDAR did not fire or the camera is a fisheye),
    calib and the P line's name."""
    nn = f"{int(camera):02d}"
    frame = f"{int(frame):06d}"
    image = os.path.join(run, f"image_{nn}", frame + ".png")
    boxes = os.path.join(run, f"boxes_{nn}", frame + ".json")
    for path, channel in ((image, "rgb"), (boxes, "boxes")):
        if not os.path.exists(path):
            raise ValueError(f"{path} does not exist: camera {nn} has no {channel} at frame {frame} "
                             "(not in its channels, or it did not fire at that frame)")
    lidar = os.path.join(run, "velodyne", frame + ".bin")
    calib = os.path.join(run, "calib.txt")
    p_name = "P" + str(int(camera))
    has_p = False
    if os.path.exists(calib):
        with open(calib) as f:
            has_p = any(line.split(":", 1)[0].strip() == p_name for line in f if ":" in line)
    with open(boxes) as f:
        pinhole = json.load(f).get("model", "pinhole") == "pinhole"
    if not (has_p and pinhole and os.path.exists(lidar)):
        lidar = None  # a fisheye's P line is its pinhole equivalent, exact on the axis only
    return image, boxes, lidar, calib, p_name


def self_test():
    with tempfile.TemporaryDirectory() as d:
        grey = Picture(64, 48, bytearray([90] * 64 * 48 * 3))
        write_png(grey, os.path.join(d, "rgb.png"))
        doc = {"format": "vista.boxes", "version": 1, "width": 64, "height": 48,
               "boxes": [{"id": 1, "kind": "car", "visible": [10, 12, 20, 30], "pixels": 50,
                          "full": [5.5, 11.5, 20.5, 30.5]}]}
        with open(os.path.join(d, "boxes.json"), "w") as f:
            json.dump(doc, f)
        # A LiDAR at the camera: x forward = camera z, y left = -camera x, z up = -camera y.
        f_px, cx, cy = 40.0, 31.5, 23.5
        calib = (f"P2: {f_px} 0 {cx} 0 0 {f_px} {cy} 0 0 0 1 0\nR0_rect: 1 0 0 0 1 0 0 0 1\n"
                 "Tr_velo_to_cam: 0 -1 0 0 0 0 -1 0 1 0 0 0\n")
        with open(os.path.join(d, "calib.txt"), "w") as f:
            f.write(calib)
        # A point 10 m ahead and 2.5 m to the left projects to u = cx - 40 * 0.25 = 21.5, v = cy.
        with open(os.path.join(d, "lidar.bin"), "wb") as f:
            f.write(struct.pack("<8f", 10.0, 2.5, 0.0, 0.5, -5.0, 0.0, 0.0, 0.5))  # the second is behind
        n, pts = show(os.path.join(d, "rgb.png"), os.path.join(d, "boxes.json"), os.path.join(d, "out.png"),
                      os.path.join(d, "lidar.bin"), os.path.join(d, "calib.txt"))
        pic = read_png(os.path.join(d, "out.png"))
        car = KIND_COLORS["car"]
        checks = [
            (n == 1 and pts == 1, f"1 box and 1 point drawn, got {n} and {pts}"),
            (pic.get(15, 12) == car and pic.get(10, 20) == car and pic.get(20, 30) == car, "visible box outline"),
            (pic.get(15, 13) == (90, 90, 90) and pic.get(9, 20) != car, "inside and left of the box untouched"),
            (pic.get(6, 16) == car and pic.get(6, 12) != car, "full extent dashed, from column 6"),
            (pic.get(22, 24) == range_color(math.sqrt(10.0 ** 2 + 2.5 ** 2)), "LiDAR point at (22, 24)"),
            (pic.get(40, 40) == (90, 90, 90), "background untouched"),
        ]
        # A rig run: camera 01 is the reference camera turned 90 degrees to the left (its z = the LiDAR's y).
        run = os.path.join(d, "run")
        for sub in ("image_01", "boxes_01", "velodyne"):
            os.makedirs(os.path.join(run, sub))
        write_png(grey, os.path.join(run, "image_01", "000002.png"))
        with open(os.path.join(run, "boxes_01", "000002.json"), "w") as f:
            json.dump(doc, f)
        # P1 = K [R | 0], R mapping the reference camera (x right, y down, z forward) to one looking left:
        # its x = the reference's z, its y = the reference's y, its z = -(the reference's x).
        p1 = [-cx, 0, f_px, 0, -cy, f_px, 0, 0, -1, 0, 0, 0]
        with open(os.path.join(run, "calib.txt"), "w") as f:
            f.write(f"P0: {f_px} 0 {cx} 0 0 {f_px} {cy} 0 0 0 1 0\n")
            f.write("P1: " + " ".join(str(v) for v in p1) + "\n")
            f.write("Tr_velo_to_cam: 0 -1 0 0 0 0 -1 0 1 0 0 0\n")
        # 10 m to the left and 2.5 m ahead: u = cx + 40 * 2.5 / 10 = 41.5 in camera 01; 10 m ahead is beside it.
        with open(os.path.join(run, "velodyne", "000002.bin"), "wb") as f:
            f.write(struct.pack("<8f", 2.5, 10.0, 0.0, 0.5, 10.0, 0.0, 0.0, 0.5))
        files = rig_frame_files(run, "2", "1")
        n2, pts2 = show(*files[:2], os.path.join(d, "rig.png"), files[2], files[3], p_name=files[4])
        rig = read_png(os.path.join(d, "rig.png"))
        checks += [
            (files[4] == "P1" and files[2] is not None, f"rig files of camera 01: {files}"),
            (n2 == 1 and pts2 == 1, f"rig frame: 1 box and 1 point drawn, got {n2} and {pts2}"),
            (rig.get(42, 24) == range_color(math.sqrt(10.0 ** 2 + 2.5 ** 2)), "rig LiDAR point at (42, 24)"),
        ]
        failed = [m for ok, m in checks if not ok]
        for m in failed:
            print("FAILED:", m)
        if not failed:
            print("show_frame self-test: ok")
        return 1 if failed else 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--image", help="the frame's image (8-bit PNG)")
    ap.add_argument("--boxes", help="the frame's boxes JSON (format vista.boxes)")
    ap.add_argument("--lidar", help="LiDAR points: float32 x, y, z, intensity records")
    ap.add_argument("--calib", help="KITTI calibration file (P2, R0_rect, Tr_velo_to_cam)")
    ap.add_argument("--run", help="a `vista render --rig` output directory (with --frame and --camera)")
    ap.add_argument("--frame", default="0", help="--run: the rig frame (number, e.g. 3 or 000003)")
    ap.add_argument("--camera", default="0", help="--run: the camera's index NN (image_NN/)")
    ap.add_argument("-o", "--out", help="the picture to write (PNG)")
    ap.add_argument("--min-pixels", type=int, default=1, help="hide boxes with fewer visible pixels")
    ap.add_argument("--no-full", action="store_true", help="draw the visible extents only")
    ap.add_argument("--self-test", action="store_true", help="draw a synthetic frame and check it")
    a = ap.parse_args()
    if a.self_test:
        return self_test()
    if not a.out or not (a.run or (a.image and a.boxes)):
        ap.error("-o and either --run or --image and --boxes are required")
    try:
        p_name = "P2"
        if a.run:
            if not (a.frame.isdigit() and a.camera.isdigit()):
                raise ValueError(f"--frame {a.frame!r} and --camera {a.camera!r} must be whole numbers")
            a.image, a.boxes, a.lidar, a.calib, p_name = rig_frame_files(a.run, a.frame, a.camera)
        n, pts = show(a.image, a.boxes, a.out, a.lidar, a.calib, a.min_pixels, not a.no_full, p_name)
    except (OSError, ValueError, KeyError) as e:
        print(f"show_frame: {e}", file=sys.stderr)
        return 2
    print(f"{a.out}: {n} boxes" + (f", {pts} LiDAR points" if a.lidar else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
