"""Fixtures of the Python module's tests: the built `vista` tool, small cities made by it, a GL display.

ctest runs these with PYTHONPATH=<build>/python and VISTA_BINARY=<build>/vista (tests/CMakeLists.txt).
"""
import os
import subprocess

import pytest

VISTA = os.environ.get("VISTA_BINARY", "vista")
SEED, SIZE = 5, 400  # a small city: a few seconds to generate and render


def run_vista(*args, check=True):
    """Runs the `vista` tool; returns the completed process (stdout and stderr as text)."""
    r = subprocess.run([VISTA, *map(str, args)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if check and r.returncode != 0:
        raise AssertionError(f"vista {' '.join(map(str, args))} exited {r.returncode}: {r.stderr}")
    return r


@pytest.fixture(scope="session")
def cli_city(tmp_path_factory):
    """A city file and its stats JSON, written by `vista gen`."""
    d = tmp_path_factory.mktemp("cli_city")
    run_vista("gen", "--seed", SEED, "--size", SIZE, "-o", d / "city.osgb", "--stats", d / "stats.json",
              "--xodr", d / "city.xodr", "-q")
    return d


@pytest.fixture(scope="session")
def city(cli_city):
    import vista

    return vista.load(cli_city / "city.osgb")


@pytest.fixture
def display():
    """Rendering needs a GL context: a display (ctest runs under xvfb-run in CI)."""
    if not os.environ.get("DISPLAY"):
        pytest.skip("no display: run under xvfb-run -a (rendering needs a GL context)")
