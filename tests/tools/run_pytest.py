"""Runs pytest over a folder with its temporary files in a scratch directory
that is removed afterwards, so that a test run leaves the file system as it was.

Usage: run_pytest.py TEST_DIR [pytest options...]

It runs in the interpreter that imports the module under test (no shell in
between), so a sanitizer run's preloaded runtime reaches only that interpreter.
"""
import sys
import tempfile

import pytest


def main():
    if len(sys.argv) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    with tempfile.TemporaryDirectory(prefix="vista-pytest-") as scratch:
        return int(pytest.main(["-q", "-p", "no:cacheprovider", "--basetemp", f"{scratch}/t", *sys.argv[2:],
                                sys.argv[1]]))


if __name__ == "__main__":
    sys.exit(main())
