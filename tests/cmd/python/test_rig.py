"""vista.Rig against `vista render --rig`: the same camera channels and LiDAR points byte for byte."""
import json

import numpy as np
import pytest
from PIL import Image

import vista
from conftest import run_vista

RIG = {"sensors": [
    {"name": "cam", "type": "pinhole", "pose": {"x": 0.3, "y": 0.0, "z": 0.4}, "rate_hz": 10,
     "intrinsics": {"width": 64, "height": 48, "fx": 40, "fy": 40, "cx": 31.5, "cy": 23.5},
     "channels": ["rgb", "depth", "semantic", "instance", "boxes"]},
    {"name": "lidar", "type": "lidar", "pose": {"x": 0.0, "y": 0.0, "z": 0.5}, "rate_hz": 10,
     "beams": {"count": 8, "min_deg": -15, "max_deg": 2}, "columns": 64, "min_range_m": 0.9, "max_range_m": 80,
     "rotation_hz": 10},
]}


def test_rig_fires_what_vista_render_rig_writes(cli_city, city, tmp_path):
    (tmp_path / "rig.json").write_text(json.dumps(RIG))
    out = tmp_path / "out"
    run_vista("render", cli_city / "city.osgb", "--rig", tmp_path / "rig.json", "--frames", 2, "--out", out, "-q")
    frames = json.loads((out / "rig.json").read_text())["frames"]
    path = vista.path(city)
    rig = vista.Rig(city, tmp_path / "rig.json")
    assert rig.sensors == ["cam", "lidar"]
    for f in frames:
        name, i = f["name"], f["path_index"]
        got = rig.fire(path[i], t=f["t_s"], path=path)
        cam, lidar = got["cam"], got["lidar"]
        assert np.array_equal(cam["rgb"], np.asarray(Image.open(out / "image_00" / f"{name}.png")))
        assert np.array_equal(cam["depth"], np.load(out / "depth_00" / f"{name}.npy"))
        assert np.array_equal(cam["semantic"], np.asarray(Image.open(out / "semantic_00" / f"{name}.png")))
        assert np.array_equal(cam["instance"], np.load(out / "instance_00" / f"{name}.npy"))
        boxes = json.loads((out / "boxes_00" / f"{name}.json").read_text())["boxes"]
        visible = {b["id"]: b["visible"] for b in boxes}
        assert sorted(cam["boxes"]["id"].tolist()) == sorted(visible)
        for b in cam["boxes"]:
            assert [int(b["u0"]), int(b["v0"]), int(b["u1"]), int(b["v1"])] == visible[int(b["id"])]
        velodyne = np.fromfile(out / "velodyne" / f"{name}.bin", dtype="<f4").reshape(-1, 4)
        assert lidar["points"].dtype == np.float32 and np.array_equal(lidar["points"], velodyne)
        labels = np.fromfile(out / "labels_vista" / f"{name}.label", dtype="<u4")
        assert np.array_equal(lidar["semantic"].astype(np.uint32), labels)
        times = np.fromfile(out / "velodyne_time" / f"{name}.bin", dtype="<f4")
        assert np.array_equal(lidar["time"].astype(np.float32), times)
        assert np.all(np.diff(lidar["time"][lidar["beam"] == 0]) >= 0)  # per-point times along the sweep
        assert lidar["time"].max() < 0.1 + 1e-6  # one revolution at 10 Hz


def test_a_standing_rig_needs_no_path(city, tmp_path):
    (tmp_path / "rig.json").write_text(json.dumps(RIG))
    rig = vista.Rig(city, tmp_path / "rig.json")
    pose = vista.path(city, duration=1)[0]
    a, b = rig.fire(pose), rig.fire(pose)
    assert np.array_equal(a["cam"]["rgb"], b["cam"]["rgb"]) and len(a["lidar"]["points"]) > 0


def test_bad_rig_file_raises_naming_the_field(city, tmp_path):
    bad = json.loads(json.dumps(RIG))
    bad["sensors"][0]["rate_hz"] = 0
    (tmp_path / "bad.json").write_text(json.dumps(bad))
    with pytest.raises(ValueError, match=r"rate_hz.*\(0, 1000\]"):
        vista.Rig(city, tmp_path / "bad.json")


def test_dataset_reads_the_per_point_lidar_files(cli_city, tmp_path):
    (tmp_path / "rig.json").write_text(json.dumps(RIG))
    out = tmp_path / "out"
    run_vista("render", cli_city / "city.osgb", "--rig", tmp_path / "rig.json", "--frames", 1, "--out", out, "-q")
    item = vista.RenderDataset(out)[0]
    n = len(np.fromfile(out / "velodyne" / "000000.bin", dtype="<f4")) // 4
    times = np.asarray(item["velodyne_time"])
    assert times.shape == (n,) and times.dtype == np.float32 and 0 <= times.min() and times.max() < 0.1
    sk = np.asarray(item["labels"])
    vista_classes = np.asarray(item["labels_vista"])
    assert sk.shape == vista_classes.shape == (n,)
    # Road points (vista class 2) are SemanticKITTI road (40) with no instance.
    road = vista_classes == 2
    assert road.any() and np.all(sk[road] == 40)
