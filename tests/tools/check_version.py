#!/usr/bin/env python3
"""Checks that every place that states vista's version states the same one.

The one source is the VERSION of project() in the top-level CMakeLists.txt.
Against it:

1. `vista --version` prints "vista VERSION";
2. CHANGELOG.md's newest version heading (## MAJOR.MINOR.PATCH — title) is
   VERSION, and the line under it is "Released YYYY-MM-DD." with a real date;
   the version headings go strictly down the page (newest first);
3. the build's CPack configuration (the .deb's Version) and the CMake package's
   vistaConfigVersion.cmake carry VERSION;
4. the Python module's vista.__version__ is VERSION (when --python-dir is given
   and holds the module);
5. every find_package(vista X.Y ...) in examples/ and docs/ asks for VERSION's
   major.minor (the CMake package accepts only its own minor version, so an
   older request fails to configure).

Prints every disagreement and exits 1 if there is one.

Usage: check_version.py --root SOURCE_DIR --vista VISTA --build BUILD_DIR [--python-dir DIR]
       check_version.py --self-test
  (--self-test plants each kind of disagreement in made-up inputs and fails
   unless the check reports it, then checks an agreeing set)
"""
import argparse
import datetime
import os
import re
import subprocess
import sys

SEMVER = r"(\d+)\.(\d+)\.(\d+)"
PROJECT_RE = re.compile(r"^\s*project\(\s*vista\b[^)]*\bVERSION\s+" + SEMVER + r"\b", re.MULTILINE)
HEADING_RE = re.compile(r"^##\s+(.*?)\s*$")
VERSION_HEADING_RE = re.compile(r"^" + SEMVER + r"(?:\s+—\s+\S.*)?$")
DATE_LINE_RE = re.compile(r"^Released (\d{4})-(\d{2})-(\d{2})\.$")


def cmake_version(cmakelists_text):
    """The version of project(vista VERSION x.y.z), or None."""
    m = PROJECT_RE.search(cmakelists_text)
    return ".".join(m.groups()) if m else None


def changelog_problems(text, version):
    """Disagreements of CHANGELOG.md's version headings with VERSION."""
    problems = []
    lines = text.split("\n")
    versions = []  # (line index, (major, minor, patch))
    for i, line in enumerate(lines):
        m = HEADING_RE.match(line)
        if not m or line.startswith("###"):
            continue
        title = m.group(1)
        if title == "Unreleased":
            continue
        v = VERSION_HEADING_RE.match(title)
        if not v:
            problems.append(f"CHANGELOG.md:{i + 1}: heading \"{title}\" is neither \"Unreleased\" "
                            "nor \"MAJOR.MINOR.PATCH — title\"")
            continue
        versions.append((i, tuple(int(x) for x in v.groups()[:3])))
    if not versions:
        return problems + ["CHANGELOG.md: no version heading (## MAJOR.MINOR.PATCH — title)"]
    first, newest = versions[0]
    if ".".join(map(str, newest)) != version:
        problems.append(f"CHANGELOG.md:{first + 1}: newest version heading is "
                        f"{'.'.join(map(str, newest))}, CMake's project VERSION is {version}")
    following = [line for line in lines[first + 1:] if line.strip()]
    date = DATE_LINE_RE.match(following[0]) if following else None
    if not date:
        problems.append(f"CHANGELOG.md:{first + 1}: the newest version has no \"Released YYYY-MM-DD.\" "
                        "line under its heading")
    else:
        try:
            datetime.date(*(int(x) for x in date.groups()))
        except ValueError:
            problems.append(f"CHANGELOG.md:{first + 1}: \"{following[0]}\" is not a calendar date")
    for (_, newer), (i, older) in zip(versions, versions[1:]):
        if not older < newer:
            problems.append(f"CHANGELOG.md:{i + 1}: version {'.'.join(map(str, older))} comes after "
                            f"{'.'.join(map(str, newer))}: versions go newest first")
    return problems


def reported_problems(version, reported):
    """REPORTED: {place: text it reports or None when unreadable}."""
    problems = []
    for place, got in reported.items():
        if got is None:
            problems.append(f"{place}: no version found")
        elif got != version:
            problems.append(f"{place}: reports {got}, CMake's project VERSION is {version}")
    return problems


FIND_PACKAGE_RE = re.compile(r"find_package\(\s*vista\s+(\d+(?:\.\d+)*)")


def find_package_problems(root, version):
    """find_package(vista X.Y) requests in examples/ and docs/ that ask for another minor version."""
    want = version.split(".")[:2]
    problems = []
    for top in ("examples", "docs"):
        for base, dirs, names in os.walk(os.path.join(root, top)):
            dirs.sort()
            for name in sorted(names):
                if not (name == "CMakeLists.txt" or name.endswith((".cmake", ".md"))):
                    continue
                path = os.path.join(base, name)
                for i, line in enumerate(read(path).split("\n")):
                    for m in FIND_PACKAGE_RE.finditer(line):
                        if m.group(1).split(".")[:2] != want:
                            problems.append(f"{os.path.relpath(path, root)}:{i + 1}: find_package(vista "
                                            f"{m.group(1)}) asks for another minor version than {version}")
    return problems


def read(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


def match_in_file(path, regex):
    if not os.path.exists(path):
        return None
    m = re.search(regex, read(path), re.MULTILINE)
    return m.group(1) if m else None


def check(root, vista, build, python_dir):
    version = cmake_version(read(os.path.join(root, "CMakeLists.txt")))
    if version is None:
        return None, ["CMakeLists.txt: no project(vista VERSION MAJOR.MINOR.PATCH)"]
    problems = changelog_problems(read(os.path.join(root, "CHANGELOG.md")), version)
    problems += find_package_problems(root, version)
    out = subprocess.run([vista, "--version"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                         text=True, timeout=60).stdout.strip()
    m = re.fullmatch(r"vista " + SEMVER, out)
    reported = {
        "`vista --version`": ".".join(m.groups()) if m else None,
        "CPackConfig.cmake (the .deb's Version)": match_in_file(
            os.path.join(build, "CPackConfig.cmake"), r'^set\(CPACK_PACKAGE_VERSION "([^"]*)"\)'),
        "vistaConfigVersion.cmake (find_package(vista))": match_in_file(
            os.path.join(build, "vistaConfigVersion.cmake"), r'^set\(PACKAGE_VERSION "([^"]*)"\)'),
    }
    if python_dir:
        env = dict(os.environ, PYTHONPATH=python_dir)
        r = subprocess.run([sys.executable, "-c", "import vista; print(vista.__version__)"],
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env,
                           timeout=120)
        reported["the Python module's vista.__version__"] = r.stdout.strip() if r.returncode == 0 else None
        if r.returncode != 0:
            problems.append(f"importing vista from {python_dir} failed:\n{r.stdout}")
    return version, problems + reported_problems(version, reported)


def self_test():
    cmake = "cmake_minimum_required(VERSION 3.20)\nproject(vista VERSION 2.3.4 LANGUAGES CXX C)\n"
    good = ("# Changelog\n\n## Unreleased\n\n- x\n\n## 2.3.4 — a title\n\nReleased 2031-02-03.\n\n"
            "### Part\n- y\n\n## 2.2.0 — older\n\n- z\n")
    failures = []
    v = cmake_version(cmake)
    if v != "2.3.4":
        failures.append(f"project VERSION read as {v}")
    if changelog_problems(good, "2.3.4"):
        failures.append(f"agreeing CHANGELOG: {changelog_problems(good, '2.3.4')}")
    if reported_problems("2.3.4", {"a": "2.3.4"}):
        failures.append("agreeing report flagged")
    planted = {
        "older newest heading": (good, "2.4.0"),
        "no date line": (good.replace("Released 2031-02-03.\n\n", ""), "2.3.4"),
        "impossible date": (good.replace("2031-02-03", "2031-02-30"), "2.3.4"),
        "wrong order": (good.replace("2.2.0", "2.5.0"), "2.3.4"),
        "malformed heading": (good.replace("## 2.2.0 — older", "## Version two"), "2.3.4"),
    }
    for what, (text, version) in planted.items():
        if len(changelog_problems(text, version)) != 1:
            failures.append(f"planted {what}: expected 1 problem, got {changelog_problems(text, version)}")
    for what, got in {"other version": "2.3.5", "unreadable": None}.items():
        if len(reported_problems("2.3.4", {"place": got})) != 1:
            failures.append(f"planted {what} report: not found")
    import tempfile
    with tempfile.TemporaryDirectory() as tmp:
        os.makedirs(os.path.join(tmp, "examples", "app"))
        with open(os.path.join(tmp, "examples", "app", "CMakeLists.txt"), "w") as f:
            f.write("find_package(vista 2.3 CONFIG REQUIRED)\n")
        if find_package_problems(tmp, "2.3.4"):
            failures.append(f"an agreeing find_package flagged: {find_package_problems(tmp, '2.3.4')}")
        if len(find_package_problems(tmp, "2.4.0")) != 1:
            failures.append("planted older find_package(vista 2.3) not found against 2.4.0")
    for f in failures:
        print(f"check_version self-test: {f}")
    if failures:
        return 1
    print(f"check_version self-test: {len(planted) + 3} planted disagreements found, the agreeing set passes")
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--root", help="the source tree")
    ap.add_argument("--vista", help="the built vista binary")
    ap.add_argument("--build", help="the build directory (CPackConfig.cmake, vistaConfigVersion.cmake)")
    ap.add_argument("--python-dir", help="the directory that holds the built Python package vista")
    ap.add_argument("--self-test", action="store_true")
    args = ap.parse_args()
    if args.self_test:
        return self_test()
    if not (args.root and args.vista and args.build):
        ap.error("--root, --vista and --build are required")
    version, problems = check(args.root, args.vista, args.build, args.python_dir)
    for p in problems:
        print(p)
    if problems:
        print(f"check_version: {len(problems)} disagreement(s) with CMake's project VERSION {version}")
        return 1
    print(f"check_version: CMake, `vista --version`, CHANGELOG.md, the .deb's CPack version, the CMake "
          f"package, the find_package requests{', the Python module' if args.python_dir else ''} all say "
          f"{version}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
