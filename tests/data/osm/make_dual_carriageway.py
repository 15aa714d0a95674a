#!/usr/bin/env python3
"""Writes dual_carriageway.osm: a boulevard mapped as OSM maps dual carriageways, two one-way
ways 10 m apart (closer than the default snap radius and minimum segment), for the tests that
each way stays a one-way road with its own lanes (citygen/streets.h planarize, osm_road_tags.h).

Layout (metres east / north of the centre; every crossing shares a node):
  y = 0      x -500 .. -300 and 300 .. 500: primary, two-way, lanes=4 (2 + 2)
  y = +5     x -300 .. 300 (splitting off at x = -300, joining at 300): primary, oneway=yes,
             lanes=2, turn:lanes=left|through, maxspeed=50 (drawn and driven west -> east)
  y = -5     the same span: primary, oneway=-1, lanes=3, maxspeed=40 (drawn west -> east,
             driven east -> west)
  x = -150, 150   residential, two-way, y -150 .. 150 across both carriageways
  x = 0      residential, y -150 .. -5 two-way; y 5 .. 150 oneway=-1 (drawn north, driven south)
Deterministic: python3 make_dual_carriageway.py > dual_carriageway.osm
"""
from osm_fixture import print_osm, way


CROSS = (-150, 0, 150)
way(1, [(-500, 0), (-300, 0)], [("highway", "primary"), ("lanes", "4")])
way(2, [(300, 0), (500, 0)], [("highway", "primary"), ("lanes", "4")])
way(3, [(-300, 0), (-250, 5)] + [(x, 5) for x in CROSS] + [(250, 5), (300, 0)],
    [("highway", "primary"), ("name", "Boulevard"), ("oneway", "yes"), ("lanes", "2"),
     ("turn:lanes", "left|through"), ("maxspeed", "50")])
way(4, [(-300, 0), (-250, -5)] + [(x, -5) for x in CROSS] + [(250, -5), (300, 0)],
    [("highway", "primary"), ("name", "Boulevard"), ("oneway", "-1"), ("lanes", "3"), ("maxspeed", "40")])
way(5, [(-150, -150), (-150, -5), (-150, 5), (-150, 150)], [("highway", "residential")])
way(6, [(150, -150), (150, -5), (150, 5), (150, 150)], [("highway", "residential")])
way(7, [(0, -150), (0, -5), (0, 5)], [("highway", "residential")])
way(8, [(0, 5), (0, 150)], [("highway", "residential"), ("oneway", "-1")])

print_osm("make_dual_carriageway.py")
