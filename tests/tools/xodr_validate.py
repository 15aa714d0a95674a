#!/usr/bin/env python3
"""Validates .xodr files against the ASAM OpenDRIVE 1.6 schema with xmllint.

The schema's licence (ASAM licence terms) keeps it out of this repository; it
is looked for in VISTA_OPENDRIVE_XSD (opendrive_16_core.xsd or the folder
holding it and the files it includes), then in tests/data/opendrive-1.6/.
Without it, or without xmllint (Debian package libxml2-utils), the run is
skipped: exit 77 with the reason on stdout.

Exit status: 0 every file is valid, 1 some file has schema errors (each one
listed), 2 a file cannot be read, 77 skipped.

Usage: xodr_validate.py FILE.xodr...
"""
import os
import shutil
import subprocess
import sys

SKIP = 77
HERE = os.path.dirname(os.path.abspath(__file__))
VENDORED = os.path.normpath(os.path.join(HERE, "..", "data", "opendrive-1.6"))


def find_xsd():
    """The path of opendrive_16_core.xsd, or None; and where it was looked for."""
    tried = []
    env = os.environ.get("VISTA_OPENDRIVE_XSD")
    for cand in ([env] if env else []) + [VENDORED]:
        path = os.path.join(cand, "opendrive_16_core.xsd") if os.path.isdir(cand) else cand
        tried.append(path)
        if os.path.isfile(path):
            return path, tried
    return None, tried


def main(argv):
    if not argv:
        print(__doc__.strip().splitlines()[-1], file=sys.stderr)
        return 2
    xsd, tried = find_xsd()
    if xsd is None:
        print("SKIPPED: the OpenDRIVE 1.6 schema is not available (ASAM licence terms: it is not shipped with vista); "
              "set VISTA_OPENDRIVE_XSD to opendrive_16_core.xsd (ASAM OpenDRIVE 1.6.1, e.g. from "
              "github.com/asam-ev/qc-opendrive qc_opendrive/schema/1.6.1/). Looked for: " + ", ".join(tried))
        return SKIP
    if shutil.which("xmllint") is None:
        print("SKIPPED: xmllint is not installed (Debian package libxml2-utils)")
        return SKIP
    status = 0
    for path in argv:
        if not os.path.isfile(path):
            print(f"xodr_validate: cannot read {path}", file=sys.stderr)
            return 2
        r = subprocess.run(["xmllint", "--noout", "--schema", xsd, path], capture_output=True, text=True)
        errors = [ln for ln in r.stderr.splitlines() if "error" in ln]
        if r.returncode == 0:
            print(f"{os.path.basename(path)}: valid against {os.path.basename(xsd)}")
            continue
        status = 1
        print(f"{os.path.basename(path)}: {len(errors)} schema errors against {os.path.basename(xsd)}")
        # distinct messages first: the same error repeats once per road
        kinds = {}
        for ln in errors:
            key = ln.split(": ", 2)[-1]
            kinds[key] = kinds.get(key, 0) + 1
        for key, n in sorted(kinds.items(), key=lambda kv: -kv[1])[:20]:
            print(f"  {n:6d} x {key}")
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
