#!/usr/bin/env python3
"""Self-tests of xodr_check.py: its geometry evaluation against closed forms
and fine numeric references, one broken file per rule that fails exactly
that rule, and correct small networks (three roads joined by an arc road,
a three-arm junction) that pass every rule. The correct networks are also
validated against the OpenDRIVE 1.6 schema when it is available
(VISTA_OPENDRIVE_XSD or tests/data/opendrive-1.6/)."""
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import xodr_check as xc  # noqa: E402

CHECKS = ("gaps", "kinks", "folds", "turn_radius", "overlaps", "unlinked", "references", "planview", "signals")


# ---------------------------------------------------------------------------
# small OpenDRIVE builders

def doc(body, ns=False):
    root = '<OpenDRIVE xmlns="http://code.asam.net/simulation/standard/opendrive_schema">' if ns else "<OpenDRIVE>"
    return ('<?xml version="1.0" encoding="UTF-8"?>\n' + root +
            '\n <header revMajor="1" revMinor="6" name="test"/>\n' + body + "</OpenDRIVE>\n")


def geom(x, y, hdg, length, kind="<line/>", s=0.0):
    return f'<geometry s="{s!r}" x="{x!r}" y="{y!r}" hdg="{hdg!r}" length="{length!r}">{kind}</geometry>'


def lane(lid, width=3.5, kind="driving", pred=None, succ=None, widths=None):
    link = ""
    if pred is not None or succ is not None:
        link = "<link>" + ("" if pred is None else f'<predecessor id="{pred}"/>') + \
               ("" if succ is None else f'<successor id="{succ}"/>') + "</link>"
    ws = widths or [(0.0, width, 0.0, 0.0, 0.0)]
    wx = "".join(f'<width sOffset="{o!r}" a="{a!r}" b="{b!r}" c="{c!r}" d="{d!r}"/>' for o, a, b, c, d in ws)
    return f'<lane id="{lid}" type="{kind}" level="false">{link}{wx}</lane>'


def section(left=(), right=(), s=0.0):
    out = f'<laneSection s="{s!r}">'
    if left:
        out += "<left>" + "".join(left) + "</left>"
    out += '<center><lane id="0" type="none" level="false"/></center>'
    if right:
        out += "<right>" + "".join(right) + "</right>"
    return out + "</laneSection>"


def road(rid, length, geoms, sections, pred=None, succ=None, junction="-1", elevation=None,
         superelevation=None, offsets=None, rule="RHT", extra=""):
    """extra: <objects>/<signals> XML after <lanes>."""
    """pred/succ: ("road", id, contactPoint) or ("junction", id)."""
    def link(tag, l):
        if l is None:
            return ""
        if l[0] == "junction":
            return f'<{tag} elementType="junction" elementId="{l[1]}"/>'
        return f'<{tag} elementType="road" elementId="{l[1]}" contactPoint="{l[2]}"/>'
    out = f'<road name="r{rid}" length="{length!r}" id="{rid}" junction="{junction}" rule="{rule}">'
    if pred or succ:
        out += "<link>" + link("predecessor", pred) + link("successor", succ) + "</link>"
    out += "<planView>" + "".join(geoms) + "</planView>"
    if elevation:
        out += "<elevationProfile>" + "".join(
            f'<elevation s="{s!r}" a="{a!r}" b="{b!r}" c="{c!r}" d="{d!r}"/>' for s, a, b, c, d in elevation) + \
            "</elevationProfile>"
    if superelevation:
        out += "<lateralProfile>" + "".join(
            f'<superelevation s="{s!r}" a="{a!r}" b="{b!r}" c="{c!r}" d="{d!r}"/>'
            for s, a, b, c, d in superelevation) + "</lateralProfile>"
    out += "<lanes>" + "".join(f'<laneOffset s="{s!r}" a="{a!r}" b="{b!r}" c="{c!r}" d="{d!r}"/>'
                               for s, a, b, c, d in (offsets or []))
    out += "".join(sections) + "</lanes>" + extra + "</road>\n"
    return out


# Three roads: a 50 m line east, a quarter circle of radius 50 turning left,
# a 50 m line north; climbing 2 % throughout; one lane each way.
ARC_R = 50.0
ARC_L = 0.5 * math.pi * ARC_R


def arc_network(shift3=0.0, dz3=0.0, succ1=-1, succ2=-1, hdg3=0.0):
    z2 = 1.0 + 0.02 * ARC_L
    return doc(
        road(1, 50.0, [geom(0.0, 0.0, 0.0, 50.0)],
             [section([lane(1, pred=None, succ=1)], [lane(-1, succ=succ1)])],
             succ=("road", 2, "start"), elevation=[(0.0, 0.0, 0.02, 0.0, 0.0)]) +
        road(2, ARC_L, [geom(50.0, 0.0, 0.0, ARC_L, f'<arc curvature="{1 / ARC_R!r}"/>')],
             [section([lane(1, pred=1, succ=1)], [lane(-1, pred=-1, succ=succ2)])],
             pred=("road", 1, "end"), succ=("road", 3, "start"), elevation=[(0.0, 1.0, 0.02, 0.0, 0.0)]) +
        road(3, 50.0, [geom(100.0, 50.0 + shift3, 0.5 * math.pi + hdg3, 50.0)],
             [section([lane(1, pred=1)], [lane(-1, pred=-1)])],
             pred=("road", 2, "end"), elevation=[(0.0, z2 + dz3, 0.02, 0.0, 0.0)]))


SIGNALS = ('<objects><object id="o1" s="45.0" t="-4.0" zOffset="0" type="pole" height="3"/></objects>'
           '<signals><signal id="s1" s="49.0" t="-3.5" zOffset="2" dynamic="yes" orientation="+" country="OpenDRIVE" '
           'type="1000001" subtype="-1"><validity fromLane="-1" toLane="-1"/></signal>'
           '<signal id="s2" s="40.0" t="-3.5" zOffset="2" dynamic="no" orientation="+" country="DE" '
           'type="205" subtype="-1"/></signals>')


def t_junction(incoming_a="1", signals=SIGNALS, unfed=(), arm2="", arm3="", controls=""):
    """Arms 1 (west, ends at the junction), 2 (east) and 3 (south), both starting
    at it; six connecting roads (100..105) of one right lane each, 3 m lanes,
    turns of radius 10 m; arm 1 carries a traffic light (controlled by c1), a
    sign and a pole. unfed: connecting roads whose lane has neither a lane
    predecessor nor a laneLink; arm2/arm3: extra XML (<signals>) of arms 2
    and 3; controls: extra <control>s of c1."""
    w = 3.0
    arms = (
        road(1, 50.0, [geom(-60.0, 0.0, 0.0, 50.0)], [section([lane(1, w)], [lane(-1, w)])], succ=("junction", 9),
             extra=signals) +
        road(2, 50.0, [geom(10.0, 0.0, 0.0, 50.0)], [section([lane(1, w)], [lane(-1, w)])], pred=("junction", 9),
             extra=arm2) +
        road(3, 50.0, [geom(0.0, -10.0, -0.5 * math.pi, 50.0)], [section([lane(1, w)], [lane(-1, w)])],
             pred=("junction", 9), extra=arm3))
    quarter = 0.5 * math.pi * 10.0
    # (id, from road, its end, from lane, x, y, hdg, length, curvature, to road, its contact, to lane)
    conns = [
        (100, 1, "end", -1, -10.0, 0.0, 0.0, 20.0, 0.0, 2, "start", -1),
        (101, 2, "start", 1, 10.0, 0.0, math.pi, 20.0, 0.0, 1, "end", 1),
        (102, 1, "end", -1, -10.0, 0.0, 0.0, quarter, -0.1, 3, "start", -1),
        (103, 3, "start", 1, 0.0, -10.0, 0.5 * math.pi, quarter, 0.1, 1, "end", 1),
        (104, 2, "start", 1, 10.0, 0.0, math.pi, quarter, 0.1, 3, "start", -1),
        (105, 3, "start", 1, 0.0, -10.0, 0.5 * math.pi, quarter, -0.1, 2, "start", -1),
    ]
    body = ""
    junction = f'<controller id="c1"><control signalId="s1"/>{controls}</controller>\n<junction id="9" name="T">'
    for i, (rid, fr, fe, fl, x, y, h, length, k, to, te, tl) in enumerate(conns):
        kind = "<line/>" if k == 0 else f'<arc curvature="{k!r}"/>'
        body += road(rid, length, [geom(x, y, h, length, kind)],
                     [section(right=[lane(-1, w, pred=None if rid in unfed else fl, succ=tl)])],
                     pred=("road", fr, fe), succ=("road", to, te), junction="9")
        inc = incoming_a if rid == 100 else str(fr)
        link = "" if rid in unfed else f'<laneLink from="{fl}" to="-1"/>'
        junction += (f'<connection id="{i}" incomingRoad="{inc}" connectingRoad="{rid}" contactPoint="start">'
                     f'{link}</connection>')
    return doc(arms + body + junction + '<controller id="c1"/></junction>\n')


def check(text, **kw):
    opt = xc.options(["-"] + [f"--{k.replace('_', '-')}={v}" for k, v in kw.items()])
    return xc.check_network(xc.load_text(text), opt)


def failing(checks):
    return sorted(name for name, c in checks.items() if c.failures)


def xsd_path():
    env = os.environ.get("VISTA_OPENDRIVE_XSD")
    cands = [env] if env else []
    cands.append(os.path.join(HERE, "..", "data", "opendrive-1.6", "opendrive_16_core.xsd"))
    for c in cands:
        if c and os.path.isdir(c):
            c = os.path.join(c, "opendrive_16_core.xsd")
        if c and os.path.isfile(c):
            return c
    return None


# ---------------------------------------------------------------------------

class GeometryTest(unittest.TestCase):
    def one_road(self, kind, length=10.0, x=1.0, y=2.0, hdg=0.3):
        text = doc(road(1, length, [geom(x, y, hdg, length, kind)], [section(right=[lane(-1)])]))
        return xc.load_text(text).roads["1"]

    def test_arc_end_point_is_the_chord_of_the_circle(self):
        k, L, h = 0.05, 10.0, 0.3
        x, y, hh, kk = self.one_road(f'<arc curvature="{k}"/>', L).ref(L)
        chord = 2.0 / k * math.sin(0.5 * k * L)
        self.assertAlmostEqual(x, 1.0 + chord * math.cos(h + 0.5 * k * L), places=10)
        self.assertAlmostEqual(y, 2.0 + chord * math.sin(h + 0.5 * k * L), places=10)
        self.assertAlmostEqual(hh, h + k * L, places=12)
        self.assertAlmostEqual(kk, k, places=12)

    def test_spiral_matches_a_fine_numeric_integration(self):
        k0, k1, L, h = -0.02, 0.15, 60.0, 0.3
        r = self.one_road(f'<spiral curvStart="{k0}" curvEnd="{k1}"/>', L)
        n = 200000  # midpoint rule on the heading's cosine and sine
        for s_end in (17.3, L):
            ds = s_end / n
            u = v = 0.0
            for i in range(n):
                t = (i + 0.5) * ds
                a = h + k0 * t + 0.5 * (k1 - k0) / L * t * t
                u += math.cos(a) * ds
                v += math.sin(a) * ds
            x, y, hh, kk = r.ref(s_end)
            self.assertAlmostEqual(x, 1.0 + u, delta=1e-6)
            self.assertAlmostEqual(y, 2.0 + v, delta=1e-6)
            self.assertAlmostEqual(hh, h + k0 * s_end + 0.5 * (k1 - k0) / L * s_end ** 2, places=10)
            self.assertAlmostEqual(kk, k0 + (k1 - k0) * s_end / L, places=12)

    def test_poly3_of_a_slanted_line_runs_along_its_arc_length(self):
        r = self.one_road('<poly3 a="0" b="1" c="0" d="0"/>', 10.0, x=0.0, y=0.0, hdg=0.0)
        x, y, hh, kk = r.ref(5.0)
        self.assertAlmostEqual(x, 5.0 / math.sqrt(2), places=9)
        self.assertAlmostEqual(y, 5.0 / math.sqrt(2), places=9)
        self.assertAlmostEqual(hh, 0.25 * math.pi, places=12)
        self.assertAlmostEqual(kk, 0.0, places=12)

    def test_param_poly3_in_both_p_ranges(self):
        # u = p, v = 0.01 p^2 + 0.002 p^3 (arcLength) and the same curve with p in [0, 1].
        L, h = 10.0, 0.4
        arc = self.one_road('<paramPoly3 aU="0" bU="1" cU="0" dU="0" aV="0" bV="0" cV="0.01" dV="0.002" '
                            'pRange="arcLength"/>', L, hdg=h)
        nor = self.one_road('<paramPoly3 aU="0" bU="10" cU="0" dU="0" aV="0" bV="0" cV="1" dV="2" '
                            'pRange="normalized"/>', L, hdg=h)
        u, v = 5.0, 0.01 * 25 + 0.002 * 125
        dv, ddv = 0.02 * 5 + 0.006 * 25, 0.02 + 0.012 * 5
        for r in (arc, nor):
            x, y, hh, kk = r.ref(5.0)
            self.assertAlmostEqual(x, 1.0 + u * math.cos(h) - v * math.sin(h), places=10)
            self.assertAlmostEqual(y, 2.0 + u * math.sin(h) + v * math.cos(h), places=10)
            self.assertAlmostEqual(hh, h + math.atan(dv), places=10)
            self.assertAlmostEqual(kk, ddv / (1 + dv * dv) ** 1.5, places=10)

    def test_border_point_with_lane_offset_widths_sections_and_superelevation(self):
        h = math.pi / 6
        text = doc(road(
            1, 20.0, [geom(3.0, 4.0, h, 20.0)],
            [section(right=[lane(-1, widths=[(0.0, 3.0, 0.05, 0.0, 0.0)])]),
             section(right=[lane(-1, widths=[(0.0, 3.5, 0.0, 0.0, 0.0), (5.0, 3.2, -0.02, 0.001, 0.0)])], s=10.0)],
            elevation=[(0.0, 10.0, 0.02, 0.0, 0.0)], superelevation=[(0.0, 0.05, 0.001, 0.0, 0.0)],
            offsets=[(0.0, 0.5, 0.01, 0.0, 0.0)]))
        r = xc.load_text(text).roads["1"]
        s = 17.0
        sec = r.sections[r.section_index(s)]
        self.assertEqual(sec.s, 10.0)
        offset = 0.5 + 0.01 * s                          # laneOffset
        width = 3.2 - 0.02 * 2.0 + 0.001 * 4.0          # second record, ds = 17 - 10 - 5
        t = offset - width                               # outer border of lane -1
        z = 10.0 + 0.02 * s + t * math.tan(0.05 + 0.001 * s)
        inner, outer = r.border_points(sec, s)[-1]
        self.assertAlmostEqual(outer[0], 3.0 + s * math.cos(h) - t * math.sin(h), places=10)
        self.assertAlmostEqual(outer[1], 4.0 + s * math.sin(h) + t * math.cos(h), places=10)
        self.assertAlmostEqual(outer[2], z, places=10)
        self.assertAlmostEqual(inner[2], 10.0 + 0.02 * s + offset * math.tan(0.05 + 0.001 * s), places=10)
        # the first section's record at s = 4: width 3 + 0.05 * 4
        self.assertAlmostEqual(r.borders(r.sections[0], 4.0)[-1][1], 0.5 + 0.04 - 3.2, places=10)


class CorrectNetworksTest(unittest.TestCase):
    def test_three_roads_joined_by_an_arc_pass(self):
        c = check(arc_network())
        self.assertEqual(failing(c), [])
        self.assertEqual(c["gaps"].checked, 4)        # 2 links x 2 lane pairs
        self.assertEqual(c["kinks"].checked, 2)
        self.assertLess(c["gaps"].worst, 1e-9)
        self.assertLess(c["kinks"].worst, 1e-9)
        self.assertEqual(c["unlinked"].checked, 6)    # each road: lane -1 at its end, lane 1 at its start

    def test_three_arm_junction_passes(self):
        c = check(t_junction())
        self.assertEqual(failing(c), [])
        self.assertEqual(c["gaps"].checked, 12)       # 6 connecting roads x 2 ends
        self.assertEqual(c["kinks"].checked, 12)
        self.assertLess(c["gaps"].worst, 1e-9)
        self.assertLess(c["kinks"].worst, 1e-9)

    def test_namespaced_file_evaluates_the_same(self):
        c = check(arc_network().replace("<OpenDRIVE>", '<OpenDRIVE xmlns="http://code.asam.net/simulation/standard/opendrive_schema">'))
        self.assertEqual(failing(c), [])
        self.assertEqual(c["gaps"].checked, 4)

    def test_counts(self):
        net = xc.load_text(t_junction())
        n = xc.count(net)
        self.assertEqual((n["roads"], n["connecting_roads"], n["junctions"], n["driving_lanes"],
                          n["connecting_driving_lanes"]), (3, 6, 1, 6, 6))
        self.assertEqual(n["geometries"]["arc"], 4)
        self.assertEqual((n["signals"], n["signals_dynamic"], n["signals_static"], n["controllers"]), (2, 1, 1, 1))
        self.assertEqual(n["objects_by_type"], {"pole": 1})

    def test_correct_networks_are_schema_valid(self):
        xsd = xsd_path()
        if xsd is None:
            self.skipTest("OpenDRIVE 1.6 XSD not found (set VISTA_OPENDRIVE_XSD to opendrive_16_core.xsd)")
        if shutil.which("xmllint") is None:
            self.skipTest("xmllint not installed (Debian package libxml2-utils)")
        with tempfile.TemporaryDirectory() as d:
            for name, text in (("arc", arc_network()), ("junction", t_junction())):
                p = os.path.join(d, name + ".xodr")
                with open(p, "w") as f:
                    f.write(text)
                self.assertEqual(xc.schema_errors(p, xsd), [], name)


class BrokenFilesTest(unittest.TestCase):
    def test_kink(self):
        # two straight roads meeting at 1 degree; lanes of 0.4 m keep the borders within 1 cm
        kink = math.radians(1.0)
        text = doc(
            road(1, 20.0, [geom(0.0, 0.0, 0.0, 20.0)], [section(right=[lane(-1, 0.4, succ=-1)])],
                 succ=("road", 2, "start")) +
            road(2, 20.0, [geom(20.0, 0.0, kink, 20.0)], [section(right=[lane(-1, 0.4, pred=-1)])],
                 pred=("road", 1, "end")))
        c = check(text)
        self.assertEqual(failing(c), ["kinks"])
        self.assertAlmostEqual(c["kinks"].worst, 1.0, places=9)
        self.assertEqual(c["kinks"].failures, 1)
        # the same file passes with a limit above the kink
        self.assertEqual(failing(check(text, max_kink_deg=1.5)), [])

    def test_kink_at_a_reversed_contact(self):
        # road 2 runs backwards (its end meets road 1's end): heading + pi
        text = doc(
            road(1, 20.0, [geom(0.0, 0.0, 0.0, 20.0)], [section(right=[lane(-1, 0.4, succ=1)])],
                 succ=("road", 2, "end")) +
            road(2, 20.0, [geom(40.0, 0.0, math.pi, 20.0)], [section([lane(1, 0.4, succ=-1)])],
                 succ=("road", 1, "end")))
        self.assertEqual(failing(check(text)), [])
        bent = text.replace(f'hdg="{math.pi!r}"', f'hdg="{math.pi + 0.02!r}"').replace(
            'x="40.0" y="0.0"', f'x="{20 + 20 * math.cos(0.02)!r}" y="{20 * math.sin(0.02)!r}"')
        c = check(bent)
        self.assertEqual(failing(c), ["kinks"])
        self.assertAlmostEqual(c["kinks"].worst, math.degrees(0.02), places=6)

    def test_five_centimetre_gap(self):
        c = check(arc_network(shift3=0.05))
        self.assertEqual(failing(c), ["gaps"])
        self.assertAlmostEqual(c["gaps"].worst, 0.05, places=9)
        self.assertEqual(c["gaps"].failures, 2)  # both lanes of the road 2 / road 3 link

    def test_height_step(self):
        c = check(arc_network(dz3=0.03))
        self.assertEqual(failing(c), ["gaps"])
        self.assertEqual(c["gaps"].failures, 2)
        self.assertEqual(failing(check(arc_network(dz3=0.015))), [])

    def test_gap_across_lane_sections(self):
        text = doc(road(1, 20.0, [geom(0.0, 0.0, 0.0, 20.0)],
                        [section(right=[lane(-1, 3.5)]), section(right=[lane(-1, 3.45)], s=10.0)]))
        c = check(text)
        self.assertEqual(failing(c), ["gaps"])
        self.assertAlmostEqual(c["gaps"].worst, 0.05, places=9)

    def test_folding_inner_border_on_a_tight_arc(self):
        # radius 4 m turning left: the left lanes' outer border at t = 5.5 m passes the centre
        text = doc(road(1, 10.0, [geom(0.0, 0.0, 0.0, 10.0, '<arc curvature="0.25"/>')],
                        [section([lane(2, 2.0, "sidewalk"), lane(1, 3.5)], [lane(-1, 3.5)])]))
        c = check(text)
        self.assertEqual(failing(c), ["folds"])
        self.assertEqual(c["folds"].failures, 1)
        self.assertIn("lane 2", c["folds"].offenders[0])
        self.assertAlmostEqual(c["folds"].worst, 1 - 0.25 * 5.5, places=9)
        # a zero-width lane on the folding side counts too
        zero = text.replace('<lane id="2" type="sidewalk" level="false"><width sOffset="0.0" a="2.0"',
                            '<lane id="3" type="none" level="false"><width sOffset="0.0" a="0.0" b="0.0" c="0.0" d="0.0"/></lane>'
                            '<lane id="2" type="sidewalk" level="false"><width sOffset="0.0" a="2.0"')
        self.assertEqual(check(zero)["folds"].failures, 2)

    def test_driving_lane_without_successor(self):
        c = check(arc_network(succ1=None))
        self.assertEqual(failing(c), ["unlinked"])
        self.assertEqual(c["unlinked"].failures, 1)
        self.assertIn("road 1 lane -1", c["unlinked"].offenders[0])

    def test_driving_lane_without_lane_link_in_the_junction(self):
        # arm 3's lane 1 enters the junction through connecting roads 103 and 105: drop both laneLinks
        text = t_junction()
        for rid in (103, 105):
            text = text.replace(f'connectingRoad="{rid}" contactPoint="start"><laneLink from="1" to="-1"/>',
                                f'connectingRoad="{rid}" contactPoint="start">')
        c = check(text)
        self.assertEqual(failing(c), ["unlinked"])
        self.assertIn("road 3 lane 1", c["unlinked"].offenders[0])

    def test_junction_exit_lane_that_no_connecting_lane_feeds(self):
        # arm 3's lane -1 leaves the junction, fed by connecting roads 102 and 104: cut both from their incoming lanes
        c = check(t_junction(unfed=(102, 104)))
        self.assertEqual(failing(c), ["unlinked"])
        self.assertEqual(c["unlinked"].by_kind, {"junction exit": 1})
        self.assertIn("road 3 lane -1 at its start", c["unlinked"].offenders[0])
        # one of the two still fed: the lane is reached
        self.assertEqual(failing(check(t_junction(unfed=(102,)))), [])

    def test_tapering_lane_and_dead_end_need_no_successor(self):
        # lane -2 narrows from 3 m to 0 at the end; the road's start has no link
        taper = [(0.0, 3.0, -0.15, 0.0, 0.0)]
        text = doc(
            road(1, 20.0, [geom(0.0, 0.0, 0.0, 20.0)], [section([lane(1)], [lane(-1, succ=-1), lane(-2, widths=taper)])],
                 succ=("road", 2, "start")) +
            road(2, 20.0, [geom(20.0, 0.0, 0.0, 20.0)], [section([lane(1, pred=1)], [lane(-1, pred=-1)])],
                 pred=("road", 1, "end")))
        self.assertEqual(failing(check(text)), [])
        wide = text.replace('a="3.0" b="-0.15"', 'a="3.0" b="-0.1"')
        c = check(wide)
        self.assertEqual(failing(c), ["unlinked"])
        self.assertIn("road 1 lane -2", c["unlinked"].offenders[0])

    def test_lane_ending_between_lane_sections(self):
        # lane -2 ends where the second laneSection starts: a cubic taper to zero width is fine
        def road_with(widths):
            return doc(road(1, 40.0, [geom(0.0, 0.0, 0.0, 40.0)],
                            [section(right=[lane(-1), lane(-2, widths=widths)]),
                             section(right=[lane(-1)], s=20.0)]))
        # 3.5 m to 0 over 20 m with zero slope at both ends: 3.5 - 3*3.5/400 ds^2 + 2*3.5/8000 ds^3
        taper = [(0.0, 3.5, 0.0, -3 * 3.5 / 400, 2 * 3.5 / 8000)]
        c = check(road_with(taper))
        self.assertEqual(failing(c), [])
        self.assertEqual(c["gaps"].checked, 1)  # lane -1 across the boundary
        r = xc.load_text(road_with(taper)).roads["1"]
        self.assertAlmostEqual(r.borders(r.sections[0], 10.0)[-2][1], -3.5 - 1.75, places=9)
        c = check(road_with([(0.0, 3.5, 0.0, 0.0, 0.0)]))
        self.assertEqual(failing(c), ["unlinked"])
        self.assertEqual(c["unlinked"].by_kind, {"laneSection": 1})

    def test_left_hand_traffic_swaps_directions(self):
        # right lanes without successors: fine under LHT (they run toward -s), not under RHT
        def two(rule):
            return doc(
                road(1, 20.0, [geom(0.0, 0.0, 0.0, 20.0)], [section([lane(1, succ=1)], [lane(-1)])],
                     succ=("road", 2, "start"), rule=rule) +
                road(2, 20.0, [geom(20.0, 0.0, 0.0, 20.0)], [section([lane(1)], [lane(-1, pred=-1)])],
                     pred=("road", 1, "end"), rule=rule))
        self.assertEqual(failing(check(two("LHT"))), [])
        self.assertEqual(failing(check(two("RHT"))), ["unlinked"])

    def test_dangling_lane_reference(self):
        c = check(arc_network(succ2=-2))
        self.assertEqual(failing(c), ["references"])
        self.assertIn("lane -2", c["references"].offenders[0])

    def test_dangling_road_in_a_junction(self):
        c = check(t_junction(incoming_a="77"))
        self.assertEqual(failing(c), ["references"])
        self.assertTrue(all("77" in o for o in c["references"].offenders))

    def test_asymmetric_road_link(self):
        text = arc_network().replace('elementType="road" elementId="2" contactPoint="end"',
                                     'elementType="road" elementId="1" contactPoint="end"', 1)
        c = check(text)
        self.assertIn("references", failing(c))
        self.assertTrue(any("does not link back" in o for o in c["references"].offenders))

    def test_controller_of_a_missing_signal(self):
        text = t_junction().replace('<control signalId="s1"/>', '<control signalId="s9"/>')
        c = check(text)
        self.assertEqual(failing(c), ["references"])
        self.assertIn("signal s9", c["references"].offenders[0])


    def test_signal_off_its_road_and_validity_of_a_missing_lane(self):
        for bad, words in (('s="49.0"', 's="51.0"'), ('fromLane="-1"', 'fromLane="-4"')):
            c = check(t_junction().replace(*((bad, words))))
            self.assertEqual(failing(c), ["references"], words)
            self.assertIn("s1", c["references"].offenders[0])

    def test_signal_code_unknown_to_readers(self):
        # the generic traffic light exists under the OpenDRIVE country only
        c = check(t_junction().replace('country="OpenDRIVE"', 'country="DE"'))
        self.assertEqual(failing(c), ["signals"])
        self.assertEqual(c["signals"].by_kind, {"code": 1})
        self.assertIn("s1", c["signals"].offenders[0])

    def test_validity_from_lane_above_to_lane(self):
        c = check(t_junction().replace('<validity fromLane="-1" toLane="-1"/>', '<validity fromLane="1" toLane="-1"/>'))
        self.assertEqual(failing(c), ["signals"])
        self.assertEqual(c["signals"].by_kind, {"validity": 1})

    def test_controller_of_crossing_approaches(self):
        def light(sid, s):  # a light on an arm starting at the junction, facing the traffic toward it (-s)
            return (f'<signals><signal id="{sid}" s="{s}" t="3.5" zOffset="2" dynamic="yes" orientation="-" '
                    f'country="OpenDRIVE" type="1000001" subtype="-1"><validity fromLane="1" toLane="1"/></signal>'
                    f'</signals>')
        # arm 2 (east) is opposite arm 1 (west): one phase
        c = check(t_junction(arm2=light("s3", 1.0), controls='<control signalId="s3"/>'))
        self.assertEqual(failing(c), [])
        self.assertLess(c["signals"].worst, 1e-6)
        # arm 3 (south) crosses arm 1's traffic at 90 degrees: not one phase
        c = check(t_junction(arm3=light("s3", 1.0), controls='<control signalId="s3"/>'))
        self.assertEqual(failing(c), ["signals"])
        self.assertEqual(c["signals"].by_kind, {"controller": 1})
        self.assertAlmostEqual(c["signals"].worst, 90.0, places=6)

    def test_crosswalk_beyond_its_road_end(self):
        def crosswalk(u0, u1):  # at road 1's end (s = 50), 6 m wide
            corners = "".join(f'<cornerLocal u="{u}" v="{v}" z="0" height="0"/>'
                              for u, v in ((u0, -3.0), (u1, -3.0), (u1, 3.0), (u0, 3.0)))
            return (f'<objects><object id="o1" type="crosswalk" s="50.0" t="0" zOffset="0" hdg="0">'
                    f'<outlines><outline id="0" closed="true">{corners}</outline></outlines></object></objects>'
                    + SIGNALS.split("</objects>", 1)[1])
        self.assertEqual(failing(check(t_junction(signals=crosswalk(-3.0, -0.3)))), [])
        c = check(t_junction(signals=crosswalk(0.3, 3.0)))
        self.assertEqual(failing(c), ["signals"])
        self.assertEqual(c["signals"].by_kind, {"crosswalk": 1})
        self.assertIn("3.000 m beyond", c["signals"].offenders[0])

    def test_connecting_road_not_linked_to_its_incoming_road(self):
        text = t_junction().replace('<predecessor elementType="road" elementId="2" contactPoint="start"/>'
                                    '<successor elementType="road" elementId="1"',
                                    '<predecessor elementType="road" elementId="3" contactPoint="start"/>'
                                    '<successor elementType="road" elementId="1"')
        c = check(text)
        self.assertIn("references", failing(c))
        self.assertTrue(any("does not link to incomingRoad 2" in o for o in c["references"].offenders))


class TurnsAndOverlapsTest(unittest.TestCase):
    """The lane-centre radius on connecting roads, the margin of lane borders
    from their centre of curvature, and lane surfaces of different roads
    sharing area."""

    def test_clip_area_against_closed_forms(self):
        sq = [(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0)]
        moved = [(x + 1.0, y + 0.5) for x, y in sq]
        self.assertAlmostEqual(xc.clip_area(sq, moved), 1.0 * 1.5, places=12)
        diamond = [(1.0, -1.0), (3.0, 1.0), (1.0, 3.0), (-1.0, 1.0)]  # square of side 2*sqrt(2) around (1, 1)
        self.assertAlmostEqual(xc.clip_area(sq, diamond), 4.0, places=12)  # the square is inscribed
        tri = [(0.0, 0.0), (3.0, 0.0), (0.0, 3.0)]
        self.assertAlmostEqual(xc.clip_area(tri, sq), 4.0 - 0.5, places=12)  # x + y <= 3 cuts the corner (2, 2)
        self.assertEqual(xc.clip_area(sq, [(2.0, 0.0), (4.0, 0.0), (4.0, 2.0), (2.0, 2.0)]), 0.0)  # touching
        self.assertEqual(xc.clip_area(sq, [(5.0, 5.0), (6.0, 5.0), (6.0, 6.0)]), 0.0)

    def test_tight_connecting_road_fails_the_turn_radius(self):
        # the 3-arm junction with the right turn 102 on a 4 m arc: lane -1's centre (t = -1.5) runs at 2.5 m
        self.assertEqual(check(t_junction())["turn_radius"].failures, 0)
        self.assertAlmostEqual(check(t_junction())["turn_radius"].worst, 10.0 - 1.5, places=9)
        text = t_junction().replace('<arc curvature="-0.1"/>', '<arc curvature="-0.25"/>', 1)
        c = check(text)
        self.assertEqual(c["turn_radius"].failures, 1)
        self.assertIn("road 102 laneSection 0 lane -1", c["turn_radius"].offenders[0])
        self.assertAlmostEqual(c["turn_radius"].worst, 4.0 - 1.5, places=9)
        self.assertEqual(check(text, min_turn_radius=2.4)["turn_radius"].failures, 0)

    def test_border_closer_than_the_margin_to_its_centre_of_curvature(self):
        # radius 4 m turning left, lanes 1 and 2 of 1.9 m: lane 2's border 0.2 m from the centre
        text = doc(road(1, 10.0, [geom(0.0, 0.0, 0.0, 10.0, '<arc curvature="0.25"/>')],
                        [section([lane(2, 1.9), lane(1, 1.9)], [lane(-1, 3.5)])]))
        c = check(text)
        self.assertEqual(failing(c), ["folds"])
        self.assertIn("lane 2", c["folds"].offenders[0])
        self.assertIn("0.200 m from the centre", c["folds"].offenders[0])
        self.assertEqual(failing(check(text, fold_margin=0.1)), [])

    def crossing(self, dx=0.0, junction2="-1"):
        """Road 1 east along y = 0, road 2 north along x = 10 + dx; one 3 m lane each side."""
        return doc(road(1, 20.0, [geom(0.0, 0.0, 0.0, 20.0)], [section([lane(1, 3.0)], [lane(-1, 3.0)])]) +
                   road(2, 20.0, [geom(10.0 + dx, -10.0, 0.5 * math.pi, 20.0)],
                        [section([lane(1, 3.0)], [lane(-1, 3.0)])], junction=junction2) +
                   ("" if junction2 == "-1" else f'<junction id="{junction2}" name="j"/>'))

    def test_crossing_roads_overlap_by_their_square(self):
        c = check(self.crossing())
        self.assertEqual(failing(c), ["overlaps"])
        self.assertEqual(c["overlaps"].failures, 1)
        self.assertAlmostEqual(c["overlaps"].worst, 6.0 * 6.0, places=6)
        self.assertEqual(c["overlaps"].by_kind, {"street roads": 1})
        self.assertEqual(check(self.crossing(junction2="9"))["overlaps"].by_kind, {"street road / connecting road": 1})
        # 2.5 m of road 2's width over road 1's end: 2.5 x 6 m^2
        self.assertAlmostEqual(check(self.crossing(dx=10.5))["overlaps"].worst, 2.5 * 6.0, places=6)
        # touching ends share no area
        self.assertEqual(failing(check(self.crossing(dx=13.0))), [])
        self.assertEqual(check(self.crossing(), overlap_step=0)["overlaps"].checked, 0)

    def test_overlaps_reported_only_on_request(self):
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "cross.xodr")
            with open(path, "w") as f:
                f.write(self.crossing())
            res = xc.run(path, xc.options([path]))
            self.assertFalse(res["pass"])
            res = xc.run(path, xc.options([path, "--overlap-report-only"]))
            self.assertTrue(res["pass"])
            self.assertEqual(res["checks"]["overlaps"]["failures"], 1)
            self.assertIn("note overlaps", xc.summary(res))

    def test_connecting_roads_overlap_inside_their_junction_only(self):
        self.assertEqual(check(t_junction())["overlaps"].failures, 0)
        # connecting road 100 moved into a junction of its own: it crosses 102..105 of junction 9
        text = t_junction().replace('<road name="r100" length="20.0" id="100" junction="9"',
                                    '<road name="r100" length="20.0" id="100" junction="8"')
        text = text.replace('<connection id="0" incomingRoad="1" connectingRoad="100" contactPoint="start">'
                            '<laneLink from="-1" to="-1"/></connection>', "")
        text = text.replace('<controller id="c1"><control', '<junction id="8" name="other"/><controller id="c1"><control')
        c = check(text)
        self.assertIn("overlaps", failing(c))
        self.assertEqual(set(c["overlaps"].by_kind), {"connecting roads of different junctions"})


class GeometryJoinsTest(unittest.TestCase):
    """A road of line + arc + line (a rounded corner) as one reference line."""
    R, L1 = 20.0, 30.0

    def corner(self, arc_hdg=0.0, arc_dx=0.0, line2_s=None, length=None):
        R, L1 = self.R, self.L1
        La = 0.5 * math.pi * R
        g = [geom(0.0, 0.0, 0.0, L1),
             geom(L1 + arc_dx, 0.0, arc_hdg, La, f'<arc curvature="{1 / R!r}"/>', s=L1),
             geom(L1 + R, R, 0.5 * math.pi, 25.0, s=L1 + La if line2_s is None else line2_s)]
        total = L1 + La + 25.0 if length is None else length
        return doc(road(1, total, g, [section([lane(1)], [lane(-1)])]))

    def test_rounded_corner_passes(self):
        c = check(self.corner())
        self.assertEqual(failing(c), [])
        self.assertEqual(c["kinks"].checked, 2)
        r = xc.load_text(self.corner()).roads["1"]
        x, y, h, k = r.ref(self.L1 + 0.5 * math.pi * self.R + 10.0)
        self.assertAlmostEqual(x, self.L1 + self.R, places=9)
        self.assertAlmostEqual(y, self.R + 10.0, places=9)
        self.assertAlmostEqual(h, 0.5 * math.pi, places=12)

    def test_heading_jump_between_geometries(self):
        # the arc turned by 1 degree: its start and its end meet the lines at 1 degree
        c = check(self.corner(arc_hdg=math.radians(1.0)))
        self.assertIn("kinks", failing(c))
        self.assertEqual(c["kinks"].by_kind, {"geometry": 2})
        self.assertAlmostEqual(c["kinks"].worst, 1.0, places=9)

    def test_position_jump_between_geometries(self):
        c = check(self.corner(arc_dx=0.05))
        self.assertEqual(failing(c), ["gaps"])
        self.assertEqual(c["gaps"].by_kind, {"geometry": 2})

    def test_planview_lengths(self):
        self.assertEqual(failing(check(self.corner(length=80.0))), ["planview"])
        c = check(self.corner(line2_s=self.L1 + 0.5 * math.pi * self.R + 0.1))
        self.assertIn("planview", failing(c))


class CommandLineTest(unittest.TestCase):
    def run_tool(self, text, *args):
        with tempfile.TemporaryDirectory() as d:
            p = os.path.join(d, "in.xodr")
            with open(p, "w") as f:
                f.write(text)
            out = os.path.join(d, "out.json")
            r = subprocess.run([sys.executable, os.path.join(HERE, "xodr_check.py"), p, "--json", out, *args],
                               capture_output=True, text=True)
            data = None
            if os.path.exists(out):
                with open(out) as f:
                    data = json.load(f)
            return r, data

    def test_exit_codes_and_json(self):
        r, data = self.run_tool(t_junction())
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertTrue(data["pass"])
        self.assertEqual(data["counts"]["junctions"], 1)
        self.assertEqual(set(data["checks"]), set(CHECKS))
        r, data = self.run_tool(arc_network(shift3=0.05))
        self.assertEqual(r.returncode, 1)
        self.assertFalse(data["checks"]["gaps"]["pass"])
        self.assertAlmostEqual(data["checks"]["gaps"]["worst"], 0.05, places=6)
        self.assertIn("FAIL", r.stdout)

    def test_invalid_input_exits_2_without_output(self):
        for text, words in (("<OpenDRIVE><header", "well-formed"),
                            ("<Other/>", "root element"),
                            (doc(road(1, 10.0, [geom(0, 0, 0, 10, "<arc/>")], [section(right=[lane(-1)])])),
                             "curvature")):
            r, data = self.run_tool(text)
            self.assertEqual(r.returncode, 2)
            self.assertIn(words, r.stderr)
            self.assertIsNone(data)
        r, _ = self.run_tool(t_junction(), "--max-gap", "-1")
        self.assertEqual(r.returncode, 2)
        self.assertIn("--max-gap", r.stderr)


if __name__ == "__main__":
    unittest.main()
