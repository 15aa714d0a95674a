// vista.Rig: a sensor rig (the rig file of `vista render --rig`) fired at a
// pose in-process: every camera's channels by one Embree ray per pixel and
// every LiDAR's sweep, as the command casts them (the same library steps),
// returned as numpy arrays instead of files.
#include <memory>
#include <optional>
#include <string>

#include "cmd/options.h"
#include "cmd/python/bindings.h"
#include "runtime/engine/boxes.h"
#include "runtime/engine/lidar.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/engine/rig.h"
#include "runtime/engine/rig_boxes.h"
#include "runtime/engine/rig_camera.h"

namespace vista {
namespace {

class PyRig {
public:
    PyRig(PyCity city, const std::string& rigFile, int threads) : _city(std::move(city)), _threads(threads) {
        _rig = unwrap(loadRigFile(rigFile));
        if (!_city.model->labelled)
            throw py::value_error("city" + (_city.fromFile() ? " '" + _city.source + "'" : std::string()) +
                                  " has no ground-truth labels: a rig's channels need them");
        _fx = unwrap(runTimeEffects(std::nullopt, _city.model->params.effects, true, "vista"));
        py::gil_scoped_release nogil;
        auto rays = RayScene::build(*_city.model);
        py::gil_scoped_acquire gil;
        _rays = unwrap(std::move(rays));
        for (const RigCamera& c : _rig.cameras)
            if (c.channels & kRigBoxes) _wantBoxes = true;
    }

    // Every sensor at the vehicle pose `pose` (time `t`); with `path`, the vehicle moves along it
    // during a LiDAR sweep and a camera's flow looks ahead `flowDt` seconds on it, as in the command.
    py::dict fire(const Pose& pose, double t, const PyPath* path, double flowDt) {
        const RigPose vehicle = vehiclePose(PathSample{t, pose.position, pose.heading, pose.pitch});
        check(_rays->placeFrameNear(vehicle.position));
        if (_wantBoxes && !_boxes) {
            py::gil_scoped_release nogil;
            _boxes = std::make_unique<CityBoxes>(buildCityBoxes(*_city.model, _threads));
        }
        py::dict out;
        for (const RigCamera& c : _rig.cameras) out[py::str(c.name)] = camera(c, vehicle, t, path, flowDt);
        for (const RigLidar& l : _rig.lidars) out[py::str(l.name)] = lidar(l, vehicle, t, path);
        return out;
    }

    py::list sensors() const {
        py::list l;
        for (const std::string& n : _rig.order) l.append(n);
        return l;
    }

private:
    py::dict camera(const RigCamera& c, const RigPose& vehicle, double t, const PyPath* path, double flowDt) {
        CameraShot shot;
        shot.model = c.model;
        shot.pose = sensorPose(vehicle, c.mount);
        shot.channels = c.channels;
        shot.fx = &_fx;
        if (c.channels & kRigFlow)
            shot.next = path ? sensorPose(vehiclePoseAt(path->path, t + flowDt), c.mount) : shot.pose;
        CameraImages im;
        {
            py::gil_scoped_release nogil;
            castRigCamera(*_city.model, *_rays, shot, im, _threads);
        }
        const py::ssize_t h = im.height, w = im.width;
        py::dict d;
        if (c.channels & kRigRgb) d["rgb"] = ownedArray(std::move(im.rgb.rgba), {h, w, 3}, {w * 4, 4, 1});
        if (c.channels & kRigDepth) d["depth"] = ownedArray(std::move(im.depth), {h, w});
        if (c.channels & kRigSemantic) d["semantic"] = ownedArray(std::move(im.classes), {h, w});
        if (c.channels & kRigFlow) d["flow"] = ownedArray(std::move(im.flow), {h, w, 2});
        if (c.channels & kRigBoxes) d["boxes"] = boxes(c, shot.pose, im.ids);
        if (c.channels & kRigInstance) d["instance"] = ownedArray(std::move(im.ids), {h, w});
        return d;
    }

    py::array boxes(const RigCamera& c, const RigPose& pose, const std::vector<uint32_t>& ids) {
        FrameBoxOptions o;
        o.threads = _threads;
        const std::vector<FrameBox> fb = frameBoxes(*_city.model, *_boxes, rigBoxCamera(c.model, pose), ids, o);
        return structured({{"id", "<u4"},
                           {"u0", "<i4"},
                           {"v0", "<i4"},
                           {"u1", "<i4"},
                           {"v1", "<i4"},
                           {"pixels", "<u4"},
                           {"visible_fraction", "<f8"},
                           {"truncated", "<f8"},
                           {"x", "<f8"},
                           {"y", "<f8"},
                           {"z", "<f8"},
                           {"length", "<f8"},
                           {"width", "<f8"},
                           {"height", "<f8"},
                           {"yaw", "<f8"}},
                          fb.size(), [&](size_t i, py::list& r) {
                              const FrameBox& b = fb[i];
                              r.append(b.id), r.append(b.visibleU0), r.append(b.visibleV0), r.append(b.visibleU1);
                              r.append(b.visibleV1), r.append(b.pixels), r.append(b.visibleFraction);
                              r.append(b.truncated), r.append(b.box.center.x), r.append(b.box.center.y);
                              r.append(b.box.center.z), r.append(b.box.size.x), r.append(b.box.size.y);
                              r.append(b.box.size.z), r.append(b.box.yaw);
                          });
    }

    py::dict lidar(const RigLidar& l, const RigPose& vehicle, double t, const PyPath* path) {
        const LidarPoseAt poseAt = [&](double at) {
            return lidarPoseOf(sensorPose(path ? vehiclePoseAt(path->path, at) : vehicle, l.mount));
        };
        LidarSweep sweep;
        {
            py::gil_scoped_release nogil;
            sweep = castLidarSweep(*_city.model, *_rays, l.spec, poseAt, t, _threads);
        }
        const size_t n = sweep.points.size();
        std::vector<float> xyzi(n * 4), time(n);
        std::vector<uint8_t> cls(n);
        std::vector<uint32_t> inst(n);
        std::vector<uint16_t> beam(n);
        for (size_t i = 0; i < n; ++i) {
            const LidarPoint& p = sweep.points[i];
            xyzi[4 * i] = p.sensor.x, xyzi[4 * i + 1] = p.sensor.y, xyzi[4 * i + 2] = p.sensor.z;
            xyzi[4 * i + 3] = p.intensity;
            time[i] = p.time, cls[i] = p.semantic, inst[i] = p.instance, beam[i] = p.beam;
        }
        const py::ssize_t pn = py::ssize_t(n);
        py::dict d;
        d["points"] = ownedArray(std::move(xyzi), {pn, 4});
        d["time"] = ownedArray(std::move(time), {pn});
        d["semantic"] = ownedArray(std::move(cls), {pn});
        d["instance"] = ownedArray(std::move(inst), {pn});
        d["beam"] = ownedArray(std::move(beam), {pn});
        d["misses"] = sweep.misses;
        return d;
    }

    PyCity _city;
    Rig _rig;
    FrameEffects _fx;
    std::unique_ptr<RayScene> _rays;
    std::unique_ptr<CityBoxes> _boxes;
    bool _wantBoxes = false;
    int _threads = 0;
};

}  // namespace

void bindRig(py::module_& m) {
    py::class_<PyRig>(m, "Rig", "A sensor rig fired in-process (see vista.Rig).")
        .def(py::init<PyCity, std::string, int>(), py::arg("city"), py::arg("rig_file"), py::arg("threads"))
        .def("fire", &PyRig::fire, py::arg("pose"), py::arg("t"), py::arg("path"), py::arg("flow_dt"))
        .def("sensors", &PyRig::sensors);
}

}  // namespace vista
