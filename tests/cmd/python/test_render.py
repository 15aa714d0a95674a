"""Renderer against `vista render`: the same frames byte for byte (rgb PNG decoded, depth and instance
.npy, semantic PNG), arrays without copies, bad input as ValueError."""
import json

import numpy as np
import pytest
from PIL import Image

import vista
from conftest import run_vista

W, H = 160, 120


def cli_frames(cli_city, out, mode, sampling):
    run_vista("render", cli_city / "city.osgb", "--frames", 3, "--sampling", sampling, "--size", f"{W}x{H}",
              "--mode", mode, "--out", out, "-q")
    return json.loads((out / "cameras.json").read_text())["frames"]


@pytest.mark.parametrize("mode, sampling", [("full", "spread"), ("hybrid", "consecutive")])
def test_frames_equal_vista_render(display, cli_city, city, tmp_path, mode, sampling):
    out = tmp_path / "out"
    frames = cli_frames(cli_city, out, mode, sampling)
    path = vista.path(city)  # the path `vista render` makes with its default path options
    r = vista.Renderer(city, mode=mode, size=(W, H))
    for f in frames:  # in order: hybrid carries its panoramic cache from frame to frame
        got = r.render(path[f["path_index"]])
        name = f["name"]
        assert np.array_equal(got["rgb"], np.asarray(Image.open(out / "rgb" / f"{name}.png")))
        assert np.array_equal(got["depth"], np.load(out / "depth" / f"{name}.npy"))
        assert np.array_equal(got["semantic"], np.asarray(Image.open(out / "semantic" / f"{name}.png")))
        assert np.array_equal(got["instance"], np.load(out / "instance" / f"{name}.npy"))
        assert got["rgb"].dtype == np.uint8 and got["depth"].dtype == np.float32
        assert got["instance"].dtype == np.uint32 and got["semantic"].shape == (H, W)


def test_arrays_are_views_of_the_renderers_buffers(display, city):
    r = vista.Renderer(city, mode="full", size=(W, H), channels="rgb,depth")
    got = r.render(vista.path(city, duration=1)[0])
    rgb = got["rgb"]
    # rgb is a view of the RGBA rows (no copy): it owns no data and steps over alpha.
    assert not rgb.flags.owndata and rgb.strides == (W * 4, 4, 1) and rgb.shape == (H, W, 3)
    assert not got["depth"].flags.owndata
    assert set(got) == {"rgb", "depth", "frame_ms"}
    cam = r.camera
    assert cam["width"] == W and cam["cx"] == (W - 1) / 2


def test_frames_keep_their_memory_after_the_next_render(display, city):
    r = vista.Renderer(city, mode="full", size=(W, H), channels=["rgb"])
    p = vista.path(city, duration=2)
    first = r.render(p[0])["rgb"]
    kept = first.copy()
    r.render(p[-1])
    assert np.array_equal(first, kept)


@pytest.mark.parametrize("kw, words", [
    ({"size": (0, 10)}, ["size", "8192"]),
    ({"fov": 180}, ["fov", "179"]),
    ({"mode": "raycast"}, ["mode", "full or hybrid"]),
    ({"channels": ["rgb", "colour"]}, ["colour", "rgb, depth, semantic, instance"]),
    ({"channels": ["rgb", "rgb"]}, ["twice"]),
])
def test_bad_renderer_options_raise(city, kw, words):
    with pytest.raises(ValueError) as e:
        vista.Renderer(city, **kw)
    for w in words:
        assert w in str(e.value)


def test_pose_outside_the_city_raises(display, city):
    r = vista.Renderer(city, mode="full", size=(32, 24), channels=["rgb"])
    with pytest.raises(ValueError, match="outside|bounds"):
        r.render(vista.Pose((1e5, 0.0, 1.2)))


def test_a_renderer_after_a_closed_one_draws_the_same(display, city):
    """A city drawn by a renderer with the label pass, then closed, draws the same in the next renderer
    (its context reuses the closed one's id: the graph must keep no GL names of the closed context)."""
    import gc

    p = vista.path(city, duration=2)
    first = vista.Renderer(city, mode="hybrid", size=(W, H), channels=["rgb"])
    want = first.render(p[0])["rgb"].copy()
    del first
    gc.collect()
    labels = vista.Renderer(city, mode="full", size=(W, H), channels=["rgb", "depth"])
    labels.render(p[0])
    del labels
    gc.collect()
    again = vista.Renderer(city, mode="hybrid", size=(W, H), channels=["rgb"])
    assert np.array_equal(again.render(p[0])["rgb"], want)
