#!/usr/bin/env python3
"""Writes divided_highway.osm: a divided highway mapped as OSM maps it, two one-way ways whose
centre lines lie 6 m apart, closer than their two-lane carriageways are wide (2 x 3.33 m each at
the highway class's lane width), for the tests that the two halves get carriageways that share
no area and stay one-way roads with their lanes (citygen/side_by_side.h).

Layout (metres east / north of the centre; every crossing shares a node):
  y = +3     x -200 .. 200: trunk, oneway=-1, lanes=2 (drawn west -> east, driven east -> west:
             right-hand traffic)
  y = -3     x -200 .. 200: trunk, oneway=yes, lanes=2, maxspeed=80 (driven west -> east)
  x = -200, 0, 200   residential, two-way, y -150 .. 150 across both halves
Deterministic: python3 make_divided_highway.py > divided_highway.osm
"""
from osm_fixture import print_osm, way


way(1, [(-200, 3), (0, 3), (200, 3)],
    [("highway", "trunk"), ("name", "Avinguda"), ("oneway", "-1"), ("lanes", "2")])
way(2, [(-200, -3), (0, -3), (200, -3)],
    [("highway", "trunk"), ("name", "Avinguda"), ("oneway", "yes"), ("lanes", "2"), ("maxspeed", "80")])
for wid, x in ((3, -200), (4, 0), (5, 200)):
    way(wid, [(x, -150), (x, -3), (x, 3), (x, 150)], [("highway", "residential")])

print_osm("make_divided_highway.py")
