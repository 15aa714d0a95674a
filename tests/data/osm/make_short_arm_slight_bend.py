#!/usr/bin/env python3
"""Writes short_arm_slight_bend.osm: a crossing of two secondary streets (13 m carriageways)
whose north arm is two ways meeting end to end 18 m from the crossing, the second turning 3
degrees east, for the tests that such a node is dropped (citygen/short_bends.h): the arm is one
straight road from the crossing, no transition 18 m from it that the junction's footprint would
reach over.

Layout (metres east / north of the centre):
  y = 0      x -100 .. 100: secondary (one way through the crossing at the origin)
  x = 0      y -100 .. 0: secondary
  north arm  (0, 0) .. (0, 18): secondary; (0, 18) .. 100 m on at 3 degrees east of north:
             secondary, another way
Deterministic: python3 make_short_arm_slight_bend.py > short_arm_slight_bend.osm
"""
import math

from osm_fixture import print_osm, way


bend = math.radians(3.0)
far = (round(100 * math.sin(bend), 3), round(18 + 100 * math.cos(bend), 3))
way(1, [(-100, 0), (0, 0), (100, 0)], [("highway", "secondary"), ("name", "Carrer Major")])
way(2, [(0, -100), (0, 0)], [("highway", "secondary"), ("name", "Carrer Sud")])
way(3, [(0, 0), (0, 18)], [("highway", "secondary"), ("name", "Carrer Nord")])
way(4, [(0, 18), far], [("highway", "secondary"), ("name", "Carrer Nord"), ("surface", "asphalt")])

print_osm("make_short_arm_slight_bend.py")
