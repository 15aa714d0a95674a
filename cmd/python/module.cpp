// The Python module's native part (`vista._vista`): converts Python
// arguments and calls the library steps that the `vista` command's
// subcommands call (gen, path, render), so that the same arguments give the
// same bytes. Arrays go out as numpy arrays over memory the C++ side
// allocated and hands to a capsule (no copy); bad input raises ValueError
// with the library's message (it names the field, the value and the range).
// The GIL is released while a city is generated and while a frame renders.
#include <cmath>
#include <cstdint>
#include <fstream>
#include <functional>
#include <iterator>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bake/gen/baked_lighting.h"
#include "citygen/blocks.h"
#include "citygen/generate.h"
#include "citygen/lanes.h"
#include "citygen/params.h"
#include "citygen/streets.h"
#include "cmd/options.h"
#include "cmd/render_shared.h"
#include "foundation/atomic_file.h"
#include "foundation/units.h"
#include "foundation/version.h"
#include "nodes/render/ground_truth_session.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/city_opendrive.h"
#include "runtime/scene/paged_load.h"
#include "runtime/scene/paths.h"
#include "runtime/scene/scene_graph.h"
#include "cmd/python/bindings.h"

namespace py = pybind11;

namespace vista {
namespace {

// The laid-out city (streets, blocks, lots, buildings, trees; no meshes) of a
// loaded city, grown again from its parameters (deterministic: the layout the
// file was meshed from). A city whose streets came from OSM cannot be grown again.
const City& layoutOf(PyCity& c) {
    if (c.generated) return *c.generated;
    if (c.model->params.geo)
        throw py::value_error("city '" + c.source +
                              "': its streets came from OpenStreetMap, so its buildings cannot be laid out again "
                              "from its parameters; generate it in this process (vista.generate(osm=...))");
    GenerateOptions o;
    auto layout = std::make_shared<City>();
    o.beforeMeshing = [&](const City& l) {
        *layout = l;
        return Status::error("layout only");
    };
    CityParams p = c.model->params;
    {
        py::gil_scoped_release nogil;
        (void)generateCity(p, o);
    }
    if (layout->streets.nodes.empty() && !c.model->streets.nodes.empty())
        throw py::value_error("city '" + c.source + "': its layout could not be grown again from its parameters");
    c.generated = layout;
    return *c.generated;
}

PyCity generate(const std::string& paramsJson, const std::string& osm, bool osmBuildings, bool sizeGiven) {
    CityParams params = unwrap(parseParamsJson(paramsJson, "params"));
    check(validateParams(params));
    GenerateOptions opts;
    if (!osm.empty()) {
        auto g = unwrap(importOsm(osm, params, osmBuildings, sizeGiven ? OsmExtent::CitySquare : OsmExtent::Extract));
        params.geo = g.geo;
        params.size_m = g.citySize_m;
        opts.streets = std::move(g.streets);
        if (osmBuildings) {
            opts.osmBuildings = std::move(g.buildings);
            opts.osmStats = g.buildingStats;
        }
    }
    check(checkSingleFileSize(params));
    auto city = std::make_shared<City>();
    PyCity out;
    {
        py::gil_scoped_release nogil;
        auto r = generateCity(params, opts);
        if (r) {
            *city = std::move(*r);
            if (bakedLightingCalledFor(params)) {
                BakedLightingStats lighting;
                Status s = bakeLighting(*city, nullptr, lighting);
                if (!s) r = s;
            }
        }
        if (!r) {
            py::gil_scoped_acquire gil;
            throw py::value_error(r.status().message());
        }
    }
    osg::ref_ptr<osg::Node> root = buildCityScene(*city);
    out.model = std::make_shared<SceneModel>(unwrap(decodeCityScene(root.get(), "the generated city")));
    out.generated = city;
    return out;
}

PyCity load(const std::string& path) {
    PyCity out;
    out.source = path;
    if (isPagedCityPath(path)) {
        out.paged = true;
        auto m = unwrap(readPagedManifest(path));
        std::vector<int> regions;
        for (const auto& r : m.regions)
            if (!r.empty) regions.push_back(r.region);
        py::gil_scoped_release nogil;
        auto model = loadPagedCity(m, regions, kMaxPagedRadiusM);
        py::gil_scoped_acquire gil;
        out.model = std::make_shared<SceneModel>(unwrap(std::move(model)));
        // The street graph of the whole city (a merged model carries the regions' own).
        out.model->streets = unwrap(pagedPathStreets(m));
        return out;
    }
    py::gil_scoped_release nogil;
    auto model = loadCityFile(path);
    py::gil_scoped_acquire gil;
    out.model = std::make_shared<SceneModel>(unwrap(std::move(model)));
    return out;
}

void save(const PyCity& c, const std::string& path) {
    if (path.size() < 5 || path.compare(path.size() - 5, 5, ".osgb") != 0)
        throw py::value_error("path = '" + path + "': a city file must end in .osgb");
    if (c.paged) throw py::value_error("city '" + c.source + "' is a paged city directory: it is saved already");
    check(checkWritablePath("path", path));
    if (c.fromFile()) {
        if (c.source == path)
            throw py::value_error("path = '" + path + "': the city's own file (outputs never overwrite an input)");
        std::string bytes;
        {
            std::ifstream in(c.source, std::ios::binary);
            if (!in) throw py::value_error("city file '" + c.source + "': cannot read it again");
            bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
        }
        check(writeFileAtomic(path, bytes));
        return;
    }
    py::gil_scoped_release nogil;
    Status s = writeCityFile(*c.generated, path);
    py::gil_scoped_acquire gil;
    check(s);
}

}  // namespace

glm::dvec3 originOf(const PyCity& c) { return {c.model->params.origin_x, c.model->params.origin_y, 0.0}; }

namespace {

py::dict streets(const PyCity& c) {
    const StreetGraph& g = c.model->streets;
    const glm::dvec3 o = originOf(c);
    std::vector<double> nodes(g.nodes.size() * 2);
    for (size_t i = 0; i < g.nodes.size(); ++i)
        nodes[2 * i] = g.nodes[i].x + o.x, nodes[2 * i + 1] = g.nodes[i].y + o.y;
    py::dict d;
    d["nodes"] = ownedArray(std::move(nodes), {py::ssize_t(g.nodes.size()), 2});
    d["edges"] = structured({{"a", "<u4"},
                             {"b", "<u4"},
                             {"road_class", "u1"},
                             {"width", "<f4"},
                             {"lanes", "u1"},
                             {"lanes_forward", "i1"},
                             {"lanes_backward", "i1"},
                             {"maxspeed_kmh", "<f4"}},
                            g.edges.size(), [&](size_t i, py::list& r) {
                                const StreetEdge& e = g.edges[i];
                                r.append(e.a), r.append(e.b), r.append(int(e.cls)), r.append(e.width);
                                r.append(int(e.lanes)), r.append(int(e.lanesForward)), r.append(int(e.lanesBackward));
                                r.append(e.maxspeedKmh);
                            });
    return d;
}

// One record per driving lane of every street road: its centre line in the direction of travel.
py::array lanes(PyCity& c) {
    // The blocks decide the sidewalk sides (and so the junction trims): derived from the street
    // graph as the OpenDRIVE writer derives them for a loaded city (city_opendrive.h).
    const std::vector<Block> blocks = extractBlocks(c.model->streets, c.model->params, nullptr);
    const LaneModel m = buildLaneModel(c.model->streets, c.model->params, &blocks);
    const glm::dvec3 o = originOf(c);
    struct Row {
        uint32_t edge;
        int lane;
        uint64_t road;
        glm::dvec2 p0, p1;
        double width, speed;
    };
    std::vector<Row> rows;
    for (uint32_t e = 0; e < m.edges.size(); ++e) {
        const EdgeLanes& L = m.edges[e];
        if (!L.valid) continue;
        const uint64_t road = streetRoadId(m, e);
        for (int id = -L.right; id <= L.left; ++id) {
            if (id == 0) continue;
            const glm::dvec2 off = L.normal() * L.laneCentre(id);
            glm::dvec2 a = L.start + off, b = L.end + off;
            if (id > 0) std::swap(a, b);  // left lanes drive b -> a
            rows.push_back({e, id, road, a, b, L.laneWidth, L.speedKmh / 3.6});
        }
    }
    return structured({{"edge", "<u4"},
                       {"lane", "<i4"},
                       {"road", "<u8"},
                       {"x0", "<f8"},
                       {"y0", "<f8"},
                       {"x1", "<f8"},
                       {"y1", "<f8"},
                       {"width", "<f8"},
                       {"speed_limit", "<f8"}},
                      rows.size(), [&](size_t i, py::list& r) {
                          const Row& w = rows[i];
                          r.append(w.edge), r.append(w.lane), r.append(w.road);
                          r.append(w.p0.x + o.x), r.append(w.p0.y + o.y), r.append(w.p1.x + o.x),
                              r.append(w.p1.y + o.y);
                          r.append(w.width), r.append(w.speed);
                      });
}

py::array buildings(PyCity& c) {
    const City& city = layoutOf(c);
    const glm::dvec3 o = originOf(c);
    return structured({{"x", "<f8"},
                       {"y", "<f8"},
                       {"base_z", "<f8"},
                       {"height", "<f8"},
                       {"min_height", "<f8"},
                       {"floors", "<i4"},
                       {"roof", "u1"},
                       {"roof_height", "<f8"},
                       {"footprint_area", "<f8"},
                       {"osm_id", "<i8"}},
                      city.buildings.size(), [&](size_t i, py::list& r) {
                          const Building& b = city.buildings[i];
                          glm::dvec2 centre(0.0);
                          double area2 = 0;
                          const auto& ring = b.footprint;
                          for (size_t k = 0; k < ring.size(); ++k) {
                              const glm::dvec2 p = ring[k], q = ring[(k + 1) % ring.size()];
                              const double cr = p.x * q.y - q.x * p.y;
                              area2 += cr;
                              centre += (p + q) * cr;
                          }
                          if (std::abs(area2) > 0) centre /= 3.0 * area2;
                          r.append(centre.x + o.x), r.append(centre.y + o.y), r.append(b.base_z);
                          r.append(b.height), r.append(b.min_height), r.append(b.floors), r.append(int(b.roof));
                          r.append(b.roof_height), r.append(0.5 * std::abs(area2)), r.append(b.osm_id);
                      });
}

py::list buildingFootprints(PyCity& c) {
    const City& city = layoutOf(c);
    const glm::dvec3 o = originOf(c);
    py::list out;
    for (const Building& b : city.buildings) {
        std::vector<double> v(b.footprint.size() * 2);
        for (size_t k = 0; k < b.footprint.size(); ++k)
            v[2 * k] = b.footprint[k].x + o.x, v[2 * k + 1] = b.footprint[k].y + o.y;
        out.append(ownedArray(std::move(v), {py::ssize_t(b.footprint.size()), 2}));
    }
    return out;
}

// The trees as the scene draws them (instances of the tree prototypes, world frame).
py::array trees(const PyCity& c) {
    const auto& in = c.model->instances;
    return structured({{"x", "<f8"}, {"y", "<f8"}, {"z", "<f8"}, {"prototype", "<u4"}, {"instance_id", "<u4"}},
                      in.size(), [&](size_t i, py::list& r) {
                          const glm::dvec4 t = in[i].transform[3];
                          r.append(t.x), r.append(t.y), r.append(t.z), r.append(in[i].prototype), r.append(in[i].id);
                      });
}

py::dict stats(PyCity& c) {
    py::dict d;
    const CityParams& p = c.model->params;
    d["seed"] = p.seed;
    d["size_m"] = p.size_m;
    d["detail"] = p.detail;
    if (c.generated && !c.fromFile()) {
        const CityCounts n = countCity(*c.generated);
        d["street_nodes"] = n.streetNodes, d["street_edges"] = n.streetEdges, d["blocks"] = n.blocks;
        d["lots"] = n.lots, d["buildings"] = n.buildings, d["trees"] = n.trees;
        d["cars"] = c.generated->cars.size(), d["tiles"] = c.generated->tiles.size();
        d["triangles"] = n.triangles, d["stored_triangles"] = n.storedTriangles, d["vertices"] = n.vertices;
        d["draw_calls"] = n.drawCalls;
    } else {
        d["street_nodes"] = c.model->streets.nodes.size(), d["street_edges"] = c.model->streets.edges.size();
        d["tiles"] = c.model->tiles.size(), d["triangles"] = c.model->triangles;
    }
    return d;
}

std::string opendrive(const PyCity& c) {
    return unwrap(cityOpenDrive(*c.model, c.fromFile() ? c.source : "the generated city"));
}

PyPath makePath(const PyCity& c, const std::string& kind, uint64_t seed, double duration, double dt,
                std::optional<double> speed, double yawRateDeg, double flyHeight, std::optional<double> flyPitchDeg,
                double runUp, const std::string& route, bool lht) {
    PathOptions o;
    o.seed = seed;
    auto k = parsePathKind(kind);
    if (!k) throw py::value_error("kind: " + k.status().message());
    o.kind = *k;
    check(checkLeftHandTraffic(lht, o.kind));
    o.leftHandTraffic = lht;
    o.duration = duration;
    o.dt = dt;
    o.runUp = runUp;
    o.maxSpeed = speed ? *speed : defaultSpeed(o.kind);
    auto r = parseRouteStyle(route);
    if (!r) throw py::value_error("route: " + r.status().message());
    o.route = *r;
    o.maxYawRate = yawRateDeg * kPi / 180.0;
    o.flyHeight = flyHeight;
    // The default goes through degrees as `vista path` does (the same bits).
    const double pitchDeg = flyPitchDeg ? *flyPitchDeg : o.flyPitch * 180.0 / kPi;
    o.flyPitch = pitchDeg * kPi / 180.0;
    check(validatePathOptions(o));
    PyPath p;
    py::gil_scoped_release nogil;
    auto g = generatePath(c.model->streets, c.model->params, o);
    py::gil_scoped_acquire gil;
    p.path = unwrap(std::move(g));
    return p;
}

py::dict pathArrays(const PyPath& p) {
    const auto& s = p.path.samples;
    const py::ssize_t n = py::ssize_t(s.size());
    std::vector<double> t(s.size()), pos(s.size() * 3), ori(s.size() * 2);
    for (size_t i = 0; i < s.size(); ++i) {
        t[i] = s[i].t;
        pos[3 * i] = s[i].position.x, pos[3 * i + 1] = s[i].position.y, pos[3 * i + 2] = s[i].position.z;
        ori[2 * i] = s[i].heading, ori[2 * i + 1] = s[i].pitch;
    }
    py::dict d;
    d["t"] = ownedArray(std::move(t), {n});
    d["position"] = ownedArray(std::move(pos), {n, 3});
    d["orientation"] = ownedArray(std::move(ori), {n, 2});
    if (p.path.lanes.size() == s.size()) {
        std::vector<uint64_t> road(s.size());
        std::vector<int32_t> lane(s.size());
        std::vector<double> ss(s.size()), to(s.size());
        for (size_t i = 0; i < s.size(); ++i) {
            const LanePosition& l = p.path.lanes[i];
            road[i] = l.road, lane[i] = l.lane, ss[i] = l.s, to[i] = l.tOffset;
        }
        d["road"] = ownedArray(std::move(road), {n});
        d["lane"] = ownedArray(std::move(lane), {n});
        d["s"] = ownedArray(std::move(ss), {n});
        d["t_offset"] = ownedArray(std::move(to), {n});
    }
    return d;
}

// The channels a renderer draws.
enum Channel : unsigned { kRgb = 1, kDepth = 2, kSemantic = 4, kInstance = 8 };

class Renderer {
public:
    Renderer(PyCity city, const std::string& mode, int width, int height, double fov,
             const std::vector<std::string>& channels, std::optional<double> nearM, std::optional<std::string> effects,
             int threads)
        : _city(std::move(city)) {
        if (mode != "full" && mode != "hybrid")
            throw py::value_error("mode = '" + mode + "': ground truth is rendered in full or hybrid");
        if (!checkImageSize(width, height))
            throw py::value_error("size = (" + std::to_string(width) + ", " + std::to_string(height) +
                                  "): each side 1 .. " + std::to_string(kMaxImageSide) + " pixels");
        if (!checkFov(fov))
            throw py::value_error("fov = " + std::to_string(fov) + ": the vertical field of view in degrees, (" +
                                  std::to_string(int(kMinFovDeg)) + ", " + std::to_string(int(kMaxFovDeg)) + ")");
        for (const std::string& c : channels) {
            const unsigned bit = c == "rgb"        ? kRgb
                                 : c == "depth"    ? kDepth
                                 : c == "semantic" ? kSemantic
                                 : c == "instance" ? kInstance
                                                   : 0u;
            if (!bit)
                throw py::value_error("channels: unknown channel '" + c + "' (known: rgb, depth, semantic, instance)");
            if (_channels & bit) throw py::value_error("channels: channel '" + c + "' given twice");
            _channels |= bit;
        }
        if (!_channels) throw py::value_error("channels: give at least one of rgb, depth, semantic, instance");
        const bool labels = (_channels & (kDepth | kSemantic | kInstance)) != 0;
        if ((_channels & (kSemantic | kInstance)) && !_city.model->labelled)
            throw py::value_error(std::string("city ") + (_city.fromFile() ? "'" + _city.source + "'" : "") +
                                  " has no ground-truth labels" +
                                  (_city.paged ? " (a paged city's merged model carries none): channels rgb, depth"
                                               : ": regenerate it with this version"));
        ModeFlags flags;
        flags.threads = threads;
        if (nearM) flags.near = std::to_string(*nearM);
        GroundTruthSetup g;
        check(parseModeFlags(flags, g.options));
        if (nearM) g.options.nearDistance = *nearM;
        // Ground truth follows no timing (as `vista render`): no adaptive pauses, a fixed split.
        g.options.cacheAdaptive = false;
        g.options.horizonAdaptive = false;
        if (g.options.nearDistance < 0) g.options.nearDistance = kDefaultNearDistance;
        g.options.effects = unwrap(runTimeEffects(effects, _city.model->params.effects, true, "vista"));
        g.mode = mode;
        g.width = width;
        g.height = height;
        g.labels = labels;
        _base.width = width;
        _base.height = height;
        _base.fovY = degToRad(fov);
        _threads = threads;
        py::gil_scoped_release nogil;
        Status s = _session.setUp(g, *_city.model);
        py::gil_scoped_acquire gil;
        check(s);
    }

    py::dict render(const Pose& pose) {
        Path one;
        one.samples.push_back({pose.t, pose.position, pose.heading, pose.pitch});
        check(checkPathInCity(one, *_city.model));
        const Camera cam = one.camera(0, _base);
        FrameStats st;
        LabelCosts costs;
        Status s;
        {
            py::gil_scoped_release nogil;
            s = _session.renderFrame(cam, _b, st);
            if (s && (_channels & ~unsigned(kRgb))) s = _session.renderLabels(cam, _threads, _b, costs);
        }
        check(s);
        const py::ssize_t h = _base.height, w = _base.width;
        py::dict out;
        if (_channels & kRgb) {
            // A view of the renderer's RGBA rows: rgb without a copy (strides skip alpha).
            out["rgb"] = ownedArray(std::move(_b.img.rgba), {h, w, 3}, {w * 4, 4, 1});
            _b.img = Image();
        }
        if (_channels & kDepth) out["depth"] = ownedArray(std::move(_b.gt.depth), {h, w});
        if (_channels & kSemantic) out["semantic"] = ownedArray(std::move(_b.gt.classes), {h, w});
        if (_channels & kInstance) out["instance"] = ownedArray(std::move(_b.gt.ids), {h, w});
        if (_channels & ~unsigned(kRgb)) _b.gt = LabelImage();
        out["frame_ms"] = st.frameMs;
        return out;
    }

    py::dict camera() const {
        const double fy = 0.5 * _base.height / std::tan(0.5 * _base.fovY);
        py::dict d;
        d["width"] = _base.width, d["height"] = _base.height, d["fx"] = fy, d["fy"] = fy;
        d["cx"] = 0.5 * (_base.width - 1), d["cy"] = 0.5 * (_base.height - 1);
        d["fov_y_deg"] = radToDeg(_base.fovY);
        return d;
    }

private:
    PyCity _city;  // holds the model the session draws
    GroundTruthSession _session;
    GroundTruthBuffers _b;
    Camera _base;
    unsigned _channels = 0;
    int _threads = 0;
};

}  // namespace
}  // namespace vista

PYBIND11_MODULE(_vista, m) {
    using namespace vista;
    m.doc() =
        "Native part of the vista module: the library steps behind `vista gen`, `vista path` and "
        "`vista render`. Use the `vista` package, which wraps these.";
    m.attr("__version__") = vista::version();
    py::class_<PyCity>(m, "City", "A generated or loaded city (see vista.City).")
        .def_property_readonly("paged", [](const PyCity& c) { return c.paged; })
        .def_property_readonly("source", [](const PyCity& c) { return c.source; })
        .def_property_readonly("params", [](const PyCity& c) { return paramsToJson(c.model->params); })
        .def_property_readonly("labelled", [](const PyCity& c) { return c.model->labelled; })
        .def("save", &save, py::arg("path"))
        .def("streets", &streets)
        .def("lanes", &lanes)
        .def("buildings", &buildings)
        .def("building_footprints", &buildingFootprints)
        .def("trees", &trees)
        .def("stats", &stats)
        .def("opendrive", &opendrive);
    py::class_<Pose>(m, "Pose",
                     "A camera pose: time t (s), world position (metres: x east, y north, z up), heading (radians "
                     "clockwise from north) and pitch (radians above the horizontal).")
        .def(py::init([](std::vector<double> position, double heading, double pitch, double t) {
                 if (position.size() != 3) throw py::value_error("position: give x, y, z (metres, world frame)");
                 return Pose{t, {position[0], position[1], position[2]}, heading, pitch};
             }),
             py::arg("position"), py::arg("heading") = 0.0, py::arg("pitch") = 0.0, py::arg("t") = 0.0)
        .def_property_readonly("t", [](const Pose& p) { return p.t; })
        .def_property_readonly("position",
                               [](const Pose& p) { return py::make_tuple(p.position.x, p.position.y, p.position.z); })
        .def_property_readonly("heading", [](const Pose& p) { return p.heading; })
        .def_property_readonly("pitch", [](const Pose& p) { return p.pitch; })
        .def("__repr__", [](const Pose& p) {
            char b[200];
            std::snprintf(b, sizeof b, "Pose(position=(%.3f, %.3f, %.3f), heading=%.6f, pitch=%.6f, t=%.4f)",
                          p.position.x, p.position.y, p.position.z, p.heading, p.pitch, p.t);
            return std::string(b);
        });
    py::class_<PyPath>(m, "Path", "A walkthrough path (see vista.Path).")
        .def("__len__", [](const PyPath& p) { return p.path.samples.size(); })
        .def("pose",
             [](const PyPath& p, long i) {
                 const long n = long(p.path.samples.size());
                 if (i < 0) i += n;
                 if (i < 0 || i >= n) throw py::index_error("path index out of range");
                 const PathSample& s = p.path.samples[size_t(i)];
                 return Pose{s.t, s.position, s.heading, s.pitch};
             })
        .def("arrays", &pathArrays)
        .def_property_readonly(
            "lanes_missing", [](const PyPath& p) { return p.path.lanes.empty() ? p.path.lanesMissing : std::string(); })
        .def("save", [](const PyPath& p, const std::string& file) {
            check(checkWritablePath("path", file));
            check(savePathCsv(p.path, file));
        });
    m.def("generate", &generate, py::arg("params_json"), py::arg("osm"), py::arg("osm_buildings"),
          py::arg("size_given"));
    m.def("load", &load, py::arg("path"));
    m.def(
        "load_path", [](const std::string& file) { return PyPath{unwrap(loadPathCsv(file))}; }, py::arg("file"));
    m.def("path", &makePath, py::arg("city"), py::arg("kind"), py::arg("seed"), py::arg("duration"), py::arg("dt"),
          py::arg("speed"), py::arg("yaw_rate_deg"), py::arg("fly_height"), py::arg("fly_pitch_deg"), py::arg("run_up"),
          py::arg("route"), py::arg("lht"));
    py::class_<Renderer>(m, "Renderer", "Ground-truth renderer (see vista.Renderer).")
        .def(py::init<PyCity, std::string, int, int, double, std::vector<std::string>, std::optional<double>,
                      std::optional<std::string>, int>(),
             py::arg("city"), py::arg("mode"), py::arg("width"), py::arg("height"), py::arg("fov"), py::arg("channels"),
             py::arg("near"), py::arg("effects"), py::arg("threads"))
        .def("render", &Renderer::render, py::arg("pose"))
        .def("camera", &Renderer::camera);
    bindRig(m);
}
