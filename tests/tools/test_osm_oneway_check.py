#!/usr/bin/env python3
"""Self-tests of osm_oneway_check.py: its projection against Snyder's worked
example, its PBF reader against the XML reader on the same extract, and
hand-written OpenDRIVE roads on a hand-written OSM way: lanes along a one-way
way pass, lanes in both directions fail two_way, lanes only against the way
fail against, a two-way way and a road beside the way are not judged."""
import json
import os
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import osm_oneway_check as oc  # noqa: E402

DATA = os.path.join(HERE, "..", "data", "osm")
GEO = "+proj=tmerc +lat_0=48.2 +lon_0=16.36 +k_0=1 +x_0=1000 +y_0=2000 +ellps=WGS84 +units=m +no_defs"


def osm(oneway_tag):
    tag = "" if oneway_tag is None else f'<tag k="oneway" v="{oneway_tag}"/>'
    # A way running east from (48.2, 16.36) for about 74 m (0.001 degrees of longitude).
    return ('<?xml version="1.0"?>\n<osm version="0.6">\n'
            '<node id="1" lat="48.2" lon="16.36"/><node id="2" lat="48.2" lon="16.361"/>\n'
            f'<way id="7"><nd ref="1"/><nd ref="2"/><tag k="highway" v="residential"/>{tag}</way>\n'
            '<way id="8"><nd ref="1"/><nd ref="2"/><tag k="highway" v="footway"/><tag k="oneway" v="yes"/></way>\n'
            '</osm>\n')


def lane(lid):
    return (f'<lane id="{lid}" type="driving" level="false"><width sOffset="0" a="3.5" b="0" c="0" d="0"/>'
            '</lane>')


def xodr(left, right, x=1005.0, y=2000.0, hdg=0.0):
    """One 60 m road starting at (x, y) with the given driving lane ids on each side."""
    side = ""
    if left:
        side += "<left>" + "".join(lane(i) for i in left) + "</left>"
    side += '<center><lane id="0" type="none" level="false"/></center>'
    if right:
        side += "<right>" + "".join(lane(i) for i in right) + "</right>"
    return ('<?xml version="1.0" encoding="UTF-8"?>\n<OpenDRIVE>\n'
            f' <header revMajor="1" revMinor="6" name="t"><geoReference><![CDATA[{GEO}]]></geoReference></header>\n'
            f' <road name="r" length="60" id="1" junction="-1" rule="RHT"><link/><planView>'
            f'<geometry s="0" x="{x!r}" y="{y!r}" hdg="{hdg!r}" length="60"><line/></geometry></planView>'
            f'<lanes><laneSection s="0">{side}</laneSection></lanes></road>\n</OpenDRIVE>\n')


class Projection(unittest.TestCase):
    def test_snyder_worked_example(self):
        # Snyder (1987), p. 269: Clarke 1866, central meridian 75 W, k0 = 0.9996:
        # 40.5 N, 73.5 W -> x = 127,106.5 m, y = 4,484,124.4 m.
        tm = oc.TransverseMercator({"lat_0": 0, "lon_0": -75, "k_0": 0.9996, "x_0": 0, "y_0": 0},
                                   a=6378206.4, e2=0.00676866)
        x, y = tm.forward(40.5, -73.5)
        self.assertAlmostEqual(x, 127106.5, delta=0.1)
        self.assertAlmostEqual(y, 4484124.4, delta=0.1)

    def test_offsets_and_origin(self):
        tm = oc.TransverseMercator(oc.parse_proj(GEO))
        x, y = tm.forward(48.2, 16.36)
        self.assertAlmostEqual(x, 1000.0, places=6)
        self.assertAlmostEqual(y, 2000.0, places=6)

    def test_other_projection_refused(self):
        with self.assertRaises(oc.InputError):
            oc.parse_proj("+proj=utm +zone=33")


class Readers(unittest.TestCase):
    def test_pbf_reads_as_xml(self):
        nx, wx = oc.read_osm(os.path.join(DATA, "buildings.osm"))
        npb, wpb = oc.read_osm(os.path.join(DATA, "buildings.osm.pbf"))
        self.assertEqual(wx, wpb)
        self.assertEqual(set(nx), set(npb))
        for k in nx:
            self.assertAlmostEqual(nx[k][0], npb[k][0], places=7)
            self.assertAlmostEqual(nx[k][1], npb[k][1], places=7)

    def test_truncated_files_are_errors(self):
        with tempfile.TemporaryDirectory() as d:
            src = open(os.path.join(DATA, "buildings.osm.pbf"), "rb").read()
            p = os.path.join(d, "cut.osm.pbf")
            with open(p, "wb") as f:
                f.write(src[:len(src) // 2])
            with self.assertRaises(oc.InputError):
                oc.read_osm(p)
            with self.assertRaises(oc.InputError):
                oc.read_osm(os.path.join(DATA, "truncated.osm"))

    def test_oneway_values(self):
        self.assertEqual(oc.oneway_of({"oneway": "yes"}), 1)
        self.assertEqual(oc.oneway_of({"oneway": "-1"}), -1)
        self.assertEqual(oc.oneway_of({"highway": "motorway"}), 1)
        self.assertEqual(oc.oneway_of({"highway": "motorway", "oneway": "no"}), 0)
        self.assertEqual(oc.oneway_of({"junction": "roundabout"}), 1)
        self.assertEqual(oc.oneway_of({"oneway": "maybe"}), 0)


class Checks(unittest.TestCase):
    def run_case(self, oneway_tag, road):
        with tempfile.TemporaryDirectory() as d:
            po, px, pj = (os.path.join(d, n) for n in ("m.osm", "m.xodr", "r.json"))
            with open(po, "w") as f:
                f.write(osm(oneway_tag))
            with open(px, "w") as f:
                f.write(road)
            p = subprocess.run([sys.executable, os.path.join(HERE, "osm_oneway_check.py"), po, px, "--json", pj],
                               capture_output=True, text=True)
            res = json.load(open(pj))
        return p.returncode, res

    def test_lanes_along_the_way_pass(self):
        rc, res = self.run_case("yes", xodr([], [-1, -2]))
        self.assertEqual(rc, 0)
        self.assertEqual(res["counts"]["roads_on_oneway_ways"], 1)

    def test_both_directions_fail_two_way(self):
        rc, res = self.run_case("yes", xodr([1], [-1]))
        self.assertEqual(rc, 1)
        self.assertEqual(res["checks"]["two_way"]["failures"], 1)
        self.assertIn("way 7", res["checks"]["two_way"]["offenders"][0])

    def test_lanes_against_the_way_fail(self):
        rc, res = self.run_case("yes", xodr([1], []))
        self.assertEqual((rc, res["checks"]["against"]["failures"]), (1, 1))
        # The same lanes on a road drawn the other way round run along the way.
        rc, res = self.run_case("yes", xodr([1], [], x=1065.0, hdg=3.141592653589793))
        self.assertEqual(rc, 0)
        # oneway=-1: traffic runs against the way's nodes.
        rc, res = self.run_case("-1", xodr([], [-1]))
        self.assertEqual((rc, res["checks"]["against"]["failures"]), (1, 1))

    def test_two_way_way_and_distant_road_not_judged(self):
        rc, res = self.run_case(None, xodr([1], [-1]))
        self.assertEqual((rc, res["counts"]["roads_matched"], res["counts"]["roads_on_oneway_ways"]), (0, 1, 0))
        rc, res = self.run_case("yes", xodr([1], [-1], y=2005.0))
        self.assertEqual((rc, res["counts"]["roads_matched"]), (0, 0))


if __name__ == "__main__":
    unittest.main()
