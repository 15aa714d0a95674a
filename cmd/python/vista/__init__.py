"""vista from Python: generate a city, drive a path through it and render frames, in-process.

The module calls the same library steps as the ``vista`` command (``vista gen``,
``vista path``, ``vista render``): the same arguments give the same bytes. Arrays
are numpy arrays over memory the library allocated (no copy). Bad input raises
``ValueError`` with the command's message, which names the field and its range.

    import vista
    city = vista.generate(seed=7, size_m=600)
    path = vista.path(city, kind="car", duration=10)
    renderer = vista.Renderer(city, mode="hybrid", size=(640, 480))
    frame = renderer.render(path[0])      # {"rgb": HxWx3 uint8, "depth": HxW float32, ...}
"""

import json as _json

from . import _vista
from ._vista import Pose

#: vista's version (MAJOR.MINOR.PATCH), the same as ``vista --version`` and the Debian package's.
__version__ = _vista.__version__

__all__ = ["City", "Path", "Pose", "Renderer", "Rig", "generate", "load", "path", "load_path", "RenderDataset"]


class City:
    """A city: generated in this process (:func:`generate`) or loaded from a file (:func:`load`).

    Coordinates are world metres (x east, y north, z up): the city frame plus the
    params' origin, as the path CSV and ``cameras.json`` give them.
    """

    def __init__(self, native):
        self._c = native

    @property
    def params(self):
        """The city's parameters as a dict (the canonical JSON stored in its file)."""
        return _json.loads(self._c.params)

    @property
    def paged(self):
        """True when the city was loaded from a paged city directory (DIR.paged)."""
        return self._c.paged

    @property
    def labelled(self):
        """True when the city carries ground-truth labels (the semantic and instance channels)."""
        return self._c.labelled

    def save(self, path):
        """Write the city as a scene file (.osgb), atomically: the bytes of ``vista gen -o path``.

        Raises ValueError naming ``path`` for a bad path (not .osgb, missing folder,
        the city's own file); nothing is left behind on error.
        """
        self._c.save(str(path))

    @property
    def streets(self):
        """The street graph: ``{"nodes": float64 (N, 2) world xy, "edges": structured (a, b, road_class,
        width, lanes, lanes_forward, lanes_backward, maxspeed_kmh)}``."""
        return self._c.streets()

    @property
    def lanes(self):
        """Every driving lane of the street roads (the lane model the OpenDRIVE file is written from):
        structured array (edge, lane, road, x0, y0, x1, y1, width, speed_limit): the lane's centre line
        from (x0, y0) to (x1, y1) in its direction of travel (world metres), its width (m), its speed
        limit (m/s), the street edge, the OpenDRIVE road id and lane id."""
        return self._c.lanes()

    @property
    def buildings(self):
        """The buildings: structured array (x, y, base_z, height, min_height, floors, roof, roof_height,
        footprint_area, osm_id); (x, y) is the footprint's centroid. A loaded city's layout is grown
        again from its parameters (not for a city whose streets came from OpenStreetMap)."""
        return self._c.buildings()

    @property
    def building_footprints(self):
        """The buildings' outer rings: a list of float64 (K, 2) arrays, world xy, counter-clockwise."""
        return self._c.building_footprints()

    @property
    def trees(self):
        """The trees as drawn: structured array (x, y, z, prototype, instance_id); instance_id is the
        id the instance channel gives their pixels."""
        return self._c.trees()

    @property
    def stats(self):
        """The city's counts as ``vista gen --stats`` writes them (a generated city: street nodes and
        edges, blocks, lots, buildings, trees, cars, tiles, triangles, vertices, draw calls; a loaded
        one: what its file carries)."""
        return self._c.stats()

    def opendrive(self):
        """The road network as ASAM OpenDRIVE 1.6 text: the bytes of ``vista gen --xodr``."""
        return self._c.opendrive()

    def __repr__(self):
        p = self.params
        return "City(seed=%s, size_m=%s%s)" % (p.get("seed"), p.get("size_m"), ", paged" if self.paged else "")


def generate(seed=None, size_m=None, params=None, osm=None, osm_buildings=True, **fields):
    """Generate a city (deterministic by its parameters), as ``vista gen`` does.

    seed, size_m and every other keyword are parameters named as in the params file
    (docs/reference/params.md), over ``params`` (a dict, or the path of a JSON params
    file) over the defaults. ``osm``: take streets (and, with ``osm_buildings``,
    buildings) from an OpenStreetMap extract; the city covers the extract unless
    size_m clips it. Raises ValueError naming the parameter and its range.
    """
    merged = {}
    if isinstance(params, dict):
        merged.update(params)
    elif params is not None:
        with open(str(params), "r", encoding="utf-8") as f:
            text = f.read()
        try:
            merged.update(_json.loads(text))
        except ValueError as e:
            raise ValueError("params file '%s': not valid JSON (%s)" % (params, e)) from None
    merged.update(fields)
    if seed is not None:
        merged["seed"] = seed
    if size_m is not None:
        merged["size_m"] = size_m
    return City(_vista.generate(_json.dumps(merged), "" if osm is None else str(osm), bool(osm_buildings),
                                "size_m" in merged))


def load(path):
    """Load a city: a scene file (.osgb) from ``vista gen``, or a paged city directory (DIR.paged:
    every region merged, with the whole street graph). Raises ValueError naming the file."""
    return City(_vista.load(str(path)))


class Path:
    """A walkthrough path: arrays of its samples and ``path[i]`` poses that :meth:`Renderer.render` takes.

    Arrays: ``t`` (N,) seconds, ``position`` (N, 3) world metres (the eye), ``orientation`` (N, 2)
    heading and pitch in radians (heading clockwise from north, pitch above the horizontal), ``heading``, ``pitch``; car
    paths that drive in lanes also ``road``, ``lane``, ``s``, ``t_offset`` (the OpenDRIVE position of
    each sample, as ``vista path --xodr-positions`` writes it), else None.
    """

    def __init__(self, native):
        self._p = native
        a = native.arrays()
        self.t = a["t"]
        self.position = a["position"]
        self.orientation = a["orientation"]
        self.heading = self.orientation[:, 0]
        self.pitch = self.orientation[:, 1]
        self.road = a.get("road")
        self.lane = a.get("lane")
        self.s = a.get("s")
        self.t_offset = a.get("t_offset")

    def __len__(self):
        """The number of samples."""
        return len(self._p)

    def __getitem__(self, i):
        """The pose of sample ``i`` (negative counts from the end)."""
        return self._p.pose(int(i))

    def __iter__(self):
        """The poses of every sample, in order."""
        for i in range(len(self)):
            yield self._p.pose(i)

    def save(self, file):
        """Write the path as ``vista path`` does (CSV: t_s,x_m,y_m,z_m,heading_deg,pitch_deg), atomically."""
        self._p.save(str(file))

    def __repr__(self):
        return "Path(%d samples, %.1f s)" % (len(self), float(self.t[-1]) if len(self) else 0.0)


def path(city, kind="car", seed=1, duration=60.0, dt=1.0 / 30.0, speed=None, yaw_rate_deg=45.0, fly_height=80.0,
         fly_pitch_deg=None, run_up=8.0, route="tour", lht=False):
    """A deterministic walkthrough path along the city's streets, as ``vista path`` makes it.

    kind: "walk" (eye 1.7 m), "car" (eye 1.2 m, in its lane) or "fly"; duration (0, 86400] s; dt (0, 10] s;
    speed (0, 1000] m/s (default: walk 1.4, car and fly 14); yaw_rate_deg (0, 720]; fly_height (0, 10000) m;
    fly_pitch_deg (-90, 90) (default -11.5); run_up 0 .. 600 s driven before t = 0; route "tour" or "wander";
    lht: left-hand traffic (car). Raises ValueError naming the field and its range.
    """
    return Path(_vista.path(city._c, kind, int(seed), float(duration), float(dt),
                            None if speed is None else float(speed), float(yaw_rate_deg), float(fly_height),
                            None if fly_pitch_deg is None else float(fly_pitch_deg), float(run_up), route, bool(lht)))


def load_path(file):
    """Read a path CSV (``vista path -o``): poses without lane positions."""
    return Path(_vista.load_path(str(file)))


class Renderer:
    """Renders frames of a city, as ``vista render`` does: equal poses give equal bytes.

    mode: "full" (every triangle rasterised) or "hybrid" (near field + ray-cast far field with a
    panoramic cache: frames depend on the frames before, as in the command); size: (width, height),
    1 .. 8192 each; fov: vertical field of view in degrees, (1, 179); channels: any of "rgb", "depth",
    "semantic", "instance" (default all, or rgb and depth for a city without labels); near: the
    hybrid's near distance in metres (default 100); effects: run-time effects over the city's
    declared ones (as ``--effects``); threads: worker threads (0 = all). Needs a GL context (a display,
    or Xvfb: ``xvfb-run -a python3 ...``).
    """

    def __init__(self, city, mode="hybrid", size=(640, 480), fov=60.0, channels=None, near=None, effects=None,
                 threads=0):
        if channels is None:
            channels = ("rgb", "depth", "semantic", "instance") if city.labelled else ("rgb", "depth")
        if isinstance(channels, str):
            channels = [c for c in channels.split(",")]
        w, h = size
        self.city = city
        self._r = _vista.Renderer(city._c, mode, int(w), int(h), float(fov), list(channels),
                                  None if near is None else float(near), effects, int(threads))

    @property
    def camera(self):
        """The pinhole intrinsics (width, height, fx, fy, cx, cy, fov_y_deg) as cameras.json gives them."""
        return self._r.camera()

    def render(self, pose):
        """Render one frame at ``pose`` (a :class:`Pose`, e.g. ``path[i]``).

        Returns a dict: "rgb" uint8 (H, W, 3) (a view of the renderer's RGBA rows: no copy), "depth"
        float32 (H, W) metres along the optical axis (+inf = sky), "semantic" uint8 (H, W) classes,
        "instance" uint32 (H, W) ids (classes.json of ``vista render``), "frame_ms" the mode's frame
        time. The GIL is released while the frame renders. A pose outside the city raises ValueError.
        """
        return self._r.render(pose)


class Rig:
    """A sensor rig (the rig file of ``vista render --rig``: cameras, fisheyes, LiDARs, docs/formats.md
    "Sensor rigs") on a city, fired at poses in-process: every sensor cast by Embree rays, as the
    command casts it. threads: worker threads (0 = all). Needs no GL context. Raises ValueError for a
    bad rig file (naming the sensor and field) or a city without labels.
    """

    def __init__(self, city, rig_file, threads=0):
        self.city = city
        self._r = _vista.Rig(city._c, str(rig_file), int(threads))

    @property
    def sensors(self):
        """The sensors' names in rig-file order."""
        return list(self._r.sensors())

    def fire(self, pose, t=None, path=None, flow_dt=None):
        """Fire every sensor with the vehicle at ``pose`` (the rig's vehicle frame: x forward, z up at the
        pose; ``t`` defaults to ``pose.t``).

        Returns a dict by sensor name. A camera: "rgb" uint8 (H, W, 3), "depth" float32 (H, W), "semantic"
        uint8, "instance" uint32, "flow" float32 (H, W, 2), "boxes" a structured array (id, visible pixel box
        u0 v0 u1 v1, pixels, visible_fraction, truncated, 3D box centre x y z, length, width, height, yaw in
        the world), each as its channels ask. A LiDAR: "points" float32 (N, 4) x, y, z (sensor frame at
        the firing time) and intensity, as KITTI's velodyne files; "time" float32 (N,) seconds since the
        sweep's start; "semantic", "instance", "beam" per point; "misses". Without ``path`` the vehicle
        stands at ``pose`` during the sweep and flow is that of a standing camera; with ``path`` (a
        :class:`Path`) the vehicle moves along it from ``t`` and flow looks ``flow_dt`` seconds ahead
        (default: the path's sample spacing), as ``vista render --rig`` does.
        """
        t = pose.t if t is None else t
        if flow_dt is None:
            flow_dt = float(path.t[1] - path.t[0]) if path is not None and len(path) > 1 else 0.0
        return self._r.fire(pose, float(t), None if path is None else path._p, float(flow_dt))


def __getattr__(name):
    # The Dataset imports torch only when asked for.
    if name == "RenderDataset":
        from .dataset import RenderDataset
        return RenderDataset
    raise AttributeError("module 'vista' has no attribute %r" % name)


