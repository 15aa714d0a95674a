#!/usr/bin/env python3
"""Checks the include order of vista's rooms (docs/reference/architecture.md).

Every source file belongs to one room (by its folder). A file may include
project headers only from its own room and the rooms below it, and some rooms
may not include OSG or OpenGL at all. The tests mirror the rooms: every folder
of tests/ that holds test_*.cpp files is named after a source room (tests/bake/gen
tests bake/gen/) or is one of the shared folders (TEST_FOLDERS), and no test
source or header is longer than MAX_TEST_LINES. Prints every violation and
exits 1 if there is one; exits 0 with a one-line summary otherwise.

Usage: check_rooms.py SOURCE_DIR
"""
import os
import re
import sys

# Bottom to top. A room may include itself and every room before it.
ROOMS = [
    ("foundation", "foundation/"),
    ("citygen", "citygen/"),
    ("scene", "runtime/scene/"),
    ("traffic", "runtime/traffic/"),  # SUMO runs, demand, floating-car data as plain arrays
    ("engine", "runtime/engine/"),
    ("gen", "bake/gen/"),         # generation-time passes of `vista gen`: lighting bake, paged city writer
    ("nodes", "nodes/"),          # node types, chunker, baked-file loading, plugin
    ("render", "nodes/render/"),  # offscreen renderer, render modes
    ("bake", "bake/"),
    ("cmd", "cmd/"),              # the vista executable: nothing includes it
]
# Headers of the scene room that expose OSG types (only OSG-side rooms include them).
OSG_SCENE_HEADERS = {"runtime/scene/scene_graph.h", "runtime/scene/scene_file.h", "runtime/scene/tree_impostor_graph.h"}
# Rooms that must not see OSG or GL at all (their headers and sources).
NO_OSG_ROOMS = {"foundation", "citygen", "traffic", "engine"}
# Rooms whose headers must not include OSG (their .cpp files may, privately).
NO_OSG_IN_HEADERS = {"scene", "gen"}
# The bake does not draw: it may use node types but not the render modes.
# Generation-time code is not part of the walkthrough: no runtime room above
# the engine uses it.
FORBIDDEN = {("bake", "render"), ("nodes", "gen"), ("render", "gen")}

# Folders of tests/ that are not rooms: shared helpers, fixtures, fuzzers,
# benchmarks, scripts, sanitizer suppressions.
TEST_FOLDERS = {"common", "data", "fuzz", "bench", "tools", "sanitizers"}
# A test file longer than this is split by concept (helpers go to a header beside it).
MAX_TEST_LINES = 650

SYSTEM_OSG = re.compile(r'#\s*include\s*<(osg\w*/|GL/|OpenThreads/)')
PROJECT = re.compile(r'#\s*include\s*"([^"]+)"')


def room_of(path):
    best = None
    for name, prefix in ROOMS:
        if path.startswith(prefix) and (best is None or len(prefix) > len(best[1])):
            best = (name, prefix)
    return best[0] if best else None


def check_tests(root):
    """Problems of tests/: folders not named after a room, files too long."""
    problems, files = [], 0
    tests = os.path.join(root, "tests")
    room_dirs = {prefix.rstrip("/") for _, prefix in ROOMS}
    for dirpath, _, names in os.walk(tests):
        rel_dir = os.path.relpath(dirpath, tests).replace(os.sep, "/")
        top = rel_dir.split("/")[0]
        if top == "data":
            continue
        if top not in TEST_FOLDERS and any(n.startswith("test_") and n.endswith(".cpp") for n in names):
            if rel_dir not in room_dirs or not os.path.isdir(os.path.join(root, rel_dir)):
                problems.append(f"tests/{rel_dir}: holds test_*.cpp but is not named after a source room "
                                f"({', '.join(sorted(room_dirs))}) nor one of {', '.join(sorted(TEST_FOLDERS))}")
        for n in names:
            if not n.endswith((".cpp", ".h")):
                continue
            files += 1
            with open(os.path.join(dirpath, n), encoding="utf-8", errors="replace") as f:
                lines = sum(1 for _ in f)
            if lines > MAX_TEST_LINES:
                problems.append(f"tests/{rel_dir}/{n}: {lines} lines, more than {MAX_TEST_LINES}: split it by concept")
    return problems, files


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else "."
    order = {name: i for i, (name, _) in enumerate(ROOMS)}
    problems, files = [], 0
    for dirpath, _, names in os.walk(root):
        rel_dir = os.path.relpath(dirpath, root)
        if rel_dir.startswith(("build", ".git", "tests", "docs", "data")):
            continue
        for n in names:
            if not n.endswith((".h", ".cpp")):
                continue
            rel = os.path.normpath(os.path.join(rel_dir, n)).replace(os.sep, "/")
            room = room_of(rel)
            if room is None:
                continue
            files += 1
            with open(os.path.join(root, rel), encoding="utf-8", errors="replace") as f:
                text = f.read()
            for m in PROJECT.finditer(text):
                inc = m.group(1)
                target = room_of(inc)
                if target is None:
                    continue
                if order[target] > order[room] or (room, target) in FORBIDDEN:
                    problems.append(f"{rel}: room '{room}' includes '{inc}' of room '{target}' above it")
                if inc in OSG_SCENE_HEADERS and room in NO_OSG_ROOMS:
                    problems.append(f"{rel}: room '{room}' must not see OSG but includes '{inc}'")
                if inc in OSG_SCENE_HEADERS and room == "scene" and rel.endswith(".h") and rel not in OSG_SCENE_HEADERS:
                    problems.append(f"{rel}: plain scene header includes the OSG-side '{inc}'")
            if SYSTEM_OSG.search(text):
                if room in NO_OSG_ROOMS:
                    problems.append(f"{rel}: room '{room}' must not include OSG/GL headers")
                if room in NO_OSG_IN_HEADERS and rel.endswith(".h") and rel not in OSG_SCENE_HEADERS:
                    problems.append(f"{rel}: header of room '{room}' includes OSG/GL")
    test_problems, test_files = check_tests(root)
    for p in problems + test_problems:
        print(p)
    if problems:
        print(f"{len(problems)} include-order violations in {files} files")
    if test_problems:
        print(f"{len(test_problems)} problems of the test layout in {test_files} files")
    if problems or test_problems:
        return 1
    print(f"rooms ok: {files} files, order " + " < ".join(n for n, _ in ROOMS) +
          f"; tests mirror the rooms ({test_files} files, none over {MAX_TEST_LINES} lines)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
