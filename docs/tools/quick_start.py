#!/usr/bin/env python3
"""Runs the guide's five-minute start as written and times each step.

Reads the first ```sh block under "## Five-minute start" of docs/guide/README.md,
joins its continued lines, and runs each command with bash from a working
directory that looks like the repository root to the commands (build/, data/
and docs/ of the checkout, out/ of its own), so nothing is written into the
checkout. Prints one line per step (number, wall seconds, the command) and the
total; stops at the first failing step, naming it (exit 1).

With --fresh-clone the working directory is a `git clone` of the checkout's
HEAD, and `.ci/setup.sh` runs there first (timed on its own line: the set-up
is not part of the five minutes); that is what a newcomer does.

Usage: quick_start.py [--repo DIR] [--build DIR] [--work DIR] [--fresh-clone] [--keep]
  --repo   the checkout (default: the one holding this script)
  --build  its build directory (default: REPO/build)
  --work   the working directory (default: a temporary one, removed unless --keep)
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

SECTION = "## Five-minute start"


def steps(guide_text):
    """[(label, command)] of the section's first sh block; the label is the comment before it."""
    lines = guide_text.splitlines()
    try:
        start = next(i for i, line in enumerate(lines) if line.strip() == SECTION)
    except StopIteration:
        raise SystemExit(f"quick_start: no '{SECTION}' heading in the guide")
    begin = next((i for i in range(start + 1, len(lines)) if lines[i].strip() == "```sh"), None)
    if begin is None:
        raise SystemExit(f"quick_start: no ```sh block under '{SECTION}'")
    out, label, pending = [], "", ""
    for line in lines[begin + 1:]:
        if line.strip() == "```":
            break
        if pending:
            pending += " " + line.strip()
        elif line.lstrip().startswith("#"):
            text = line.lstrip("# ").strip()
            label = text if re.match(r"\d+\.", text) else (label + " " + text).strip()
            continue
        elif line.strip():
            pending = line.strip()
        if pending.endswith("\\"):
            pending = pending[:-1].rstrip()
            continue
        if pending:
            out.append((label, pending))
            pending, label = "", ""
    return out


def run(work, label, command, env):
    t0 = time.monotonic()
    r = subprocess.run(["bash", "-c", "set -euo pipefail; " + command], cwd=work, env=env,
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    seconds = time.monotonic() - t0
    if r.returncode != 0:
        tail = "\n".join(r.stdout.splitlines()[-20:])
        raise SystemExit(f"quick_start: step failed (exit {r.returncode}) after {seconds:.1f} s: "
                         f"{label or command}\n  {command}\n{tail}")
    return seconds


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repo", default=os.path.normpath(os.path.join(here, "..", "..")))
    ap.add_argument("--build")
    ap.add_argument("--work")
    ap.add_argument("--fresh-clone", action="store_true")
    ap.add_argument("--keep", action="store_true")
    args = ap.parse_args()
    repo = os.path.abspath(args.repo)
    with open(os.path.join(repo, "docs", "guide", "README.md"), encoding="utf-8") as f:
        todo = steps(f.read())
    if not todo:
        raise SystemExit("quick_start: the block has no command")
    work = os.path.abspath(args.work) if args.work else tempfile.mkdtemp(prefix="vista-qs-")
    if os.path.exists(work) and os.listdir(work):
        raise SystemExit(f"quick_start: --work {work} is not empty (give a new or empty directory)")
    env = dict(os.environ)
    try:
        if args.fresh_clone:
            subprocess.run(["git", "clone", "-q", repo, work], check=True)
            seconds = run(work, "set-up", ".ci/setup.sh", env)
            print(f"set-up\t{seconds:.1f} s\t.ci/setup.sh")
        else:
            os.makedirs(work, exist_ok=True)
            build = os.path.abspath(args.build or os.path.join(repo, "build"))
            for name, target in (("build", build), ("data", os.path.join(repo, "data")),
                                 ("docs", os.path.join(repo, "docs"))):
                os.symlink(target, os.path.join(work, name))
        total = 0.0
        for n, (label, command) in enumerate(todo, 1):
            seconds = run(work, label, command, env)
            total += seconds
            print(f"{n}\t{seconds:.1f} s\t{command}", flush=True)
        print(f"all\t{total:.1f} s\t{len(todo)} steps after the set-up")
    finally:
        if not args.keep and not args.work:
            shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
