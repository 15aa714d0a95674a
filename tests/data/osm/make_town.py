#!/usr/bin/env python3
"""Writes town.osm: a synthetic, partly mapped OSM extract for measuring the building import
(docs/reference/buildings.md "Buildings from OSM"). A 7 x 7 grid of streets 120 m apart; 30 of the 36
blocks carry buildings (rows of rectangles along the block sides, a courtyard multipolygon in
every sixth mapped block), the other 6 are unmapped (procedural lots stay there). Tags mix
height, building:levels, none, roof:shape; a few footprints are broken on purpose (bow-ties,
unclosed ways, duplicate nodes, missing nodes, slivers). Deterministic: python3 make_town.py > town.osm
"""
import math
import random

rng = random.Random(13)
LAT0, LON0 = 48.2100000, 16.3600000
M_LAT = 1.0 / 111132.0
M_LON = 1.0 / (111320.0 * math.cos(math.radians(LAT0)))
SPACING, LINES = 120.0, 7

nodes, ways, rels = [], [], []
next_node, next_way = [1], [1000]


def node(x, y):
    i = next_node[0]
    next_node[0] += 1
    nodes.append('  <node id="%d" lat="%.7f" lon="%.7f"/>' % (i, LAT0 + y * M_LAT, LON0 + x * M_LON))
    return i


def way(refs, tags, wid=None):
    if wid is None:
        wid = next_way[0]
        next_way[0] += 1
    nd = "".join('<nd ref="%d"/>' % r for r in refs)
    tg = "".join('<tag k="%s" v="%s"/>' % kv for kv in tags)
    ways.append('  <way id="%d">%s%s</way>' % (wid, nd, tg))
    return wid


def tags_for():
    t = [("building", rng.choice(["yes", "residential", "apartments", "retail", "house"]))]
    r = rng.random()
    if r < 0.4:
        t.append(("height", rng.choice(["%d" % rng.randint(6, 30), "%.1f m" % rng.uniform(6, 30), "%d'" % rng.randint(20, 90)])))
    elif r < 0.7:
        t.append(("building:levels", "%d" % rng.randint(1, 8)))
    if rng.random() < 0.2:
        t.append(("roof:shape", rng.choice(["gabled", "hipped", "flat", "skillion", "dome"])))
    return t


def building(corners):
    """corners: list of (x, y), counter-clockwise; some come out broken on purpose."""
    r = rng.random()
    refs = [node(x, y) for x, y in corners]
    t = tags_for()
    if r < 0.02:  # bow-tie: swap two corners
        refs[1], refs[2] = refs[2], refs[1]
        way(refs + [refs[0]], t)
    elif r < 0.04:  # unclosed
        way(refs, t)
    elif r < 0.07:  # duplicate consecutive node
        way(refs[:2] + [refs[1]] + refs[2:] + [refs[0]], t)
    elif r < 0.08:  # a node missing from the extract
        way(refs[:2] + [900000000 + next_way[0]] + refs[3:] + [refs[0]], t)
    else:
        way(refs + [refs[0]], t)


def rect(x0, y0, x1, y1):
    return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]


half = SPACING * (LINES - 1) / 2.0
# Streets: the grid lines, one way each, sharing nodes at the crossings.
grid = {}
for i in range(LINES):
    for j in range(LINES):
        grid[i, j] = node(-half + i * SPACING, -half + j * SPACING)
for i in range(LINES):
    cls = "secondary" if i == LINES // 2 else "residential"
    way([grid[i, j] for j in range(LINES)], [("highway", cls)])
    way([grid[j, i] for j in range(LINES)], [("highway", cls)])

mapped = 0
for bi in range(LINES - 1):
    for bj in range(LINES - 1):
        if (bi + 2 * bj) % 6 == 0:
            continue  # unmapped block
        mapped += 1
        x0, y0 = -half + bi * SPACING + 11.0, -half + bj * SPACING + 11.0
        x1, y1 = x0 + SPACING - 22.0, y0 + SPACING - 22.0
        if mapped % 6 == 0:  # one courtyard building filling the block
            o = [node(x, y) for x, y in rect(x0 + 2, y0 + 2, x1 - 2, y1 - 2)]
            n = [node(x, y) for x, y in rect(x0 + 25, y0 + 25, x1 - 25, y1 - 25)]
            wo, wi = way(o + [o[0]], []), way(n + [n[0]], [])
            rels.append('  <relation id="%d"><member type="way" ref="%d" role="outer"/><member type="way" ref="%d" role="inner"/>'
                        '<tag k="type" v="multipolygon"/><tag k="building" v="apartments"/><tag k="building:levels" v="%d"/></relation>'
                        % (5000 + mapped, wo, wi, rng.randint(4, 7)))
            continue
        # Rows along the south and north sides, then west and east (between them).
        depth = rng.uniform(10.0, 14.0)
        for side in range(4):
            pos = (x0 if side < 2 else y0 + depth + 1.0)
            end = (x1 if side < 2 else y1 - depth - 1.0)
            while True:
                w = rng.uniform(12.0, 20.0)
                if pos + w > end:
                    break
                if rng.random() < 0.85:
                    if side == 0:
                        c = rect(pos, y0, pos + w, y0 + depth)
                    elif side == 1:
                        c = rect(pos, y1 - depth, pos + w, y1)
                    elif side == 2:
                        c = rect(x0, pos, x0 + depth, pos + w)
                    else:
                        c = rect(x1 - depth, pos, x1, pos + w)
                    building(c)
                pos += w + rng.uniform(0.0, 3.0)
        if rng.random() < 0.3:  # a sliver (too small)
            cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
            building(rect(cx, cy, cx + 1.0, cy + 1.2))

print('<?xml version="1.0" encoding="UTF-8"?>')
print("<!-- Generated by tests/data/osm/make_town.py (synthetic; see its docstring). -->")
print('<osm version="0.6" generator="vista-test">')
print("\n".join(nodes))
print("\n".join(ways))
print("\n".join(rels))
print("</osm>")
