"""generate / load / save and the city's arrays, against the files `vista gen` writes for the same params."""
import json

import numpy as np
import pytest

import vista
from conftest import SEED, SIZE, run_vista


def test_version_is_the_tools():
    out = run_vista("--version").stdout.strip()
    assert out == f"vista {vista.__version__}"
    assert len(vista.__version__.split(".")) == 3


def test_generate_saves_the_bytes_of_vista_gen(cli_city, tmp_path):
    c = vista.generate(seed=SEED, size_m=SIZE)
    c.save(tmp_path / "py.osgb")
    assert (tmp_path / "py.osgb").read_bytes() == (cli_city / "city.osgb").read_bytes()


def test_params_dict_file_and_keywords_agree(tmp_path):
    (tmp_path / "p.json").write_text(json.dumps({"seed": 2, "size_m": 300, "detail": 0}))
    a = vista.generate(params=tmp_path / "p.json")
    b = vista.generate(params={"seed": 2, "detail": 0}, size_m=300)
    c = vista.generate(seed=2, size_m=300, detail=0)
    for x in (a, b, c):
        assert x.params["detail"] == 0 and x.params["size_m"] == 300
    assert a.stats == b.stats == c.stats
    a.save(tmp_path / "a.osgb")
    c.save(tmp_path / "c.osgb")
    assert (tmp_path / "a.osgb").read_bytes() == (tmp_path / "c.osgb").read_bytes()


def test_stats_are_those_of_vista_gen(cli_city):
    cli = json.loads((cli_city / "stats.json").read_text())
    py = vista.generate(seed=SEED, size_m=SIZE).stats
    for key, value in py.items():
        assert cli[key] == value, key
    for key in ("street_nodes", "street_edges", "blocks", "buildings", "trees", "triangles", "draw_calls"):
        assert key in py


def test_opendrive_is_the_xodr_of_vista_gen(cli_city, city):
    assert city.opendrive() == (cli_city / "city.xodr").read_text()


def test_arrays_of_a_loaded_city(cli_city, city):
    stats = json.loads((cli_city / "stats.json").read_text())
    nodes, edges = city.streets["nodes"], city.streets["edges"]
    assert nodes.shape == (stats["street_nodes"], 2) and nodes.dtype == np.float64
    assert len(edges) == stats["street_edges"]
    assert edges["a"].max() < len(nodes) and edges["b"].max() < len(nodes)
    half = SIZE / 2 + 1e-6
    assert np.all(np.abs(nodes) <= half)  # origin 0: world = city frame, inside the square
    assert len(city.buildings) == stats["buildings"] == len(city.building_footprints)
    assert len(city.trees) == stats["trees"]
    # Each building's centroid lies inside the bounding box of its footprint.
    for b, ring in zip(city.buildings, city.building_footprints):
        assert ring.min(axis=0)[0] <= b["x"] <= ring.max(axis=0)[0]
        assert ring.min(axis=0)[1] <= b["y"] <= ring.max(axis=0)[1]
    # The generated city's layout and the loaded city's (grown again from its params) agree.
    g = vista.generate(seed=SEED, size_m=SIZE)
    assert np.array_equal(g.buildings, city.buildings)
    assert np.array_equal(g.trees, city.trees)


def test_lanes_are_the_opendrive_roads(cli_city, city):
    import re

    lanes = city.lanes
    assert np.array_equal(vista.generate(seed=SEED, size_m=SIZE).lanes, lanes)
    xodr = (cli_city / "city.xodr").read_text()
    roads = {int(r) for r in re.findall(r'<road [^>]*\bid="(\d+)"', xodr)}
    assert set(lanes["road"].tolist()) <= roads
    assert len(set(lanes["edge"].tolist())) == len(set(lanes["road"].tolist()))


def test_lanes_lie_beside_their_street(city):
    lanes, nodes, edges = city.lanes, city.streets["nodes"], city.streets["edges"]
    assert len(lanes) >= len(edges)
    for ln in lanes[:200]:
        e = edges[ln["edge"]]
        a, b = nodes[e["a"]], nodes[e["b"]]
        d = b - a
        n = np.array([-d[1], d[0]]) / np.linalg.norm(d)
        mid = 0.5 * (np.array([ln["x0"], ln["y0"]]) + np.array([ln["x1"], ln["y1"]]))
        lateral = float(np.dot(mid - a, n))
        # Right lanes (negative ids) right of a -> b, left lanes left of it, within the carriageway.
        assert np.sign(lateral) == np.sign(ln["lane"])
        assert abs(lateral) <= e["width"] / 2 + 1e-6
        travel = np.array([ln["x1"] - ln["x0"], ln["y1"] - ln["y0"]])
        assert np.sign(np.dot(travel, d)) == (-1 if ln["lane"] > 0 else 1)


def test_paged_city_loads(tmp_path, cli_city):
    run_vista("gen", "--seed", SEED, "--size", 1000, "--region-size", 500, "-o", tmp_path / "c.paged", "-q")
    run_vista("gen", "--seed", SEED, "--size", 1000, "-o", tmp_path / "c.osgb", "-q")
    paged, whole = vista.load(tmp_path / "c.paged"), vista.load(tmp_path / "c.osgb")
    assert paged.paged and not whole.paged
    assert np.array_equal(paged.streets["nodes"], whole.streets["nodes"])
    assert len(paged.trees) == len(whole.trees)
    assert paged.stats["triangles"] > 0
    run_vista("path", tmp_path / "c.paged", "--duration", 5, "-o", tmp_path / "cli.csv")
    vista.path(paged, duration=5).save(tmp_path / "py.csv")
    assert (tmp_path / "py.csv").read_bytes() == (tmp_path / "cli.csv").read_bytes()
    with pytest.raises(ValueError, match="paged city"):
        paged.save(tmp_path / "x.osgb")


@pytest.mark.parametrize("call, words", [
    (lambda: vista.generate(size_m=5), ["size_m", "100", "64000"]),
    (lambda: vista.generate(detail=9), ["detail", "[0, 3]"]),
    (lambda: vista.generate(sise_m=500), ["sise_m", "unknown"]),
    (lambda: vista.generate(size_m=20000), ["size_m", "16000"]),
    (lambda: vista.load("no such city.osgb"), ["no such city.osgb"]),
])
def test_bad_parameters_raise_value_error_naming_the_field(call, words):
    with pytest.raises(ValueError) as e:
        call()
    for w in words:
        assert w in str(e.value)


def test_bad_save_leaves_nothing_behind(tmp_path, city, cli_city):
    before = sorted(p.name for p in tmp_path.iterdir())
    for bad in (tmp_path / "city.txt", tmp_path / "missing" / "city.osgb"):
        with pytest.raises(ValueError, match="path"):
            city.save(bad)
    with pytest.raises(ValueError, match="input"):
        city.save(cli_city / "city.osgb")
    assert sorted(p.name for p in tmp_path.iterdir()) == before
    assert not (tmp_path / "missing").exists()
