#!/usr/bin/env python3
"""Checks an OpenDRIVE file against the one-way tags of the OpenStreetMap
extract it was made from.

Reads the extract (.osm XML, .osm.gz, .osm.bz2 or .osm.pbf) with a reader of
its own (Python standard library: ElementTree, zlib and a small protobuf
decoder for the PBF blocks), projects its nodes into the .xodr's frame with
the header's <geoReference> (+proj=tmerc on WGS84, the ellipsoidal series of
Snyder, "Map Projections: A Working Manual", eqs. 8-9 to 8-11), and evaluates
the .xodr's roads with the independent evaluator of xodr_check.py.

A road outside junctions lies on an OSM way when, at more than half of the
samples of its reference line (--samples points evenly inside its length),
the nearest way segment running parallel to it (within --max-angle-deg,
either direction) is within --max-dist metres, belongs to that way and runs
the same way along the road (a road may reach a little onto the way before
or after, or beside it). A way is one-way as OSM
says: oneway=yes/true/1 along the way, -1/reverse against it, no/false/0
two-way; without a valid value highway=motorway and junction=roundabout or
circular are one-way along the way. Ways whose highway value vista does not
import as roads (footway, path, cycleway, steps, ...) are not read.

Checks, per one-way way with at least one road on it:
  two_way        a road on it has driving lanes in both directions;
  against        a road on it has driving lanes only against the way's
                 travel direction.
(Right-hand traffic: right lanes drive toward +s, left lanes toward -s;
rule="LHT" swaps them. A lane counts when it is wider than --taper-width
somewhere.)

Exit status: 0 no failures, 1 a check fails, 2 an input cannot be read (the
message names the file and what is wrong).

Usage: osm_oneway_check.py MAP.osm[.pbf] FILE.xodr [--json OUT.json] [-q]
"""
import argparse
import bz2
import gzip
import json
import math
import os
import struct
import sys
import xml.etree.ElementTree as ET
import zlib

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import xodr_check  # noqa: E402  (the independent OpenDRIVE evaluator)

# highway=* values that are not roads for vehicles (not imported as streets).
NOT_ROADS = {"footway", "path", "cycleway", "steps", "bridleway", "pedestrian", "corridor", "proposed",
             "construction", "platform", "elevator", "abandoned", "raceway"}


class InputError(Exception):
    """An input cannot be read; the message names it."""


# ---------------------------------------------------------------------------
# OSM reading

def oneway_of(tags):
    """+1 one-way along the way, -1 against it, 0 two-way."""
    v = tags.get("oneway")
    if v in ("yes", "true", "1"):
        return 1
    if v in ("-1", "reverse"):
        return -1
    if v in ("no", "false", "0"):
        return 0
    if tags.get("highway") == "motorway" or tags.get("junction") in ("roundabout", "circular"):
        return 1
    return 0


def read_osm_xml(path):
    opener = gzip.open if path.endswith(".gz") else bz2.open if path.endswith(".bz2") else open
    nodes, ways = {}, []
    try:
        with opener(path, "rb") as f:
            for _, el in ET.iterparse(f, events=("end",)):
                if el.tag == "node":
                    try:
                        nodes[int(el.get("id"))] = (float(el.get("lat")), float(el.get("lon")))
                    except (TypeError, ValueError):
                        pass  # invalid coordinates: the importer drops such nodes too
                    el.clear()
                elif el.tag == "way":
                    tags = {t.get("k"): t.get("v") for t in el.findall("tag")}
                    refs = [int(n.get("ref")) for n in el.findall("nd")]
                    ways.append((int(el.get("id")), refs, tags))
                    el.clear()
    except ET.ParseError as e:
        raise InputError(f"{path} is not well-formed XML: {e}")
    except (OSError, EOFError, ValueError) as e:
        raise InputError(f"cannot read {path}: {e}")
    return nodes, ways


def _varint(buf, i):
    r = shift = 0
    while True:
        b = buf[i]
        i += 1
        r |= (b & 0x7F) << shift
        if b < 0x80:
            return r, i
        shift += 7


def _fields(buf):
    """(field number, wire type, value) of a protobuf message; value: int or bytes."""
    i, n = 0, len(buf)
    while i < n:
        key, i = _varint(buf, i)
        f, w = key >> 3, key & 7
        if w == 0:
            v, i = _varint(buf, i)
        elif w == 2:
            ln, i = _varint(buf, i)
            v = buf[i:i + ln]
            i += ln
        elif w == 1:
            v = buf[i:i + 8]
            i += 8
        elif w == 5:
            v = buf[i:i + 4]
            i += 4
        else:
            raise ValueError(f"protobuf wire type {w}")
        if i > n:
            raise ValueError("truncated protobuf message")
        yield f, w, v


def _packed(buf):
    out, i, n = [], 0, len(buf)
    while i < n:
        v, i = _varint(buf, i)
        out.append(v)
    return out


def _zigzag(v):
    return (v >> 1) ^ -(v & 1)


def _signed64(v):
    return v - (1 << 64) if v >= 1 << 63 else v


def read_osm_pbf(path):
    nodes, ways = {}, []
    try:
        data = open(path, "rb").read()
    except OSError as e:
        raise InputError(f"cannot read {path}: {e.strerror}")
    i = 0
    try:
        while i < len(data):
            if i + 4 > len(data):
                raise ValueError("truncated block header length")
            (hlen,) = struct.unpack(">I", data[i:i + 4])
            i += 4
            header = data[i:i + hlen]
            i += hlen
            btype, size = "", 0
            for f, _, v in _fields(header):
                if f == 1:
                    btype = v.decode()
                elif f == 3:
                    size = v
            blob = data[i:i + size]
            if len(blob) != size:
                raise ValueError("truncated blob")
            i += size
            raw = None
            for f, _, v in _fields(blob):
                if f == 1:
                    raw = bytes(v)
                elif f == 3:
                    raw = zlib.decompress(v)
                elif f in (4, 5, 6, 7):
                    raise ValueError(f"blob compression field {f} is not supported (only raw and zlib)")
            if btype != "OSMData" or raw is None:
                continue
            strings, groups, gran, lat_off, lon_off = [], [], 100, 0, 0
            for f, _, v in _fields(raw):
                if f == 1:
                    strings = [bytes(s).decode("utf-8", "replace") for ff, _, s in _fields(v) if ff == 1]
                elif f == 2:
                    groups.append(v)
                elif f == 17:
                    gran = v
                elif f == 19:
                    lat_off = _signed64(v)
                elif f == 20:
                    lon_off = _signed64(v)
            for g in groups:
                for f, _, v in _fields(g):
                    if f == 1:  # Node
                        nid = lat = lon = 0
                        for ff, _, vv in _fields(v):
                            if ff == 1:
                                nid = _zigzag(vv)
                            elif ff == 8:
                                lat = _zigzag(vv)
                            elif ff == 9:
                                lon = _zigzag(vv)
                        nodes[nid] = (1e-9 * (lat_off + gran * lat), 1e-9 * (lon_off + gran * lon))
                    elif f == 2:  # DenseNodes
                        ids = lats = lons = []
                        for ff, _, vv in _fields(v):
                            if ff == 1:
                                ids = _packed(vv)
                            elif ff == 8:
                                lats = _packed(vv)
                            elif ff == 9:
                                lons = _packed(vv)
                        nid = lat = lon = 0
                        for a, b, c in zip(ids, lats, lons):
                            nid += _zigzag(a)
                            lat += _zigzag(b)
                            lon += _zigzag(c)
                            nodes[nid] = (1e-9 * (lat_off + gran * lat), 1e-9 * (lon_off + gran * lon))
                    elif f == 3:  # Way
                        wid, keys, vals, refs = 0, [], [], []
                        for ff, _, vv in _fields(v):
                            if ff == 1:
                                wid = _signed64(vv)
                            elif ff == 2:
                                keys = _packed(vv)
                            elif ff == 3:
                                vals = _packed(vv)
                            elif ff == 8:
                                ref = 0
                                for d in _packed(vv):
                                    ref += _zigzag(d)
                                    refs.append(ref)
                        tags = {strings[k]: strings[x] for k, x in zip(keys, vals)}
                        ways.append((wid, refs, tags))
    except (ValueError, IndexError, zlib.error, UnicodeDecodeError) as e:
        raise InputError(f"{path} is not a readable .osm.pbf: {e}")
    return nodes, ways


def read_osm(path):
    if path.endswith(".pbf"):
        return read_osm_pbf(path)
    return read_osm_xml(path)


# ---------------------------------------------------------------------------
# projection (transverse Mercator on WGS84, Snyder eqs. 8-9 to 8-11)

WGS84_A = 6378137.0
WGS84_F = 1.0 / 298.257223563


def parse_proj(text):
    params = {}
    for part in (text or "").split():
        if part.startswith("+") and "=" in part:
            k, v = part[1:].split("=", 1)
            params[k] = v
    if params.get("proj") != "tmerc":
        raise InputError(f"the .xodr's geoReference is not +proj=tmerc: '{(text or '').strip()[:200]}'")
    if params.get("ellps", "WGS84") != "WGS84":
        raise InputError(f"the .xodr's geoReference ellipsoid is {params['ellps']}, not WGS84")
    try:
        return {k: float(params.get(k, d)) for k, d in
                (("lat_0", 0), ("lon_0", 0), ("k_0", params.get("k", 1)), ("x_0", 0), ("y_0", 0))}
    except ValueError as e:
        raise InputError(f"the .xodr's geoReference has a value that is not a number: {e}")


class TransverseMercator:
    def __init__(self, p, a=WGS84_A, e2=WGS84_F * (2 - WGS84_F)):
        self.p, self.a = p, a
        self.e2, self.ep2 = e2, e2 / (1 - e2)
        self.m0 = self.meridian(math.radians(p["lat_0"]))

    def meridian(self, phi):
        e2 = self.e2
        e4, e6 = e2 * e2, e2 * e2 * e2
        return self.a * ((1 - e2 / 4 - 3 * e4 / 64 - 5 * e6 / 256) * phi
                          - (3 * e2 / 8 + 3 * e4 / 32 + 45 * e6 / 1024) * math.sin(2 * phi)
                          + (15 * e4 / 256 + 45 * e6 / 1024) * math.sin(4 * phi)
                          - (35 * e6 / 3072) * math.sin(6 * phi))

    def forward(self, lat, lon):
        p, k0 = self.p, self.p["k_0"]
        phi = math.radians(lat)
        dlon = math.radians((lon - p["lon_0"] + 180.0) % 360.0 - 180.0)
        s, c = math.sin(phi), math.cos(phi)
        t = math.tan(phi) ** 2
        cc = self.ep2 * c * c
        a = dlon * c
        n = self.a / math.sqrt(1 - self.e2 * s * s)
        x = k0 * n * (a + (1 - t + cc) * a ** 3 / 6 + (5 - 18 * t + t * t + 72 * cc - 58 * self.ep2) * a ** 5 / 120)
        y = k0 * (self.meridian(phi) - self.m0 + n * math.tan(phi) *
                  (a * a / 2 + (5 - t + 9 * cc + 4 * cc * cc) * a ** 4 / 24 +
                   (61 - 58 * t + t * t + 600 * cc - 330 * self.ep2) * a ** 6 / 720))
        return x + p["x_0"], y + p["y_0"]


# ---------------------------------------------------------------------------
# matching roads to ways

class SegmentGrid:
    """Way segments in the .xodr frame, bucketed in square cells."""

    def __init__(self, cell):
        self.cell = cell
        self.cells = {}
        self.segs = []  # (x0, y0, x1, y1, way index)

    def add(self, x0, y0, x1, y1, w):
        k = len(self.segs)
        self.segs.append((x0, y0, x1, y1, w))
        c = self.cell
        for i in range(int(math.floor(min(x0, x1) / c)), int(math.floor(max(x0, x1) / c)) + 1):
            for j in range(int(math.floor(min(y0, y1) / c)), int(math.floor(max(y0, y1) / c)) + 1):
                self.cells.setdefault((i, j), []).append(k)

    def near(self, x, y, r):
        c = self.cell
        seen = set()
        for i in range(int(math.floor((x - r) / c)), int(math.floor((x + r) / c)) + 1):
            for j in range(int(math.floor((y - r) / c)), int(math.floor((y + r) / c)) + 1):
                for k in self.cells.get((i, j), ()):
                    if k not in seen:
                        seen.add(k)
                        yield self.segs[k]


def point_segment(x, y, s):
    x0, y0, x1, y1, _ = s
    dx, dy = x1 - x0, y1 - y0
    ll = dx * dx + dy * dy
    u = 0.0 if ll == 0 else max(0.0, min(1.0, ((x - x0) * dx + (y - y0) * dy) / ll))
    return math.hypot(x - (x0 + u * dx), y - (y0 + u * dy))


def lane_directions(road, taper):
    """(drives toward +s, drives toward -s): driving lanes wider than taper somewhere."""
    plus = minus = False
    for sec in road.sections:
        for lid, lane in sec.lanes.items():
            if lid == 0 or lane.type not in xodr_check.DRIVING_TYPES:
                continue
            length = sec.end - sec.s
            if lane.widths:
                wide = any(road.lane_width(sec, lane, sec.s + f * length) > taper for f in (0.0, 0.25, 0.5, 0.75, 1.0))
            else:
                wide = True
            if not wide:
                continue
            forward = (lid < 0) == (road.rule == "RHT")
            plus, minus = plus or forward, minus or not forward
    return plus, minus


def run(osm_path, xodr_path, opt):
    net = xodr_check.load(xodr_path)
    root = ET.parse(xodr_path).getroot()
    xodr_check.strip_namespaces(root)
    geo = root.find("header/geoReference")
    tm = TransverseMercator(parse_proj(geo.text if geo is not None else ""))
    nodes, ways = read_osm(osm_path)
    grid = SegmentGrid(25.0)
    kept = []  # (way id, oneway)
    for wid, refs, tags in ways:
        hw = tags.get("highway")
        if hw is None or hw in NOT_ROADS or tags.get("area") == "yes":
            continue
        pts = [tm.forward(*nodes[r]) for r in refs if r in nodes]
        if len(pts) < 2:
            continue
        w = len(kept)
        kept.append((wid, oneway_of(tags)))
        for (x0, y0), (x1, y1) in zip(pts, pts[1:]):
            if (x0, y0) != (x1, y1):
                grid.add(x0, y0, x1, y1, w)
    cos_max = math.cos(math.radians(opt.max_angle_deg))
    by_way = {}  # way index -> list of (road id, verdict)
    roads_on_oneway = roads_matched = 0
    for rid, road in sorted(net.roads.items()):
        if road.junction != "-1":
            continue
        votes = {}  # (way index, +1 along / -1 against the way's nodes) -> samples
        for k in range(opt.samples):
            s = road.length * (k + 1) / (opt.samples + 1)
            x, y, h, _ = road.ref(s)
            hx, hy = math.cos(h), math.sin(h)
            best = None
            for seg in grid.near(x, y, opt.max_dist):
                dx, dy = seg[2] - seg[0], seg[3] - seg[1]
                ln = math.hypot(dx, dy)
                cosang = (dx * hx + dy * hy) / ln
                if abs(cosang) < cos_max:
                    continue
                d = point_segment(x, y, seg)
                if d <= opt.max_dist and (best is None or d < best[0]):
                    best = (d, seg[4], 1 if cosang > 0 else -1)
            if best is not None:
                votes[best[1:]] = votes.get(best[1:], 0) + 1
        match = max(votes, key=lambda m: (votes[m], -m[0], m[1]), default=None)
        if match is None or 2 * votes[match] <= opt.samples:
            continue
        roads_matched += 1
        w, along = match
        oneway = kept[w][1]
        if oneway == 0:
            continue
        roads_on_oneway += 1
        plus, minus = lane_directions(road, opt.taper_width)
        travel_plus = along * oneway > 0  # the way's traffic runs toward +s
        if plus and minus:
            verdict = "two_way"
        elif (plus and not travel_plus) or (minus and travel_plus):
            verdict = "against"
        else:
            verdict = "ok"
        by_way.setdefault(w, []).append((rid, verdict))
    checks = {}
    for name in ("two_way", "against"):
        bad = sorted((kept[w][0], [r for r, v in rs if v == name]) for w, rs in by_way.items()
                     if any(v == name for _, v in rs))
        checks[name] = {"failures": len(bad), "checked": len(by_way),
                        "offenders": [f"way {wid}: roads {', '.join(rs)}" for wid, rs in bad[:opt.max_list]],
                        "pass": not bad}
    return {"osm": os.path.basename(osm_path), "xodr": os.path.basename(xodr_path),
            "counts": {"ways": len(kept), "oneway_ways": sum(1 for _, o in kept if o),
                       "roads_matched": roads_matched, "roads_on_oneway_ways": roads_on_oneway,
                       "oneway_ways_with_roads": len(by_way)},
            "checks": checks, "pass": all(c["pass"] for c in checks.values())}


def summary(res):
    c = res["counts"]
    out = [f"{res['xodr']} against {res['osm']}: {c['ways']} road ways ({c['oneway_ways']} one-way), "
           f"{c['roads_matched']} roads on a way, {c['roads_on_oneway_ways']} of them on "
           f"{c['oneway_ways_with_roads']} one-way ways"]
    for name, ch in res["checks"].items():
        out.append(f"  {'ok  ' if ch['pass'] else 'FAIL'} {name}: {ch['failures']} one-way ways of {ch['checked']}")
        for o in ch["offenders"]:
            out.append(f"         {o}")
    out.append("PASS" if res["pass"] else "FAIL")
    return "\n".join(out)


def options(argv=None):
    ap = argparse.ArgumentParser(description="Check an OpenDRIVE file's lane directions against the one-way tags "
                                             "of its OpenStreetMap extract.")
    ap.add_argument("osm", help="the extract (.osm, .osm.gz, .osm.bz2, .osm.pbf)")
    ap.add_argument("xodr", help="the OpenDRIVE file written from it")
    ap.add_argument("--json", help="write counts and check results to this file")
    ap.add_argument("--max-dist", type=xodr_check.positive("--max-dist"), default=2.0,
                    help="farthest a road's reference line may lie from its way, m (2.0)")
    ap.add_argument("--max-angle-deg", type=xodr_check.positive("--max-angle-deg"), default=20.0,
                    help="largest angle between a road and the way segment it lies on, degrees (20)")
    ap.add_argument("--samples", type=int, default=5, help="reference-line samples per road (5, at least 1)")
    ap.add_argument("--taper-width", type=xodr_check.positive("--taper-width"), default=0.01,
                    help="lanes never wider than this do not count, m (0.01)")
    ap.add_argument("--max-list", type=int, default=20, help="offenders listed per check (20)")
    ap.add_argument("-q", "--quiet", action="store_true", help="print only the verdict")
    opt = ap.parse_args(argv)
    if opt.samples < 1:
        ap.error(f"--samples must be at least 1, got {opt.samples}")
    if opt.max_angle_deg >= 90:
        ap.error(f"--max-angle-deg must be below 90, got {opt.max_angle_deg}")
    return opt


def main(argv=None):
    opt = options(argv)
    try:
        res = run(opt.osm, opt.xodr, opt)
    except (InputError, xodr_check.InputError) as e:
        print(f"osm_oneway_check: {e}", file=sys.stderr)
        return 2
    if opt.json:
        with open(opt.json, "w") as f:
            json.dump(res, f, indent=1, sort_keys=True)
    print(("PASS" if res["pass"] else "FAIL") if opt.quiet else summary(res))
    return 0 if res["pass"] else 1


if __name__ == "__main__":
    sys.exit(main())
