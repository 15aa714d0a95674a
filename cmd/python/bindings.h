// Pieces the Python module's bindings share (module.cpp: cities, paths,
// the renderer; rig.cpp: the sensor rig): errors as ValueError, numpy
// arrays over C++-owned memory, the city and the pose as the bindings hold
// them. Included by the module's sources only.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "citygen/city.h"
#include "foundation/status.h"
#include "runtime/scene/paths.h"
#include "runtime/scene/scene_model.h"

namespace py = pybind11;

namespace vista {

// A failed step's message as a ValueError (bad input: what the CLI reports with exit code 2).
template <class T>
T unwrap(Result<T> r) {
    if (!r) throw py::value_error(r.status().message());
    return std::move(*r);
}
inline void check(const Status& s) {
    if (!s) throw py::value_error(s.message());
}

// A numpy array over `data` (moved to the heap and owned by a capsule: no copy).
template <class T>
py::array_t<T> ownedArray(std::vector<T>&& data, std::vector<py::ssize_t> shape,
                          std::vector<py::ssize_t> strides = {}) {
    auto* owned = new std::vector<T>(std::move(data));
    py::capsule base(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
    if (strides.empty()) return py::array_t<T>(shape, owned->data(), base);
    return py::array_t<T>(shape, strides, owned->data(), base);
}

// A structured array: `fields` (name, numpy format) of `n` records filled by `fill(i, record)`.
inline py::array structured(const std::vector<std::pair<std::string, std::string>>& fields, size_t n,
                            const std::function<void(size_t, py::list&)>& fill) {
    py::list descr;
    for (const auto& [name, fmt] : fields) descr.append(py::make_tuple(name, fmt));
    py::module_ np = py::module_::import("numpy");
    py::object dtype = np.attr("dtype")(descr);
    py::list rows;
    for (size_t i = 0; i < n; ++i) {
        py::list rec;
        fill(i, rec);
        rows.append(py::tuple(rec));
    }
    return np.attr("array")(rows, py::arg("dtype") = dtype);
}

// A city: the decoded scene model every step reads, and for a generated city
// the generated model (its bytes for save(), its buildings and counts).
struct PyCity {
    std::shared_ptr<SceneModel> model;
    std::shared_ptr<City> generated;  // generate(): the whole city; load(): its layout once asked for
    std::string source;               // load(): the file or directory
    bool paged = false;
    bool fromFile() const { return !source.empty(); }
};

// A pose: what one path sample gives a camera.
struct Pose {
    double t = 0;
    glm::dvec3 position{0.0};
    double heading = 0, pitch = 0;
};

// A path as the bindings hold it (vista.Path wraps one).
struct PyPath {
    Path path;
};

// World offset of the city's frame (params origin).
glm::dvec3 originOf(const PyCity& c);

// Declares Rig (rig.cpp) on the module.
void bindRig(py::module_& m);

}  // namespace vista
