#!/usr/bin/env python3
"""Independent evaluator of ASAM OpenDRIVE 1.6 files.

Reads a .xodr file (with or without an XML namespace on its elements),
evaluates its roads from the XML alone, following the OpenDRIVE 1.6
specification, and checks the continuity of the network:

  gaps        at every road-road link, junction connection and laneSection
              boundary, both borders of every pair of linked lanes meet
              (plan distance <= --max-gap, height difference <= --max-dz);
              consecutive planView geometries of a road meet as well;
  kinks       the reference-line heading jump at every road-road link, every
              incoming-road/connecting-road contact and every geometry join
              inside a road is at most --max-kink-deg;
  folds       no lane border passes the centre of curvature of its reference
              line (1 - k*t > 0, sampled every --fold-step metres and at every
              geometry and record boundary);
  unlinked    every driving lane has a successor where its traffic leaves the
              road at a linked end (right-hand traffic: right lanes toward +s,
              left lanes toward -s; rule="LHT" swaps), unless its width there
              is below --taper-width; at a junction, every driving lane whose
              traffic enters the junction is the `from` of a laneLink, and
              every driving lane whose traffic leaves it is the successor of
              a connecting road's driving lane that is itself reached from
              an incoming road's lane (a laneLink or a lane predecessor) and
              is at least --taper-width wide at both ends;
  signals     every <validity> has fromLane <= toLane; every signal's
              (country, type) is one that simulators' catalogues know
              (KNOWN_SIGNALS); the signals of one controller face traffic
              of one approach (one road, one direction) or of opposite
              approaches (travel directions within --max-group-deg of
              opposite); every crosswalk's
              outline lies within its road's s-range (corners projected on
              the reference line, --max-gap tolerance);
  references  every referenced road, junction, lane, controller, signal and
              object exists, ids are unique, road links are symmetric and
              junction connections name roads of that junction;
  planview    geometry records follow each other in s and sum to the road
              length (within --max-length-error).

The evaluation shares nothing with the generator that writes the file.

Exit status: 0 all checks pass, 1 a check fails, 2 the input cannot be read
or is not an OpenDRIVE file this tool can evaluate (the message names the
element and attribute).

Usage: xodr_check.py FILE.xodr [--json OUT.json] [--xsd opendrive_16_core.xsd]
"""
import argparse
import bisect
import json
import math
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

TWO_PI = 2.0 * math.pi

# Lane types that carry motor traffic in one direction (OpenDRIVE 1.6 e_laneType).
DRIVING_TYPES = {"driving", "entry", "exit", "onRamp", "offRamp", "connectingRamp",
                 "mwyEntry", "mwyExit", "bus", "taxi", "HOV"}

# (country, type) of signals that simulators' catalogues know: the generic
# OpenDRIVE signals (traffic lights 1000001-1000020 as esmini's
# opendrive_traffic_signals catalogue lists them) and the German signs that
# esmini, CARLA and the ASAM examples read (205 yield, 206 stop, 274 speed
# limit, 301 right of way at the next junction, 306 priority road, 350 zebra
# crossing).
KNOWN_SIGNALS = ({("OpenDRIVE", str(1000000 + k)) for k in (1, 2, 3, 4, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17,
                                                              18, 19, 20)} |
                 {("DE", t) for t in ("205", "206", "274", "301", "306", "350")})

# Gauss-Legendre nodes and weights on [-1, 1] (5 points, exact to degree 9).
_GL_X = (-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640)
_GL_W = (0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665, 0.2369268850561891)


class InputError(Exception):
    """The file cannot be evaluated; the message says where and why."""


def gauss(f, a, b):
    """Integral of f over [a, b] by 5-point Gauss-Legendre."""
    h = 0.5 * (b - a)
    m = 0.5 * (a + b)
    return h * sum(w * f(m + h * x) for x, w in zip(_GL_X, _GL_W))


def wrap_angle(a):
    """a mapped to [-pi, pi)."""
    return (a + math.pi) % TWO_PI - math.pi


def cubic(rec, ds):
    """a + b ds + c ds^2 + d ds^3 for a record (start, a, b, c, d)."""
    return rec[1] + ds * (rec[2] + ds * (rec[3] + ds * rec[4]))


def cubic_slope(rec, ds):
    return rec[2] + ds * (2.0 * rec[3] + ds * 3.0 * rec[4])


def piece(records, starts, s):
    """The record of a piecewise list valid at s (the last one starting at or before s)."""
    if not records:
        return None
    i = bisect.bisect_right(starts, s + 1e-9) - 1
    return records[max(i, 0)]


def piecewise(records, starts, s, default=0.0):
    rec = piece(records, starts, s)
    return default if rec is None else cubic(rec, s - rec[0])


# ---------------------------------------------------------------------------
# XML access

class Where:
    """A readable location for error messages: 'road 12 / geometry 2'."""

    def __init__(self, text):
        self.text = text

    def attr(self, el, name, default=None, kind=float):
        v = el.get(name)
        if v is None:
            if default is not None:
                return default
            raise InputError(f"{self.text}: <{el.tag}> lacks the required attribute '{name}'")
        try:
            x = kind(v)
        except ValueError:
            raise InputError(f"{self.text}: <{el.tag}> attribute '{name}'=\"{v}\" is not a {kind.__name__}")
        if kind is float and not math.isfinite(x):
            raise InputError(f"{self.text}: <{el.tag}> attribute '{name}'=\"{v}\" is not finite")
        return x


def strip_namespaces(root):
    for el in root.iter():
        if isinstance(el.tag, str) and "}" in el.tag:
            el.tag = el.tag.rsplit("}", 1)[1]


def children(el, tag):
    return [] if el is None else el.findall(tag)


# ---------------------------------------------------------------------------
# planView geometry: each evaluates (x, y, heading, curvature) at ds in [0, length]

class Geometry:
    def __init__(self, s, x, y, hdg, length):
        self.s, self.x, self.y, self.hdg, self.length = s, x, y, hdg, length

    def local_to_world(self, u, v):
        c, s = math.cos(self.hdg), math.sin(self.hdg)
        return self.x + u * c - v * s, self.y + u * s + v * c


class Line(Geometry):
    kind = "line"

    def at(self, ds):
        return (self.x + ds * math.cos(self.hdg), self.y + ds * math.sin(self.hdg), self.hdg, 0.0)


class Arc(Geometry):
    kind = "arc"

    def __init__(self, s, x, y, hdg, length, k):
        super().__init__(s, x, y, hdg, length)
        self.k = k

    def at(self, ds):
        k = self.k
        h = self.hdg + k * ds
        if abs(k * ds) < 1e-9:  # the chord of a nearly straight piece
            return (self.x + ds * math.cos(self.hdg + 0.5 * k * ds),
                    self.y + ds * math.sin(self.hdg + 0.5 * k * ds), h, k)
        return (self.x + (math.sin(h) - math.sin(self.hdg)) / k,
                self.y - (math.cos(h) - math.cos(self.hdg)) / k, h, k)


class Spiral(Geometry):
    """Clothoid: curvature linear in ds from curvStart to curvEnd; position by
    Gauss-Legendre integration of the heading's cosine and sine, tabulated at
    nodes no more than 1 m apart."""
    kind = "spiral"
    STEP = 1.0

    def __init__(self, s, x, y, hdg, length, k0, k1):
        super().__init__(s, x, y, hdg, length)
        self.k0 = k0
        self.rate = (k1 - k0) / length if length > 0 else 0.0
        n = max(1, int(math.ceil(length / self.STEP)))
        self.h = length / n if length > 0 else 1.0
        self.nodes = [(0.0, 0.0)]
        for i in range(n):
            a, b = i * self.h, (i + 1) * self.h
            du, dv = self._integrate(a, b)
            u, v = self.nodes[-1]
            self.nodes.append((u + du, v + dv))

    def heading(self, ds):
        return self.k0 * ds + 0.5 * self.rate * ds * ds  # relative to self.hdg

    def _integrate(self, a, b):
        return (gauss(lambda t: math.cos(self.heading(t)), a, b),
                gauss(lambda t: math.sin(self.heading(t)), a, b))

    def at(self, ds):
        i = min(int(ds / self.h), len(self.nodes) - 1) if ds > 0 else 0
        u, v = self.nodes[i]
        a = i * self.h
        if ds > a:
            du, dv = self._integrate(a, ds)
            u, v = u + du, v + dv
        x, y = self.local_to_world(u, v)
        return (x, y, self.hdg + self.heading(ds), self.k0 + self.rate * ds)


class Poly3(Geometry):
    """v(u) = a + b u + c u^2 + d u^3 in the local frame; s is arc length,
    so u(s) is found from a tabulated arc-length integral and Newton steps."""
    kind = "poly3"

    def __init__(self, s, x, y, hdg, length, a, b, c, d):
        super().__init__(s, x, y, hdg, length)
        self.co = (a, b, c, d)
        self.us, self.ss = [0.0], [0.0]
        du = 0.5
        while self.ss[-1] < length and len(self.us) < 1000000:
            u0 = self.us[-1]
            self.ss.append(self.ss[-1] + gauss(self.speed, u0, u0 + du))
            self.us.append(u0 + du)

    def dv(self, u):
        a, b, c, d = self.co
        return b + u * (2 * c + 3 * d * u)

    def speed(self, u):
        return math.sqrt(1.0 + self.dv(u) ** 2)

    def u_at(self, ds):
        i = max(0, min(bisect.bisect_right(self.ss, ds) - 1, len(self.ss) - 2))
        u0, s0 = self.us[i], self.ss[i]
        u = u0 + (ds - s0) / max(self.speed(u0), 1e-12)
        for _ in range(30):
            err = s0 + gauss(self.speed, u0, u) - ds
            u -= err / self.speed(u)
            if abs(err) < 1e-12:
                break
        return u

    def at(self, ds):
        u = self.u_at(ds)
        a, b, c, d = self.co
        v = a + u * (b + u * (c + u * d))
        v1 = self.dv(u)
        v2 = 2 * c + 6 * d * u
        x, y = self.local_to_world(u, v)
        return (x, y, self.hdg + math.atan(v1), v2 / (1.0 + v1 * v1) ** 1.5)


class ParamPoly3(Geometry):
    """u(p), v(p) cubic in p; p = ds for pRange="arcLength" and
    p = ds / length for pRange="normalized"."""
    kind = "paramPoly3"

    def __init__(self, s, x, y, hdg, length, U, V, normalized):
        super().__init__(s, x, y, hdg, length)
        self.U, self.V = U, V
        self.scale = (1.0 / length if length > 0 else 0.0) if normalized else 1.0

    def at(self, ds):
        p = ds * self.scale
        (au, bu, cu, du), (av, bv, cv, dv) = self.U, self.V
        u = au + p * (bu + p * (cu + p * du))
        v = av + p * (bv + p * (cv + p * dv))
        u1, v1 = bu + p * (2 * cu + 3 * du * p), bv + p * (2 * cv + 3 * dv * p)
        u2, v2 = 2 * cu + 6 * du * p, 2 * cv + 6 * dv * p
        x, y = self.local_to_world(u, v)
        sp2 = u1 * u1 + v1 * v1
        k = (u1 * v2 - v1 * u2) / sp2 ** 1.5 if sp2 > 0 else 0.0
        return (x, y, self.hdg + math.atan2(v1, u1), k)


def parse_geometry(el, where):
    s = where.attr(el, "s")
    x, y, hdg = where.attr(el, "x"), where.attr(el, "y"), where.attr(el, "hdg")
    length = where.attr(el, "length")
    if length < 0:
        raise InputError(f"{where.text}: <geometry> length {length} is negative")
    kinds = [c for c in el if c.tag in ("line", "arc", "spiral", "poly3", "paramPoly3")]
    if len(kinds) != 1:
        raise InputError(f"{where.text}: <geometry> holds {len(kinds)} of line/arc/spiral/poly3/paramPoly3, needs exactly 1")
    g = kinds[0]
    if g.tag == "line":
        return Line(s, x, y, hdg, length)
    if g.tag == "arc":
        return Arc(s, x, y, hdg, length, where.attr(g, "curvature"))
    if g.tag == "spiral":
        return Spiral(s, x, y, hdg, length, where.attr(g, "curvStart"), where.attr(g, "curvEnd"))
    if g.tag == "poly3":
        return Poly3(s, x, y, hdg, length, *(where.attr(g, n) for n in "abcd"))
    p_range = g.get("pRange", "normalized")
    if p_range not in ("arcLength", "normalized"):
        raise InputError(f"{where.text}: <paramPoly3> pRange=\"{p_range}\" is not arcLength or normalized")
    U = tuple(where.attr(g, n + "U") for n in "abcd")
    V = tuple(where.attr(g, n + "V") for n in "abcd")
    return ParamPoly3(s, x, y, hdg, length, U, V, p_range == "normalized")


# ---------------------------------------------------------------------------
# roads, lane sections, lanes

class Lane:
    def __init__(self, el, where):
        self.id = where.attr(el, "id", kind=int)
        self.type = el.get("type", "none")
        self.level = el.get("level", "false") in ("true", "1")
        link = el.find("link")
        self.pred = [where.attr(p, "id", kind=int) for p in children(link, "predecessor")]
        self.succ = [where.attr(p, "id", kind=int) for p in children(link, "successor")]
        self.widths = sorted(((where.attr(w, "sOffset"), where.attr(w, "a"), where.attr(w, "b"),
                               where.attr(w, "c"), where.attr(w, "d")) for w in el.findall("width")),
                             key=lambda r: r[0])
        self.borders = sorted(((where.attr(w, "sOffset"), where.attr(w, "a"), where.attr(w, "b"),
                                where.attr(w, "c"), where.attr(w, "d")) for w in el.findall("border")),
                              key=lambda r: r[0])
        self.heights = sorted(((where.attr(h, "sOffset"), where.attr(h, "inner"), where.attr(h, "outer"))
                               for h in el.findall("height")), key=lambda r: r[0])
        self.width_starts = [r[0] for r in self.widths]
        self.border_starts = [r[0] for r in self.borders]
        self.height_starts = [r[0] for r in self.heights]
        if self.id != 0 and not self.widths and not self.borders:
            raise InputError(f"{where.text}: lane {self.id} has neither <width> nor <border>")


class Section:
    def __init__(self, el, where):
        self.s = where.attr(el, "s")
        self.end = None  # set by the road
        self.lanes = {}
        for side in ("left", "center", "right"):
            for lel in children(el.find(side), "lane"):
                lane = Lane(lel, where)
                if (side == "left" and lane.id <= 0) or (side == "right" and lane.id >= 0) or \
                        (side == "center" and lane.id != 0):
                    raise InputError(f"{where.text}: lane id {lane.id} is not allowed in <{side}>")
                if lane.id in self.lanes:
                    raise InputError(f"{where.text}: lane id {lane.id} appears twice")
                self.lanes[lane.id] = lane
        self.left = sorted(i for i in self.lanes if i > 0)
        self.right = sorted((i for i in self.lanes if i < 0), reverse=True)


class Road:
    def __init__(self, el, header_rule):
        self.id = el.get("id")
        where = Where(f"road {self.id}")
        if self.id is None:
            raise InputError("a <road> lacks the required attribute 'id'")
        self.length = where.attr(el, "length")
        self.junction = el.get("junction", "-1")
        self.rule = el.get("rule", header_rule)
        if self.rule not in ("RHT", "LHT"):
            raise InputError(f"{where.text}: rule=\"{self.rule}\" is not RHT or LHT")
        self.links = {}
        link = el.find("link")
        for tag in ("predecessor", "successor"):
            for p in children(link, tag):
                self.links[tag] = {"type": p.get("elementType", "road"), "id": p.get("elementId"),
                                   "cp": p.get("contactPoint")}
        pv = el.find("planView")
        if pv is None or not pv.findall("geometry"):
            raise InputError(f"{where.text}: no <planView> geometry")
        self.geoms = []
        for i, g in enumerate(pv.findall("geometry")):
            self.geoms.append(parse_geometry(g, Where(f"road {self.id} geometry {i}")))
        self.geoms.sort(key=lambda g: g.s)
        self.geom_starts = [g.s for g in self.geoms]

        def records(parent, tag, s_name="s"):
            recs = sorted(((where.attr(r, s_name), where.attr(r, "a"), where.attr(r, "b"), where.attr(r, "c"),
                            where.attr(r, "d")) for r in children(parent, tag)), key=lambda r: r[0])
            return recs, [r[0] for r in recs]

        self.elev, self.elev_starts = records(el.find("elevationProfile"), "elevation")
        lat = el.find("lateralProfile")
        self.superel, self.superel_starts = records(lat, "superelevation")
        shapes = {}
        for r in children(lat, "shape"):
            shapes.setdefault(where.attr(r, "s"), []).append(
                (where.attr(r, "t"), where.attr(r, "a"), where.attr(r, "b"), where.attr(r, "c"), where.attr(r, "d")))
        self.shape_s = sorted(shapes)
        self.shapes = [sorted(shapes[s]) for s in self.shape_s]
        lanes = el.find("lanes")
        if lanes is None:
            raise InputError(f"{where.text}: no <lanes>")
        self.offsets, self.offset_starts = records(lanes, "laneOffset")
        self.sections = sorted((Section(s, Where(f"road {self.id} laneSection {i}"))
                                for i, s in enumerate(lanes.findall("laneSection"))), key=lambda sec: sec.s)
        if not self.sections:
            raise InputError(f"{where.text}: no <laneSection>")
        for a, b in zip(self.sections, self.sections[1:]):
            a.end = b.s
        self.sections[-1].end = self.length
        self.section_starts = [sec.s for sec in self.sections]
        self.signals = el.find("signals")
        self.objects = el.find("objects")

    # -- reference line
    def ref(self, s):
        g = self.geoms[max(0, bisect.bisect_right(self.geom_starts, s + 1e-9) - 1)]
        return g.at(min(max(s - g.s, 0.0), g.length))

    def offset(self, s):
        return piecewise(self.offsets, self.offset_starts, s)

    def elevation(self, s):
        return piecewise(self.elev, self.elev_starts, s)

    def superelevation(self, s):
        return piecewise(self.superel, self.superel_starts, s)

    def shape_height(self, s, t):
        if not self.shapes:
            return 0.0

        def at_group(recs):
            starts = [r[0] for r in recs]
            return piecewise(recs, starts, t)
        i = bisect.bisect_right(self.shape_s, s + 1e-9) - 1
        if i < 0:
            return at_group(self.shapes[0])
        if i >= len(self.shapes) - 1:
            return at_group(self.shapes[-1])
        s0, s1 = self.shape_s[i], self.shape_s[i + 1]
        f = (s - s0) / (s1 - s0)
        return (1 - f) * at_group(self.shapes[i]) + f * at_group(self.shapes[i + 1])

    def surface(self, s, t):
        return self.elevation(s) + t * math.tan(self.superelevation(s)) + self.shape_height(s, t)

    # -- lanes
    def section_index(self, s, at_end=False):
        """The lane section that holds s; at_end picks the one ending at s on a boundary."""
        i = bisect.bisect_right(self.section_starts, s + 1e-9) - 1
        if at_end:
            while i > 0 and self.sections[i].s >= s - 1e-9:
                i -= 1
        return max(i, 0)

    def lane_width(self, sec, lane, s):
        ds = s - sec.s
        return piecewise(lane.widths, lane.width_starts, ds)

    def borders(self, sec, s):
        """{lane id: (t_inner, t_outer)} at s within section sec; the centre lane is (t0, t0)."""
        t0 = self.offset(s)
        out = {0: (t0, t0)}
        ds = s - sec.s
        for ids, sign in ((sec.left, 1.0), (sec.right, -1.0)):
            t = t0
            for i in ids:
                lane = sec.lanes[i]
                if lane.widths:
                    t_out = t + sign * piecewise(lane.widths, lane.width_starts, ds)
                else:  # <border>: the outer border's distance from the centre lane
                    t_out = t0 + sign * piecewise(lane.borders, lane.border_starts, ds)
                out[i] = (t, t_out)
                t = t_out
        return out

    def border_points(self, sec, s):
        """{lane id: ((x, y, z) inner, (x, y, z) outer)} at s within section sec.
        Lanes with level="true" keep the height of their inner border (no
        superelevation); <height> records add to the inner and outer heights."""
        x, y, h, _ = self.ref(s)
        nx, ny = -math.sin(h), math.cos(h)
        res = {}
        ds = s - sec.s
        for i, (ti, to) in self.borders(sec, s).items():
            lane = sec.lanes.get(i)
            zi = self.surface(s, ti)
            zo = zi if (lane is not None and lane.level) else self.surface(s, to)
            if lane is not None and lane.heights:
                hr = piece(lane.heights, lane.height_starts, ds)
                zi, zo = zi + hr[1], zo + hr[2]
            res[i] = ((x + ti * nx, y + ti * ny, zi), (x + to * nx, y + to * ny, zo))
        return res

    def end_s(self, end):
        return 0.0 if end == "start" else self.length

    def end_section(self, end):
        return self.sections[0] if end == "start" else self.sections[-1]

    def link_at(self, end):
        return self.links.get("predecessor" if end == "start" else "successor")


# ---------------------------------------------------------------------------
# the checks

class Check:
    """One rule: how many failures, the worst value and the first offenders."""

    def __init__(self, name, limit, unit, max_list):
        self.name, self.limit, self.unit = name, limit, unit
        self.failures = 0
        self.checked = 0
        self.worst = None
        self.worst_where = None
        self.offenders = []
        self.max_list = max_list
        self.by_kind = {}

    def value(self, v, where, worse=lambda a, b: a > b):
        if self.worst is None or worse(v, self.worst):
            self.worst, self.worst_where = v, where

    def fail(self, where, kind=None):
        self.failures += 1
        if kind:
            self.by_kind[kind] = self.by_kind.get(kind, 0) + 1
        if len(self.offenders) < self.max_list:
            self.offenders.append(where)

    def as_json(self):
        return {"failures": self.failures, "checked": self.checked, "limit": self.limit, "unit": self.unit,
                "worst": self.worst, "worst_at": self.worst_where, "offenders": self.offenders,
                "failures_by_kind": self.by_kind, "pass": self.failures == 0}


class Network:
    def __init__(self, root):
        if root.tag != "OpenDRIVE":
            raise InputError(f"the root element is <{root.tag}>, not <OpenDRIVE>")
        header = root.find("header")
        if header is None:
            raise InputError("<OpenDRIVE> has no <header>")
        self.header = {k: header.get(k) for k in ("revMajor", "revMinor", "name")}
        rule = header.get("rule", "RHT")
        self.roads = {}
        self.duplicates = []
        for el in root.findall("road"):
            r = Road(el, rule)
            if r.id in self.roads:
                self.duplicates.append(f"road id {r.id} appears twice")
            self.roads[r.id] = r
        if not self.roads:
            raise InputError("<OpenDRIVE> holds no <road>")
        self.junctions = {}
        for el in root.findall("junction"):
            jid = el.get("id")
            if jid is None:
                raise InputError("a <junction> lacks the required attribute 'id'")
            if jid in self.junctions:
                self.duplicates.append(f"junction id {jid} appears twice")
            self.junctions[jid] = el
        self.controllers = {}
        for el in root.findall("controller"):
            cid = el.get("id")
            if cid in self.controllers:
                self.duplicates.append(f"controller id {cid} appears twice")
            self.controllers[cid] = el


def section_samples(r, sec, step):
    """Sorted s values covering lane section sec of road r: every `step` metres,
    at every geometry, laneOffset and width/border record start, and just
    before each of those."""
    lo, hi = sec.s, sec.end
    if hi <= lo:
        return []
    pts = set(g.s for g in r.geoms) | set(o[0] for o in r.offsets)
    for lane in sec.lanes.values():
        pts |= set(sec.s + w[0] for w in lane.widths) | set(sec.s + w[0] for w in lane.borders)
    n_steps = max(1, int(math.ceil((hi - lo) / step)))
    samples = {lo + (hi - lo) * i / n_steps for i in range(n_steps + 1)}
    for p in pts:
        if lo <= p <= hi:
            samples.add(p)
            if p - 1e-7 >= lo:
                samples.add(p - 1e-7)
    return sorted(samples)


# ---------------------------------------------------------------------------
# overlaps: lane polygons of different roads sharing area

def clip_area(subject, clip):
    """Area of the intersection of two convex counter-clockwise polygons
    (Sutherland-Hodgman clipping of subject by each edge of clip; exact up to
    floating point; touching polygons give 0)."""
    out = subject
    n = len(clip)
    for i in range(n):
        if len(out) < 3:
            return 0.0
        ax, ay = clip[i - 1]
        bx, by = clip[i]
        ex, ey = bx - ax, by - ay
        inp, out = out, []
        px, py = inp[-1]
        dp = ex * (py - ay) - ey * (px - ax)
        for cx, cy in inp:
            dc = ex * (cy - ay) - ey * (cx - ax)
            if dc >= 0.0:
                if dp < 0.0:
                    f = dp / (dp - dc)
                    out.append((px + f * (cx - px), py + f * (cy - py)))
                out.append((cx, cy))
            elif dp > 0.0:
                f = dp / (dp - dc)
                out.append((px + f * (cx - px), py + f * (cy - py)))
            px, py, dp = cx, cy, dc
    if len(out) < 3:
        return 0.0
    a = 0.0
    x0, y0 = out[-1]
    for x1, y1 in out:
        a += x0 * y1 - x1 * y0
        x0, y0 = x1, y1
    return 0.5 * a


class RoadSurface:
    """The lanes of one road as counter-clockwise triangles in plan, two per
    sampled step of each lane (inner and outer border at consecutive s),
    with their bounding boxes on a grid of `cell` metres. Triangles of one
    road do not overlap each other unless the road folds (the folds check)."""

    def __init__(self, r, step, cell, min_width):
        self.road = r
        self.cell = cell
        self.tris = []   # (points, xmin, ymin, xmax, ymax, driving, lane id)
        self.grid = {}
        lo = [math.inf, math.inf]
        hi = [-math.inf, -math.inf]
        for sec in r.sections:
            prev = None
            for s in section_samples(r, sec, step):
                x, y, h, _ = r.ref(s)
                nx, ny = -math.sin(h), math.cos(h)
                cur = {lid: ((x + ti * nx, y + ti * ny), (x + to * nx, y + to * ny), abs(to - ti))
                       for lid, (ti, to) in r.borders(sec, s).items() if lid != 0}
                if prev is not None:
                    for lid, (i1, o1, w1) in cur.items():
                        if lid not in prev:
                            continue
                        i0, o0, w0 = prev[lid]
                        if w0 < min_width and w1 < min_width:
                            continue
                        driving = sec.lanes[lid].type in DRIVING_TYPES
                        for tri in ((i0, o0, o1), (i0, o1, i1)):
                            self.add(tri, driving, lid, lo, hi)
                prev = cur
        self.bbox = (lo[0], lo[1], hi[0], hi[1])

    def add(self, tri, driving, lid, lo, hi):
        (ax, ay), (bx, by), (cx, cy) = tri
        area2 = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
        if abs(area2) < 1e-12:
            return
        if area2 < 0:
            tri = (tri[0], tri[2], tri[1])
        xs, ys = (ax, bx, cx), (ay, by, cy)
        t = (tri, min(xs), min(ys), max(xs), max(ys), driving, lid)
        idx = len(self.tris)
        self.tris.append(t)
        lo[0], lo[1] = min(lo[0], t[1]), min(lo[1], t[2])
        hi[0], hi[1] = max(hi[0], t[3]), max(hi[1], t[4])
        c = self.cell
        for gx in range(int(math.floor(t[1] / c)), int(math.floor(t[3] / c)) + 1):
            for gy in range(int(math.floor(t[2] / c)), int(math.floor(t[4] / c)) + 1):
                self.grid.setdefault((gx, gy), []).append(idx)

    def overlap(self, other):
        """(driving area, any-lane area) shared with another road's surface."""
        drive = total = 0.0
        c = self.cell
        for tb, bx0, by0, bx1, by1, bdrive, _ in other.tris:
            seen = set()
            for gx in range(int(math.floor(bx0 / c)), int(math.floor(bx1 / c)) + 1):
                for gy in range(int(math.floor(by0 / c)), int(math.floor(by1 / c)) + 1):
                    seen.update(self.grid.get((gx, gy), ()))
            for i in seen:
                ta, ax0, ay0, ax1, ay1, adrive, _ = self.tris[i]
                if ax0 >= bx1 or bx0 >= ax1 or ay0 >= by1 or by0 >= ay1:
                    continue
                a = clip_area(ta, tb)
                if a > 0.0:
                    total += a
                    if adrive and bdrive:
                        drive += a
        return drive, total


def check_overlaps(net, opt):
    """Pairs of roads whose driving lanes share more than --max-overlap m^2
    of plan area, except connecting roads of one junction (which overlap by
    design inside it). Lane polygons are sampled every --overlap-step metres
    from the XML; each pair's area is the sum of exact triangle-triangle
    intersections. Failures by kind: between street roads, a street road and
    a connecting road, connecting roads of different junctions."""
    ch = Check("overlaps", opt.max_overlap, "m^2", opt.max_list)
    ch.total_area = 0.0
    ch.surface_pairs = 0  # pairs whose lanes of any type (sidewalks too) overlap
    if opt.overlap_step <= 0:
        return ch
    cell = 4.0
    surf = [RoadSurface(r, opt.overlap_step, cell, opt.taper_width) for r in net.roads.values()]
    surf = [sf for sf in surf if sf.tris]
    big = 64.0  # road bounding boxes on a coarse grid
    grid = {}
    for k, sf in enumerate(surf):
        x0, y0, x1, y1 = sf.bbox
        for gx in range(int(math.floor(x0 / big)), int(math.floor(x1 / big)) + 1):
            for gy in range(int(math.floor(y0 / big)), int(math.floor(y1 / big)) + 1):
                grid.setdefault((gx, gy), []).append(k)
    pairs = set()
    for members in grid.values():
        for i in range(len(members)):
            for j in range(i + 1, len(members)):
                pairs.add((members[i], members[j]))
    for i, j in sorted(pairs):
        a, b = surf[i], surf[j]
        ra, rb = a.road, b.road
        if ra.junction != "-1" and ra.junction == rb.junction:
            continue
        if a.bbox[0] >= b.bbox[2] or b.bbox[0] >= a.bbox[2] or a.bbox[1] >= b.bbox[3] or b.bbox[1] >= a.bbox[3]:
            continue
        ch.checked += 1
        if len(a.tris) < len(b.tris):
            a, b = b, a
        drive, total = a.overlap(b)
        if total > opt.max_overlap:
            ch.surface_pairs += 1
        ch.value(drive, f"road {a.road.id} / road {b.road.id}")
        if drive > opt.max_overlap:
            ch.total_area += drive
            ja, jb = a.road.junction, b.road.junction
            kind = ("street roads" if ja == "-1" and jb == "-1" else
                    "street road / connecting road" if ja == "-1" or jb == "-1" else
                    "connecting roads of different junctions")
            names = sorted((a.road, b.road), key=lambda r: r.id)
            label = " / ".join(f"road {r.id}" + ("" if r.junction == "-1" else f" (junction {r.junction})")
                               for r in names)
            ch.fail(f"{label}: driving lanes share {drive:.3f} m^2", kind)
    return ch


def check_network(net, opt):
    n = opt.max_list
    gaps = Check("gaps", {"plan_m": opt.max_gap, "height_m": opt.max_dz}, "m", n)
    gaps.worst_dz = None
    kinks = Check("kinks", opt.max_kink_deg, "deg", n)
    folds = Check("folds", {"1-k*t": 0.0, "margin_m": opt.fold_margin}, "1-k*t", n)
    folds.worst_margin = None
    turns = Check("turn_radius", opt.min_turn_radius, "m", n)
    unlinked = Check("unlinked", opt.taper_width, "m", n)
    refs = Check("references", None, "", n)
    planview = Check("planview", opt.max_length_error, "m", n)
    signals = Check("signals", opt.max_group_deg, "deg", n)
    roads = net.roads

    for d in net.duplicates:
        refs.fail(d)

    # -- planView consistency and geometry joins inside a road
    for r in roads.values():
        expect = 0.0
        for i, g in enumerate(r.geoms):
            planview.checked += 1
            err = abs(g.s - expect)
            planview.value(err, f"road {r.id} geometry {i} s")
            if err > opt.max_length_error:
                planview.fail(f"road {r.id} geometry {i}: s={g.s:.4f}, previous geometries end at {expect:.4f}")
            expect = g.s + g.length
            if i > 0:
                p = r.geoms[i - 1]
                x0, y0, h0, _ = p.at(p.length)
                d = math.hypot(g.x - x0, g.y - y0)
                gaps.checked += 1
                gaps.value(d, f"road {r.id} geometry {i - 1}->{i}")
                if d > opt.max_gap:
                    gaps.fail(f"road {r.id} geometry {i - 1}->{i}: plan {d:.4f} m", "geometry")
                jump = abs(math.degrees(wrap_angle(g.hdg - h0)))
                kinks.checked += 1
                kinks.value(jump, f"road {r.id} geometry {i - 1}->{i}")
                if jump > opt.max_kink_deg:
                    kinks.fail(f"road {r.id} geometry {i - 1}->{i}: {jump:.3f} deg", "geometry")
        planview.checked += 1
        err = abs(expect - r.length)
        planview.value(err, f"road {r.id} length")
        if err > opt.max_length_error:
            planview.fail(f"road {r.id}: geometries sum to {expect:.4f} m, length=\"{r.length:.4f}\"")
        for sec in r.sections:
            if not (-1e-9 <= sec.s <= r.length + 1e-9):
                refs.fail(f"road {r.id}: laneSection s={sec.s} outside [0, {r.length}]")
        refs.checked += 1
        if r.junction != "-1" and r.junction not in net.junctions:
            refs.fail(f"road {r.id}: junction=\"{r.junction}\" does not exist")

    # -- contacts between road ends: (road A, end A, road B, end B) with lane pairs
    contacts = {}  # key -> dict

    def add_contact(kind, a, ea, b, eb, pairs, label):
        key = frozenset([(a.id, ea), (b.id, eb)])
        c = contacts.get(key)
        j = a.junction if a.junction != "-1" else b.junction
        if j != "-1":  # a connecting road's end: reported under its junction
            kind, label = "junction", f"junction {j}"
        if c is None:
            c = contacts[key] = {"kind": kind, "a": a, "ea": ea, "b": b, "eb": eb, "pairs": set(), "label": label}
        for la, lb in pairs:
            c["pairs"].add((la, lb) if c["a"] is a else (lb, la))

    def lane_exists(road, end, lane_id):
        return lane_id in road.end_section(end).lanes

    for r in roads.values():
        for tag, end in (("predecessor", "start"), ("successor", "end")):
            link = r.links.get(tag)
            if link is None:
                continue
            where = f"road {r.id} {tag}"
            refs.checked += 1
            if link["type"] == "junction":
                if link["id"] not in net.junctions:
                    refs.fail(f"{where}: junction {link['id']} does not exist")
                continue
            if link["type"] != "road":
                refs.fail(f"{where}: elementType=\"{link['type']}\" is not road or junction")
                continue
            other = roads.get(link["id"])
            if other is None:
                refs.fail(f"{where}: road {link['id']} does not exist")
                continue
            if link["cp"] not in ("start", "end"):
                refs.fail(f"{where}: contactPoint=\"{link['cp']}\" is not start or end")
                continue
            refs.checked += 1
            # symmetry: the other road links back to this one (or to this road's junction)
            back = other.link_at(link["cp"])
            ok = back is not None and ((back["type"] == "road" and back["id"] == r.id and back["cp"] == end) or
                                       (back["type"] == "junction" and r.junction != "-1" and
                                        back["id"] == r.junction and other.junction == "-1"))
            if not ok:
                refs.fail(f"{where}: road {other.id} {link['cp']} does not link back to road {r.id} {end}")
            sec = r.end_section(end)
            pairs = []
            for lane in sec.lanes.values():
                for target in (lane.pred if end == "start" else lane.succ):
                    refs.checked += 1
                    if not lane_exists(other, link["cp"], target):
                        refs.fail(f"{where}: lane {lane.id} links to lane {target}, which road {other.id} "
                                  f"lacks at its {link['cp']}")
                    else:
                        pairs.append((lane.id, target))
            add_contact("road link", r, end, other, link["cp"], pairs, "road link")

    # junction connections: incoming road end <-> connecting road contact point
    incoming_links = {}  # (road id, lane id) -> set of junction ids providing a laneLink
    for jid, jel in net.junctions.items():
        for ci, con in enumerate(jel.findall("connection")):
            where = f"junction {jid} connection {con.get('id', ci)}"
            inc, conn_id, cp = con.get("incomingRoad"), con.get("connectingRoad"), con.get("contactPoint")
            I, C = roads.get(inc), roads.get(conn_id)
            refs.checked += 3
            if I is None:
                refs.fail(f"{where}: incomingRoad {inc} does not exist")
            if C is None:
                refs.fail(f"{where}: connectingRoad {conn_id} does not exist")
            elif C.junction != jid:
                refs.fail(f"{where}: connectingRoad {conn_id} has junction=\"{C.junction}\", not {jid}")
            if cp not in ("start", "end"):
                refs.fail(f"{where}: contactPoint=\"{cp}\" is not start or end")
            if I is None or C is None or cp not in ("start", "end"):
                continue
            back = C.link_at(cp)
            refs.checked += 1
            if back is None or back["type"] != "road" or back["id"] != I.id:
                refs.fail(f"{where}: connectingRoad {C.id} does not link to incomingRoad {I.id} at its {cp}")
            ends = [e for e in ("start", "end")
                    if (I.link_at(e) or {}).get("type") == "junction" and I.link_at(e)["id"] == jid]
            if not ends:
                ends = [e for e in ("start", "end") if (I.link_at(e) or {}).get("type") == "road"
                        and I.link_at(e)["id"] == C.id]
            if not ends:
                refs.fail(f"{where}: incomingRoad {inc} links neither to junction {jid} nor to road {C.id}")
                continue
            if len(ends) > 1:  # both ends at this junction: the one nearest the contact point
                cx, cy = C.ref(C.end_s(cp))[:2]
                ends.sort(key=lambda e: math.hypot(*(a - b for a, b in zip(I.ref(I.end_s(e))[:2], (cx, cy)))))
            ei = ends[0]
            pairs = []
            for ll in con.findall("laneLink"):
                refs.checked += 1
                try:
                    lf, lt = int(ll.get("from")), int(ll.get("to"))
                except (TypeError, ValueError):
                    refs.fail(f"{where}: laneLink from=\"{ll.get('from')}\" to=\"{ll.get('to')}\" are not lane ids")
                    continue
                if not lane_exists(I, ei, lf):
                    refs.fail(f"{where}: laneLink from lane {lf}, which road {I.id} lacks at its {ei}")
                    continue
                if not lane_exists(C, cp, lt):
                    refs.fail(f"{where}: laneLink to lane {lt}, which road {C.id} lacks at its {cp}")
                    continue
                pairs.append((lf, lt))
                incoming_links.setdefault((I.id, ei, lf), set()).add(jid)
            add_contact("junction", I, ei, C, cp, pairs, f"junction {jid}")

    # controllers, signals, objects
    signal_ids, object_ids = {}, {}
    for r in roads.values():
        for sg in children(r.signals, "signal"):
            sid = sg.get("id")
            if sid in signal_ids:
                refs.fail(f"road {r.id}: signal id {sid} appears twice")
            signal_ids[sid] = r.id
        for ob in children(r.objects, "object"):
            oid = ob.get("id")
            if oid in object_ids:
                refs.fail(f"road {r.id}: object id {oid} appears twice")
            object_ids[oid] = r.id
    for r in roads.values():
        for kind, parent, tags in (("signal", r.signals, ("signal", "signalReference")),
                                   ("object", r.objects, ("object", "objectReference", "tunnel", "bridge"))):
            for tag in tags:
                for el in children(parent, tag):
                    refs.checked += 1
                    try:
                        s_el = float(el.get("s", "nan"))
                    except ValueError:
                        s_el = float("nan")
                    if not (-1e-6 <= s_el <= r.length + 1e-6):
                        refs.fail(f"road {r.id} {tag} {el.get('id')}: s=\"{el.get('s')}\" is not in [0, {r.length:.3f}]")
                        continue
                    for v in el.findall("validity"):
                        sec = r.sections[r.section_index(s_el)]
                        for att in ("fromLane", "toLane"):
                            refs.checked += 1
                            try:
                                ok = int(v.get(att)) in sec.lanes
                            except (TypeError, ValueError):
                                ok = False
                            if not ok:
                                refs.fail(f"road {r.id} {tag} {el.get('id')}: validity {att}=\"{v.get(att)}\" "
                                          f"is not a lane at s={s_el:.2f}")
        for sr in children(r.signals, "signalReference"):
            refs.checked += 1
            if sr.get("id") not in signal_ids:
                refs.fail(f"road {r.id}: signalReference to signal {sr.get('id')}, which does not exist")
        for sg in children(r.signals, "signal"):
            for dep in sg.findall("dependency"):
                refs.checked += 1
                if dep.get("id") not in signal_ids:
                    refs.fail(f"road {r.id} signal {sg.get('id')}: dependency on signal {dep.get('id')}, which does not exist")
            for ref in sg.findall("reference"):
                refs.checked += 1
                pool = signal_ids if ref.get("elementType") == "signal" else object_ids
                if ref.get("elementId") not in pool:
                    refs.fail(f"road {r.id} signal {sg.get('id')}: reference to {ref.get('elementType')} "
                              f"{ref.get('elementId')}, which does not exist")
            for pr in sg.findall("positionRoad"):
                refs.checked += 1
                if pr.get("roadId") not in roads:
                    refs.fail(f"road {r.id} signal {sg.get('id')}: positionRoad on road {pr.get('roadId')}, which does not exist")
        for orf in children(r.objects, "objectReference"):
            refs.checked += 1
            if orf.get("id") not in object_ids:
                refs.fail(f"road {r.id}: objectReference to object {orf.get('id')}, which does not exist")
    for cid, cel in net.controllers.items():
        for ctl in cel.findall("control"):
            refs.checked += 1
            if ctl.get("signalId") not in signal_ids:
                refs.fail(f"controller {cid}: control of signal {ctl.get('signalId')}, which does not exist")
    for jid, jel in net.junctions.items():
        for jc in jel.findall("controller"):
            refs.checked += 1
            if jc.get("id") not in net.controllers:
                refs.fail(f"junction {jid}: controller {jc.get('id')} does not exist")

    # -- gaps and kinks at the contacts
    def heading_out(road, end):
        """The direction of travel leaving road at end, and its reference point."""
        x, y, h, _ = road.ref(road.end_s(end))
        return (h if end == "end" else h + math.pi), x, y

    def compare_lanes(kind, label, ra, sa, seca, rb, sb, secb, pairs):
        pa, pb = ra.border_points(seca, sa), rb.border_points(secb, sb)
        for la, lb in sorted(pairs):
            if la not in pa or lb not in pb:
                continue
            gaps.checked += 1
            worst_d = worst_z = 0.0
            for qa, qb in zip(pa[la], pb[lb]):  # inner with inner, outer with outer
                worst_d = max(worst_d, math.hypot(qa[0] - qb[0], qa[1] - qb[1]))
                worst_z = max(worst_z, abs(qa[2] - qb[2]))
            at = f"{label}: road {ra.id} lane {la} <-> road {rb.id} lane {lb}"
            gaps.value(worst_d, at)
            if gaps.worst_dz is None or worst_z > gaps.worst_dz[0]:
                gaps.worst_dz = (worst_z, at)
            if worst_d > opt.max_gap or worst_z > opt.max_dz:
                gaps.fail(f"{at}: plan {worst_d:.4f} m, height {worst_z:.4f} m", kind)

    for c in contacts.values():
        a, ea, b, eb = c["a"], c["ea"], c["b"], c["eb"]
        ha, _, _ = heading_out(a, ea)
        hb, _, _ = heading_out(b, eb)
        # leaving a and entering b: entering b at its start travels hdg(b), at its end hdg(b)+pi,
        # which is the opposite of leaving b there.
        jump = abs(math.degrees(wrap_angle(ha - (hb + math.pi))))
        label = f"{c['label']} road {a.id} {ea} / road {b.id} {eb}"
        kinks.checked += 1
        kinks.value(jump, label)
        if jump > opt.max_kink_deg:
            kinks.fail(f"{label}: {jump:.3f} deg", c["kind"])
        compare_lanes(c["kind"], c["label"], a, a.end_s(ea), a.end_section(ea), b, b.end_s(eb), b.end_section(eb), c["pairs"])

    # lane section boundaries inside a road
    for r in roads.values():
        for k in range(len(r.sections) - 1):
            s0, s1 = r.sections[k], r.sections[k + 1]
            pairs = []
            for lane in s0.lanes.values():
                if lane.id == 0:
                    continue
                targets = lane.succ or [lane.id]  # an omitted successor continues the same id
                for t in targets:
                    if t in s1.lanes:
                        pairs.append((lane.id, t))
                    elif lane.succ:
                        refs.fail(f"road {r.id} laneSection {k} lane {lane.id}: successor {t} is not in the next laneSection")
            for lane in s1.lanes.values():  # predecessors named from the far side
                for t in lane.pred:
                    if t not in s0.lanes:
                        refs.fail(f"road {r.id} laneSection {k + 1} lane {lane.id}: predecessor {t} is not in the previous laneSection")
                    elif (t, lane.id) not in pairs:
                        pairs.append((t, lane.id))
            compare_lanes("laneSection", f"road {r.id} laneSection {k}->{k + 1}", r, s1.s, s0, r, s1.s, s1, pairs)

    # -- folds (and the margin of every border from its centre of curvature),
    # turn radii of the driving lanes on connecting roads
    for r in roads.values():
        connecting = r.junction != "-1"
        for k, sec in enumerate(r.sections):
            bad, tight = {}, {}
            samples = section_samples(r, sec, opt.fold_step)
            for s in samples:
                kappa = r.ref(s)[3]
                bd = r.borders(sec, s)
                for lid, (t_in, t_out) in bd.items():
                    v = 1.0 - kappa * t_out
                    folds.value(v, f"road {r.id} lane {lid} s={s:.2f}", worse=lambda a, b: a < b)
                    # distance of the border from the centre of curvature (signed: < 0 past it)
                    margin = v / abs(kappa) if abs(kappa) > 1e-12 else math.inf
                    if folds.worst_margin is None or margin < folds.worst_margin[0]:
                        folds.worst_margin = (margin, f"road {r.id} lane {lid} s={s:.2f}")
                    if (v <= 0.0 or margin < opt.fold_margin) and (lid not in bad or v < bad[lid][0]):
                        bad[lid] = (v, s, margin)
                    lane = sec.lanes.get(lid)
                    if not connecting or lane is None or lane.type not in DRIVING_TYPES or abs(kappa) <= 1e-12 \
                            or abs(t_out - t_in) < opt.taper_width:
                        continue
                    radius = abs(1.0 / kappa - 0.5 * (t_in + t_out))
                    turns.checked += 1
                    turns.value(radius, f"road {r.id} lane {lid} s={s:.2f}", worse=lambda a, b: a < b)
                    if radius < opt.min_turn_radius and (lid not in tight or radius < tight[lid][0]):
                        tight[lid] = (radius, s)
            folds.checked += len(samples)
            for lid, (v, s, margin) in sorted(bad.items()):
                folds.fail(f"road {r.id} laneSection {k} lane {lid}: 1-k*t={v:.3f}, {margin:.3f} m from the centre "
                           f"of curvature at s={s:.2f}", "road" if r.junction == "-1" else "connecting road")
            for lid, (radius, s) in sorted(tight.items()):
                turns.fail(f"road {r.id} laneSection {k} lane {lid}: lane-centre radius {radius:.3f} m at s={s:.2f}")

    # -- unlinked driving lanes
    for r in roads.values():
        for lane_sec_end in ("start", "end"):
            sec = r.end_section(lane_sec_end)
            link = r.link_at(lane_sec_end)
            for lane in sec.lanes.values():
                if lane.id == 0 or lane.type not in DRIVING_TYPES:
                    continue
                forward = (lane.id < 0) == (r.rule == "RHT")  # traffic toward +s
                if (lane_sec_end == "end") != forward:
                    continue  # traffic enters the road here
                unlinked.checked += 1
                if link is None:
                    continue  # a dead end
                s = r.end_s(lane_sec_end)
                w = abs(r.borders(sec, s)[lane.id][1] - r.borders(sec, s)[lane.id][0])
                if w < opt.taper_width:
                    continue
                where = f"road {r.id} lane {lane.id} at its {lane_sec_end}"
                if link["type"] == "road":
                    targets = lane.pred if lane_sec_end == "start" else lane.succ
                    if not targets:
                        unlinked.fail(f"{where}: no lane {'predecessor' if lane_sec_end == 'start' else 'successor'} "
                                      f"on road {link['id']}", "road link")
                elif link["type"] == "junction":
                    if link["id"] not in incoming_links.get((r.id, lane_sec_end, lane.id), set()):
                        unlinked.fail(f"{where}: no laneLink from it in junction {link['id']}", "junction")
        # lanes ending at a laneSection boundary inside the road
        for k in range(len(r.sections) - 1):
            s0, s1 = r.sections[k], r.sections[k + 1]
            for a, b, toward_plus in ((s0, s1, True), (s1, s0, False)):
                for lane in a.lanes.values():
                    if lane.id == 0 or lane.type not in DRIVING_TYPES:
                        continue
                    if ((lane.id < 0) == (r.rule == "RHT")) != toward_plus:
                        continue
                    unlinked.checked += 1
                    targets = (lane.succ if toward_plus else lane.pred) or [lane.id]
                    if any(t in b.lanes for t in targets):
                        continue
                    bd = r.borders(a, s1.s)[lane.id]
                    if abs(bd[1] - bd[0]) < opt.taper_width:
                        continue
                    unlinked.fail(f"road {r.id} laneSection {k if toward_plus else k + 1} lane {lane.id}: "
                                  f"no lane to continue into at s={s1.s:.2f}", "laneSection")

    # lanes leaving a junction: reached by a connecting road lane that traffic reaches
    def forward(road, lane_id):
        return (lane_id < 0) == (road.rule == "RHT")

    def wide(road, end, lane_id):
        sec = road.end_section(end)
        b = road.borders(sec, road.end_s(end)).get(lane_id)
        return b is not None and abs(b[1] - b[0]) >= opt.taper_width

    linked_into = {}  # (connecting road id, its end, lane id) -> fed by a laneLink
    for jid, jel in net.junctions.items():
        for con in jel.findall("connection"):
            cp = con.get("contactPoint")
            for ll in con.findall("laneLink"):
                try:
                    linked_into[(con.get("connectingRoad"), cp, int(ll.get("to")))] = True
                except (TypeError, ValueError):
                    pass
    reached = set()  # (road id, end, lane id) that a fed connecting lane reaches
    for c in roads.values():
        if c.junction == "-1":
            continue
        for lane in c.sections[0].lanes.values():
            if lane.id == 0 or lane.type not in DRIVING_TYPES:
                continue
            entry, exit_ = ("start", "end") if forward(c, lane.id) else ("end", "start")
            entry_sec, exit_sec = c.end_section(entry), c.end_section(exit_)
            if lane.id not in entry_sec.lanes or lane.id not in exit_sec.lanes:
                continue
            in_lane, out_lane = entry_sec.lanes[lane.id], exit_sec.lanes[lane.id]
            fed = bool(in_lane.pred if entry == "start" else in_lane.succ) or (c.id, entry, lane.id) in linked_into
            if not (fed and wide(c, entry, lane.id) and wide(c, exit_, lane.id)):
                continue
            link = c.link_at(exit_)
            if link is None or link["type"] != "road":
                continue
            for target in (out_lane.succ if exit_ == "end" else out_lane.pred):
                reached.add((link["id"], link["cp"], target))
    for r in roads.values():
        if r.junction != "-1":
            continue
        for end in ("start", "end"):
            link = r.link_at(end)
            if link is None or link["type"] != "junction":
                continue
            sec = r.end_section(end)
            for lane in sec.lanes.values():
                if lane.id == 0 or lane.type not in DRIVING_TYPES:
                    continue
                if (end == "start") != forward(r, lane.id):
                    continue  # traffic arrives at the junction here (checked above)
                if not wide(r, end, lane.id):
                    continue
                unlinked.checked += 1
                if (r.id, end, lane.id) not in reached:
                    unlinked.fail(f"road {r.id} lane {lane.id} at its {end}: no connecting road lane of junction "
                                  f"{link['id']} leads into it", "junction exit")

    check_signals(net, opt, signals)
    overlaps = check_overlaps(net, opt)
    return {c.name: c for c in (gaps, kinks, folds, turns, overlaps, unlinked, refs, planview, signals)}


def point_beyond_road(road, x, y, tol):
    """How far (x, y) lies before the start or beyond the end of the road's
    reference line, along the line's heading there (0 when it projects onto
    the line); the nearest reference-line sample decides which end."""
    n = max(8, int(math.ceil(road.length / 0.25)))
    best, best_s = None, 0.0
    for i in range(n + 1):
        s = road.length * i / n
        rx, ry, _, _ = road.ref(s)
        d = math.hypot(x - rx, y - ry)
        if best is None or d < best:
            best, best_s = d, s
    if 0.0 < best_s < road.length:
        return 0.0
    rx, ry, h, _ = road.ref(best_s)
    along = (x - rx) * math.cos(h) + (y - ry) * math.sin(h)
    beyond = along if best_s >= road.length else -along
    return max(0.0, beyond)


def check_signals(net, opt, check):
    roads = net.roads
    info = {}  # signal id -> (road, travel heading of the traffic it faces)
    for r in roads.values():
        for sg in children(r.signals, "signal"):
            sid = sg.get("id")
            check.checked += 1
            where = f"road {r.id} signal {sid}"
            key = (sg.get("country"), sg.get("type"))
            if key not in KNOWN_SIGNALS:
                check.fail(f"{where}: country=\"{key[0]}\" type=\"{key[1]}\" is not a code readers know", "code")
            for v in children(sg, "validity"):
                try:
                    a, b = int(v.get("fromLane")), int(v.get("toLane"))
                except (TypeError, ValueError):
                    check.fail(f"{where}: validity fromLane=\"{v.get('fromLane')}\" toLane=\"{v.get('toLane')}\" "
                               f"are not lane ids", "validity")
                    continue
                if a > b:
                    check.fail(f"{where}: validity fromLane={a} > toLane={b}", "validity")
            try:
                s = float(sg.get("s"))
            except (TypeError, ValueError):
                continue
            h = r.ref(min(max(s, 0.0), r.length))[2]
            if sg.get("orientation") == "-":
                h += math.pi
            info[sid] = (r.id, h)
    tol = opt.max_group_deg
    for cid, cel in net.controllers.items():
        ids = [c.get("signalId") for c in cel.findall("control") if c.get("signalId") in info]
        for i in range(len(ids)):
            for k in range(i + 1, len(ids)):
                (ra, ha), (rb, hb) = info[ids[i]], info[ids[k]]
                d = abs(math.degrees(wrap_angle(ha - hb)))
                if ra == rb and d <= tol:
                    continue  # one approach
                off = 180.0 - d  # from opposite travel directions
                check.value(off, f"controller {cid} signals {ids[i]}, {ids[k]}")
                check.checked += 1
                if off > tol:
                    check.fail(f"controller {cid}: signals {ids[i]} (road {ra}) and {ids[k]} (road {rb}) face "
                               f"traffic {d:.1f} deg apart, not opposite approaches", "controller")
    for r in roads.values():
        for ob in children(r.objects, "object"):
            if ob.get("type") != "crosswalk":
                continue
            check.checked += 1
            try:
                s, t = float(ob.get("s")), float(ob.get("t", "0"))
                hdg = float(ob.get("hdg", "0"))
            except (TypeError, ValueError):
                check.fail(f"road {r.id} crosswalk {ob.get('id')}: s/t/hdg are not numbers", "crosswalk")
                continue
            x0, y0, h0, _ = r.ref(min(max(s, 0.0), r.length))
            ox, oy = x0 - t * math.sin(h0), y0 + t * math.cos(h0)
            worst = 0.0
            for outline in children(ob.find("outlines"), "outline") + children(ob, "outline"):
                for c in outline:
                    try:
                        if c.tag == "cornerLocal":
                            u, v = float(c.get("u")), float(c.get("v"))
                            a = h0 + hdg
                            x, y = ox + u * math.cos(a) - v * math.sin(a), oy + u * math.sin(a) + v * math.cos(a)
                            worst = max(worst, point_beyond_road(r, x, y, opt.max_gap))
                        elif c.tag == "cornerRoad":
                            cs = float(c.get("s"))
                            worst = max(worst, -cs, cs - r.length)
                    except (TypeError, ValueError):
                        continue
            if not (-1e-9 <= s <= r.length + 1e-9):
                worst = max(worst, -s, s - r.length)
            if worst > opt.max_gap:
                check.fail(f"road {r.id} crosswalk {ob.get('id')}: outline lies {worst:.3f} m beyond the road's "
                           f"s-range", "crosswalk")


def count(net):
    roads = [r for r in net.roads.values() if r.junction == "-1"]
    conn = [r for r in net.roads.values() if r.junction != "-1"]

    def lanes_of(rs, kind):
        return sum(1 for r in rs for sec in r.sections for lane in sec.lanes.values() if lane.type == kind)
    sig_dyn = sig_static = 0
    objects = {}
    for r in net.roads.values():
        for sg in children(r.signals, "signal"):
            if sg.get("dynamic") == "yes":
                sig_dyn += 1
            else:
                sig_static += 1
        for ob in children(r.objects, "object"):
            t = ob.get("type", "none")
            objects[t] = objects.get(t, 0) + 1
    return {
        "roads": len(roads),
        "connecting_roads": len(conn),
        "junctions": len(net.junctions),
        "driving_lanes": lanes_of(roads, "driving"),
        "connecting_driving_lanes": lanes_of(conn, "driving"),
        "sidewalk_lanes": lanes_of(roads, "sidewalk"),
        "lane_sections": sum(len(r.sections) for r in net.roads.values()),
        "geometries": {k: sum(1 for r in net.roads.values() for g in r.geoms if g.kind == k)
                       for k in ("line", "arc", "spiral", "poly3", "paramPoly3")},
        "signals": sig_dyn + sig_static,
        "signals_dynamic": sig_dyn,
        "signals_static": sig_static,
        "controllers": len(net.controllers),
        "objects": sum(objects.values()),
        "objects_by_type": dict(sorted(objects.items())),
        "length_m": round(sum(r.length for r in roads), 3),
    }


def schema_errors(path, xsd):
    """Validity errors xmllint reports against the schema at xsd."""
    try:
        p = subprocess.run(["xmllint", "--noout", "--schema", xsd, path], capture_output=True, text=True)
    except FileNotFoundError:
        raise InputError("xmllint is not installed (Debian package libxml2-utils); it is needed for --xsd")
    lines = [ln for ln in p.stderr.splitlines() if "validity error" in ln or "parser error" in ln]
    if p.returncode not in (0, 3, 4) or (p.returncode != 0 and not lines):
        raise InputError(f"xmllint could not validate against {xsd}: {p.stderr.strip()[:500]}")
    return lines


def load(path):
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as e:
        raise InputError(f"{path} is not well-formed XML: {e}")
    except OSError as e:
        raise InputError(f"cannot read {path}: {e.strerror}")
    strip_namespaces(root)
    return Network(root)


def load_text(text):
    """The network of an OpenDRIVE document given as a string."""
    try:
        root = ET.fromstring(text)
    except ET.ParseError as e:
        raise InputError(f"not well-formed XML: {e}")
    strip_namespaces(root)
    return Network(root)


def run(path, opt):
    net = load(path)
    checks = check_network(net, opt)
    result = {"file": os.path.basename(path), "header": net.header, "counts": count(net),
              "checks": {k: c.as_json() for k, c in checks.items()}}
    g = checks["gaps"]
    result["checks"]["gaps"]["worst_height"] = g.worst_dz[0] if g.worst_dz else None
    result["checks"]["gaps"]["worst_height_at"] = g.worst_dz[1] if g.worst_dz else None
    f = checks["folds"]
    finite = f.worst_margin is not None and math.isfinite(f.worst_margin[0])
    result["checks"]["folds"]["worst_margin_m"] = f.worst_margin[0] if finite else None
    result["checks"]["folds"]["worst_margin_at"] = f.worst_margin[1] if finite else None
    result["checks"]["overlaps"]["overlap_area_m2"] = checks["overlaps"].total_area
    result["checks"]["overlaps"]["surface_pairs"] = checks["overlaps"].surface_pairs
    if opt.xsd:
        errs = schema_errors(path, opt.xsd)
        result["checks"]["schema"] = {"failures": len(errs), "checked": 1, "offenders": errs[:opt.max_list],
                                      "pass": not errs, "xsd": os.path.basename(opt.xsd)}
    if opt.overlap_report_only:
        result["checks"]["overlaps"]["pass"] = True
        result["checks"]["overlaps"]["report_only"] = True
    result["pass"] = all(c["pass"] for c in result["checks"].values())
    return result


def summary(res):
    c = res["counts"]
    out = [f"{res['file']}: {c['roads']} roads, {c['connecting_roads']} connecting roads, {c['junctions']} junctions, "
           f"{c['driving_lanes']} driving lanes (+{c['connecting_driving_lanes']} in junctions), "
           f"{c['sidewalk_lanes']} sidewalk lanes, {c['signals']} signals ({c['signals_dynamic']} dynamic), "
           f"{c['controllers']} controllers, {c['objects']} objects {c['objects_by_type']}"]
    for name, ch in res["checks"].items():
        state = "ok  " if ch["pass"] else "FAIL"
        if ch.get("report_only") and ch["failures"]:
            state = "note"
        extra = ""
        if name == "gaps":
            extra = (f", worst plan {ch['worst'] or 0:.4f} m (limit {ch['limit']['plan_m']}), "
                     f"worst height {ch['worst_height'] or 0:.4f} m (limit {ch['limit']['height_m']})")
        elif name == "kinks":
            extra = f", worst {ch['worst'] or 0:.3f} deg (limit {ch['limit']})"
        elif name == "folds":
            margin = "none curved" if ch["worst_margin_m"] is None else f"{ch['worst_margin_m']:.3f} m"
            extra = (f", smallest 1-k*t {ch['worst'] if ch['worst'] is not None else 1:.4f} (must stay > 0), "
                     f"closest border to its centre of curvature {margin} (limit {ch['limit']['margin_m']} m)")
        elif name == "turn_radius":
            worst = "none curved" if ch["worst"] is None else f"{ch['worst']:.3f} m"
            extra = f", smallest lane-centre radius on connecting roads {worst} (limit {ch['limit']} m)"
        elif name == "overlaps":
            extra = (f" road pairs, {ch['overlap_area_m2']:.3f} m^2 shared by driving lanes outside a common junction "
                     f"(limit {ch['limit']} m^2 a pair), largest {ch['worst'] or 0:.3f} m^2; "
                     f"{ch['surface_pairs']} pairs overlap counting sidewalks")
        elif name == "planview":
            extra = f", worst {ch['worst'] or 0:.5f} m (limit {ch['limit']})"
        if ch.get("failures_by_kind"):
            extra += "; by kind: " + ", ".join(f"{k} {v}" for k, v in sorted(ch["failures_by_kind"].items()))
        out.append(f"  {state} {name}: {ch['failures']} failures of {ch['checked']} checked{extra}")
        if ch.get("worst_at") and not ch["pass"]:
            out.append(f"         worst at {ch['worst_at']}")
        for o in ch["offenders"]:
            out.append(f"         {o}")
    out.append("PASS" if res["pass"] else "FAIL")
    return "\n".join(out)


def positive(name):
    def parse(v):
        try:
            x = float(v)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} must be a number, got '{v}'")
        if not (x > 0 and math.isfinite(x)):
            raise argparse.ArgumentTypeError(f"{name} must be > 0, got {v}")
        return x
    return parse


def options(argv=None):
    ap = argparse.ArgumentParser(description="Evaluate and check an ASAM OpenDRIVE 1.6 file.")
    ap.add_argument("file")
    ap.add_argument("--json", help="write counts and check results to this file")
    ap.add_argument("--xsd", help="also validate with xmllint against this schema (opendrive_16_core.xsd)")
    ap.add_argument("--max-gap", type=positive("--max-gap"), default=0.01, help="plan gap limit, m (0.01)")
    ap.add_argument("--max-dz", type=positive("--max-dz"), default=0.02, help="height step limit, m (0.02)")
    ap.add_argument("--max-kink-deg", type=positive("--max-kink-deg"), default=0.5,
                    help="heading jump limit, degrees (0.5)")
    ap.add_argument("--fold-step", type=positive("--fold-step"), default=0.25, help="fold sampling step, m (0.25)")
    ap.add_argument("--fold-margin", type=positive("--fold-margin"), default=0.3,
                    help="closest a lane border may come to its centre of curvature, m (0.3)")
    ap.add_argument("--min-turn-radius", type=positive("--min-turn-radius"), default=5.0,
                    help="smallest lane-centre radius of a driving lane on a connecting road, m (5.0: a car's "
                         "kerb-to-kerb turning radius)")
    ap.add_argument("--max-overlap", type=positive("--max-overlap"), default=0.01,
                    help="plan area two roads' driving lanes may share outside a common junction, m^2 (0.01)")
    ap.add_argument("--overlap-report-only", action="store_true",
                    help="report the overlaps check without letting it fail the file")
    ap.add_argument("--overlap-step", type=float, default=0.25,
                    help="sampling step of the lane polygons of the overlaps check, m (0.25; 0 skips the check)")
    ap.add_argument("--taper-width", type=positive("--taper-width"), default=0.01,
                    help="lanes narrower than this at an end need no successor, m (0.01)")
    ap.add_argument("--max-group-deg", type=positive("--max-group-deg"), default=30.0,
                    help="signals of one controller: travel directions within this of equal or opposite, deg (30)")
    ap.add_argument("--max-length-error", type=positive("--max-length-error"), default=0.001,
                    help="planView s / road length mismatch limit, m (0.001)")
    ap.add_argument("--max-list", type=int, default=20, help="offenders listed per check (20)")
    ap.add_argument("-q", "--quiet", action="store_true", help="print only the verdict")
    return ap.parse_args(argv)


def main(argv=None):
    opt = options(argv)
    try:
        res = run(opt.file, opt)
    except InputError as e:
        print(f"xodr_check: {e}", file=sys.stderr)
        return 2
    res["limits"] = {"max_gap_m": opt.max_gap, "max_dz_m": opt.max_dz, "max_kink_deg": opt.max_kink_deg,
                     "fold_step_m": opt.fold_step, "fold_margin_m": opt.fold_margin,
                     "min_turn_radius_m": opt.min_turn_radius, "max_overlap_m2": opt.max_overlap,
                     "overlap_step_m": opt.overlap_step, "taper_width_m": opt.taper_width,
                     "max_group_deg": opt.max_group_deg,
                     "max_length_error_m": opt.max_length_error}
    if opt.json:
        with open(opt.json, "w") as f:
            json.dump(res, f, indent=1, sort_keys=True)
    print(("PASS" if res["pass"] else "FAIL") if opt.quiet else summary(res))
    return 0 if res["pass"] else 1


if __name__ == "__main__":
    sys.exit(main())
