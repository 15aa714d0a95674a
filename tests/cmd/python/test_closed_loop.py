"""The closed-loop example (examples/python/closed_loop.py) drives 300 steps along the lanes."""
import importlib.util
import os

import numpy as np

import vista

EXAMPLE = os.path.join(os.environ.get("VISTA_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", "..", "..")),
                       "examples", "python", "closed_loop.py")


def load_example():
    spec = importlib.util.spec_from_file_location("closed_loop", EXAMPLE)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def distance_to_lanes(lanes, xy):
    """Distance from xy to the nearest lane centre segment (independent of the controller)."""
    a = np.stack([lanes["x0"], lanes["y0"]], axis=1)
    b = np.stack([lanes["x1"], lanes["y1"]], axis=1)
    d = b - a
    t = np.clip(np.einsum("ij,ij->i", xy - a, d) / np.einsum("ij,ij->i", d, d), 0, 1)
    return float(np.min(np.linalg.norm(a + d * t[:, None] - xy, axis=1)))


def test_closed_loop_runs_300_steps(display, city):
    ex = load_example()
    log = ex.drive(city, steps=300, size=(64, 48))
    assert len(log["poses"]) == 300 and len(log["frames"]) == 300
    assert all(f.shape == (48, 64, 3) for f in log["frames"])
    xy = np.array([p.position[:2] for p in log["poses"]])
    travelled = np.sum(np.linalg.norm(np.diff(xy, axis=0), axis=1))
    assert travelled > 50.0  # it moves (10 s at up to the lanes' speed limits)
    lanes = city.lanes
    dists = [distance_to_lanes(lanes, p) for p in xy]
    # On lane centres except across junctions (the lanes array holds the street roads, not the turns).
    assert np.median(dists) < 0.1 and max(dists) < 3.0
