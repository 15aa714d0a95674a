"""vista.path against `vista path`: the same CSV bytes, arrays equal to the CSV's values."""
import numpy as np
import pytest

import vista
from conftest import run_vista


@pytest.mark.parametrize("kind, extra", [("car", []), ("walk", ["--route", "wander"]), ("fly", ["--seed", "4"])])
def test_path_is_the_csv_of_vista_path(cli_city, city, tmp_path, kind, extra):
    cli = tmp_path / "cli.csv"
    args = ["path", cli_city / "city.osgb", "--kind", kind, "--duration", 6, "-o", cli, *extra]
    if kind == "car":
        args += ["--xodr-positions", tmp_path / "lanes.csv"]
    run_vista(*args)
    kw = {"route": "wander"} if "wander" in extra else {}
    seed = 4 if "--seed" in extra else 1
    p = vista.path(city, kind=kind, duration=6, seed=seed, **kw)
    p.save(tmp_path / "py.csv")
    assert (tmp_path / "py.csv").read_bytes() == cli.read_bytes()
    rows = np.loadtxt(cli, delimiter=",", skiprows=1, ndmin=2)
    assert len(p) == len(rows) == len(p.t)
    # The CSV prints fixed decimals: the arrays round to its values.
    assert np.allclose(p.t, rows[:, 0], atol=1e-6)
    assert np.allclose(p.position, rows[:, 1:4], atol=1e-4)
    assert np.allclose(np.degrees(p.heading), rows[:, 4], atol=1e-4)
    assert np.allclose(np.degrees(p.pitch), rows[:, 5], atol=1e-4)
    pose = p[3]
    assert pose.t == p.t[3] and pose.position == tuple(p.position[3]) and pose.heading == p.heading[3]
    if kind == "car":
        lanes = np.loadtxt(tmp_path / "lanes.csv", delimiter=",", skiprows=1, ndmin=2)
        assert np.array_equal(p.road, lanes[:, 1].astype(np.uint64))
        assert np.array_equal(p.lane, lanes[:, 2].astype(np.int32))
        assert np.allclose(p.s, lanes[:, 3], atol=1e-4) and np.allclose(p.t_offset, lanes[:, 4], atol=1e-4)
    else:
        assert p.road is None


def test_load_path_reads_the_csv(city, tmp_path):
    p = vista.path(city, duration=3)
    p.save(tmp_path / "p.csv")
    q = vista.load_path(tmp_path / "p.csv")
    assert np.allclose(q.position, p.position, atol=1e-4) and len(q) == len(p)


@pytest.mark.parametrize("kw, words", [
    ({"duration": -1}, ["duration", "(0, 86400]"]),
    ({"dt": 100}, ["dt", "(0, 10]"]),
    ({"kind": "boat"}, ["boat", "walk, car, fly"]),
    ({"route": "zigzag"}, ["route", "zigzag"]),
    ({"kind": "walk", "lht": True}, ["car"]),
])
def test_bad_path_options_raise(city, kw, words):
    with pytest.raises(ValueError) as e:
        vista.path(city, **kw)
    for w in words:
        assert w in str(e.value)


def test_bad_path_file_leaves_nothing(city, tmp_path):
    with pytest.raises(ValueError):
        vista.path(city, duration=2).save(tmp_path / "missing" / "p.csv")
    assert list(tmp_path.iterdir()) == []
