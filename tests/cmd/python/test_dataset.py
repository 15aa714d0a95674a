"""vista.RenderDataset over `vista render` output: one camera and a rig (camera + LiDAR)."""
import json

import numpy as np
import pytest
from PIL import Image

import vista
from conftest import run_vista

torch = pytest.importorskip("torch", reason="the Dataset's test needs python3-torch (Debian)")

RIG = {"sensors": [
    {"name": "cam", "type": "pinhole", "pose": {"x": 0.3, "y": 0.0, "z": 0.4}, "rate_hz": 10,
     "intrinsics": {"width": 64, "height": 48, "fx": 40, "fy": 40, "cx": 31.5, "cy": 23.5},
     "channels": ["rgb", "depth", "semantic", "instance"]},
    {"name": "lidar", "type": "lidar", "pose": {"x": 0.0, "y": 0.0, "z": 0.5}, "rate_hz": 10,
     "beams": {"count": 8, "min_deg": -15, "max_deg": 2}, "columns": 64, "min_range_m": 0.9, "max_range_m": 80,
     "rotation_hz": 10},
]}


def test_dataset_over_one_camera(display, cli_city, tmp_path):
    out = tmp_path / "out"
    run_vista("render", cli_city / "city.osgb", "--frames", 3, "--size", "64x48", "--mode", "full", "--out", out, "-q")
    ds = vista.RenderDataset(out)
    assert len(ds) == 3 and ds.kind == "camera"
    item = ds[2]
    assert isinstance(item["rgb"], torch.Tensor) and tuple(item["rgb"].shape) == (48, 64, 3)
    assert np.array_equal(item["rgb"].numpy(), np.asarray(Image.open(out / "rgb" / "000002.png")))
    assert np.array_equal(item["depth"].numpy(), np.load(out / "depth" / "000002.npy"))
    batch = next(iter(torch.utils.data.DataLoader(ds, batch_size=3)))
    assert tuple(batch["rgb"].shape) == (3, 48, 64, 3) and tuple(batch["instance"].shape) == (3, 48, 64)
    with pytest.raises(IndexError):
        ds[3]


def test_dataset_over_a_rig(cli_city, tmp_path):
    (tmp_path / "rig.json").write_text(json.dumps(RIG))
    out = tmp_path / "rig_out"
    run_vista("render", cli_city / "city.osgb", "--rig", tmp_path / "rig.json", "--frames", 2, "--out", out, "-q")
    ds = vista.RenderDataset(out)
    assert ds.kind == "rig" and len(ds) == 2
    item = ds[1]
    assert tuple(item["image_00"].shape) == (48, 64, 3)
    pts = np.fromfile(out / "velodyne" / "000001.bin", dtype="<f4").reshape(-1, 4)
    assert item["velodyne"].shape[1] == 4 and np.array_equal(item["velodyne"].numpy(), pts)
    assert item["labels"].shape[0] == pts.shape[0]


def test_dataset_refuses_other_directories(tmp_path):
    with pytest.raises(ValueError, match="vista render"):
        vista.RenderDataset(tmp_path)
