"""A PyTorch Dataset over the output of ``vista render`` (one camera, or a sensor rig with ``--rig``).

Item ``i`` is frame ``NNNNNN`` (six digits): a dict with one entry per folder of the output that holds
that frame, keyed by the folder's name: images (``rgb``, ``image_NN``, ``semantic``, ``semantic_NN``)
as uint8 tensors (H, W, 3) or (H, W); ``.npy`` channels (``depth``, ``*_NN``) as stored, instance ids (uint32 in the files) as int64, as torch
has no uint32;
``velodyne*`` as float32 (N, 4) (x, y, z, intensity), ``velodyne_time*`` as float32 (N,) (seconds since
the sweep's start), ``labels`` (SemanticKITTI), ``labels_vista`` and ``lidar_instance`` as int64 (N,)
per point; ``boxes_*`` as the parsed JSON. A sensor that did not fire at a frame has no entry. torch is
imported when the Dataset is created (Debian's python3-torch); without it, items are numpy arrays.
"""

import json
import os

import numpy as np

_FRAME_DIGITS = 6


def _torch():
    try:
        import torch
    except ImportError:
        return None
    return torch


def _read_png(path):
    from PIL import Image  # Debian's python3-pil

    with Image.open(path) as im:
        return np.array(im)


def _read(path):
    ext = os.path.splitext(path)[1]
    folder = os.path.basename(os.path.dirname(path))
    if ext == ".png":
        return _read_png(path)
    if ext == ".npy":
        return np.load(path)
    if ext == ".bin" and folder.startswith("velodyne_time"):
        return np.fromfile(path, dtype="<f4")
    if ext == ".bin" and folder.startswith("velodyne"):
        return np.fromfile(path, dtype="<f4").reshape(-1, 4)
    if ext in (".bin", ".label"):
        return np.fromfile(path, dtype="<u4").astype(np.int64)
    if ext == ".json":
        with open(path, "r", encoding="utf-8") as f:
            return json.load(f)
    return None  # other files (flow, KITTI label text) are left to the caller


def _dataset_base():
    torch = _torch()
    return torch.utils.data.Dataset if torch is not None else object


class RenderDataset(_dataset_base()):
    """Frames of a ``vista render`` output directory (``--out``), one item per frame.

    root: the output directory (it holds cameras.json, or rig.json for a rig run). transform: an
    optional callable applied to each item. Raises ValueError when root is not such a directory.
    """

    def __init__(self, root, transform=None):
        self.root = str(root)
        self.transform = transform
        meta = None
        for name in ("rig.json", "cameras.json"):
            p = os.path.join(self.root, name)
            if os.path.isfile(p):
                with open(p, "r", encoding="utf-8") as f:
                    meta = json.load(f)
                self.kind = "rig" if name == "rig.json" else "camera"
                break
        if meta is None:
            raise ValueError("root = '%s': not the output of `vista render` (no cameras.json or rig.json)" % root)
        self.meta = meta
        self.frames = len(meta["frames"])
        self.folders = sorted(
            d for d in os.listdir(self.root) if os.path.isdir(os.path.join(self.root, d)))
        self._torch = _torch()

    def __len__(self):
        """The number of frames (cameras.json or rig.json)."""
        return self.frames

    def __getitem__(self, i):
        """Frame i's files, one entry per folder that holds it (see the module's docstring)."""
        if i < 0:
            i += self.frames
        if not 0 <= i < self.frames:
            raise IndexError("frame %d out of range 0 .. %d" % (i, self.frames - 1))
        name = str(i).zfill(_FRAME_DIGITS)
        item = {"frame": i}
        for d in self.folders:
            folder = os.path.join(self.root, d)
            for f in os.listdir(folder):
                if os.path.splitext(f)[0] != name:
                    continue
                v = _read(os.path.join(folder, f))
                if v is None:
                    continue
                if isinstance(v, np.ndarray) and self._torch is not None:
                    if v.dtype == np.uint32:  # torch has no uint32: instance ids as int64 (same values)
                        v = v.astype(np.int64)
                    v = self._torch.from_numpy(np.require(v, requirements=["C", "W"]))
                item[d] = v
        return self.transform(item) if self.transform else item
