// RayScene: Embree 3 scene of a loaded city (see ray_scene.h for the contract).
//
// Layout (regions): a top-level RTCScene holding one instance per region
// (a translation onto the region's own scene of tile meshes, vertices relative
// to the region origin) and one instance per tree (onto its prototype's
// scene). Embree here traverses one instance level, so trees cannot sit
// inside a region scene: a region's trees are its instances in the top level.
// Layout (flat): one triangle geometry per tile mesh in the top-level scene
// (vertices around frameOrigin), trees as above.
// Hit colours: barycentric interpolation of the prelit vertex colours, rounded
// to 8 bits exactly as the fixed-function rasteriser does; the colours are kept
// per triangle (primID -> its three corners), so a hit costs one memory fetch
// (docs/measurements/raw-rays.md: the colour fetch was the wrapper's largest cost).
// A soup scene: one triangle geometry on a device shared by all soup scenes
// (so the bake does not create a device per impostor); no robust flag.
// Moving objects (placeMovers): instances in a scene of their own beside the
// top level, committed per frame; the top level of regions and trees (often
// thousands of instances) is never rebuilt for them. Every query traces the
// top level first and then, when objects are placed, the movers' scene with
// the far limit at the first hit: the nearer hit wins (the top level's at an
// equal distance), occlusion is either. A mover's hit carries its instance
// id in the movers' scene with kMoverInstBit set, so hit ids (SurfaceKey)
// never collide with the top level's.
#include "runtime/engine/ray_scene.h"

#include "runtime/engine/ray_packet.h"

#include <embree3/rtcore.h>
#include <glm/gtc/matrix_transform.hpp>
#include <pmmintrin.h>
#include <xmmintrin.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <mutex>
#include <string>
#include <vector>

namespace vista {

namespace {

void enableFtzDaz() {
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
}

const char* embreeErrorName(RTCError e) {
    switch (e) {
        case RTC_ERROR_NONE: return "none";
        case RTC_ERROR_UNKNOWN: return "unknown";
        case RTC_ERROR_INVALID_ARGUMENT: return "invalid argument";
        case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
        case RTC_ERROR_OUT_OF_MEMORY: return "out of memory";
        case RTC_ERROR_UNSUPPORTED_CPU: return "unsupported CPU";
        case RTC_ERROR_CANCELLED: return "cancelled";
    }
    return "?";
}

struct ErrorSink {
    std::mutex mutex;
    std::string first;  // first error message reported by the device
};

void errorCallback(void* userPtr, RTCError code, const char* str) {
    auto* sink = static_cast<ErrorSink*>(userPtr);
    std::lock_guard<std::mutex> lock(sink->mutex);
    if (sink->first.empty())
        sink->first = std::string("Embree error (") + embreeErrorName(code) + "): " + (str ? str : "");
}

// The prelit colours of a triangle's corners, stored per triangle: a hit
// reads one 12-byte record instead of an index and then three vertex colours
// (one dependent cache miss instead of two on a large city).
struct TriColors {
    glm::u8vec4 c[3];
};

// Marks RayHit::instId of a hit in the movers' scene (never a top-level id:
// Embree's ids are dense from 0).
constexpr uint32_t kMoverInstBit = 0x80000000u;

std::vector<TriColors> triangleColors(const std::vector<glm::u8vec4>& colors, const std::vector<uint32_t>& indices) {
    std::vector<TriColors> t(indices.size() / 3);
    for (size_t i = 0; i < t.size(); ++i)
        for (int k = 0; k < 3; ++k) t[i].c[k] = colors[indices[3 * i + size_t(k)]];
    return t;
}

// Colour of a hit: barycentric interpolation, rounded like GL's unorm
// conversion (half away from zero, as std::lround, for c in [0, 255]:
// c - trunc(c) is exact there).
glm::u8vec4 interpolateColor(const std::vector<TriColors>& tris, uint32_t prim, float u, float v) {
    if (prim >= tris.size()) return {255, 0, 255, 255};  // cannot happen for a valid scene
    const TriColors& t = tris[prim];
    float w = 1.0f - u - v;
    glm::u8vec4 out;
    for (int k = 0; k < 4; ++k) {
        float c = w * float(t.c[0][k]) + u * float(t.c[1][k]) + v * float(t.c[2][k]);
        c = std::min(255.0f, std::max(0.0f, c));
        const int r = int(c);
        out[k] = uint8_t(r + (c - float(r) >= 0.5f ? 1 : 0));
    }
    return out;
}

// Back-face culling, as the rasteriser does (the city's root state set enables
// CullFace BACK; triangles are counter-clockwise seen from outside, which is
// Embree's Ng = (v1 - v0) x (v2 - v0) side). Runs for intersect and occluded
// queries; for instances both Ng and the ray are in object space.
void cullBackFaces(const RTCFilterFunctionNArguments* args) {
    int* valid = args->valid;
    for (unsigned i = 0; i < args->N; ++i) {
        if (valid[i] != -1) continue;
        float nx = RTCHitN_Ng_x(args->hit, args->N, i), ny = RTCHitN_Ng_y(args->hit, args->N, i),
              nz = RTCHitN_Ng_z(args->hit, args->N, i);
        float dx = RTCRayN_dir_x(args->ray, args->N, i), dy = RTCRayN_dir_y(args->ray, args->N, i),
              dz = RTCRayN_dir_z(args->ray, args->N, i);
        if (nx * dx + ny * dy + nz * dz >= 0.0f) valid[i] = 0;
    }
}

// The tree prototypes of one SceneModel: one child scene each (null when empty).
struct PrototypeSet {
    std::vector<RTCScene> scenes;
    std::vector<std::vector<TriColors>> colors;  // per prototype, per triangle
    std::vector<size_t> triangles;
    PrototypeSet() = default;
    PrototypeSet(const PrototypeSet&) = delete;
    PrototypeSet& operator=(const PrototypeSet&) = delete;
    ~PrototypeSet() {
        for (RTCScene s : scenes)
            if (s) rtcReleaseScene(s);
    }
};

// Column-major 3x4 float matrix of `xf` with `shift` subtracted from its translation (defined below).
void embreeTransform(const glm::dmat4& xf, const glm::dvec3& shift, float m[12]);

}  // namespace

struct RayScene::Impl {
    RTCDevice device = nullptr;
    bool ftz = true;       // set FTZ/DAZ on casting threads (city scenes)
    bool city = false;     // a city scene (regions may be added)
    bool flat = false;     // flat layout (no regions)
    bool compact = false;  // setCompactRegions
    RTCScene scene = nullptr;
    ErrorSink errors;
    glm::dvec3 origin{0.0};
    glm::dvec3 buildOrigin{0.0};  // the origin the scene was built around
    size_t triangles = 0;

    // A triangle geometry of the flat layout or of a region scene.
    struct MeshInfo {
        int sceneMesh = -1;  // index into the model's meshes (-1: soup)
        std::vector<TriColors> colors;
    };
    // One region: its scene and what it put into the top level.
    struct Region {
        bool live = false;
        RTCScene scene = nullptr;  // null when the region has no tile mesh
        unsigned topId = RTC_INVALID_GEOMETRY_ID;
        std::vector<unsigned> treeIds;  // its tree instances in the top level
        std::vector<MeshInfo> meshes;   // per geomID of `scene`
        std::shared_ptr<PrototypeSet> protos;
        glm::dvec3 origin{0.0};
        size_t triangles = 0;
    };
    // Per top-level geometry id: what it is.
    struct TopGeom {
        enum class Kind { None, Mesh, Region, Tree, Mover } kind = Kind::None;
        int index = -1;  // Mesh: flatMeshes; Region / Tree: regions (Tree: -1 in the flat layout)
        int prototype = -1;
        int instance = -1;  // Tree: index into the model's instances, or
        int impostor = -1;  // into its impostors
        const PrototypeSet* protos = nullptr;
        glm::mat3 normalMatrix{1.0f};
        glm::dmat4 transform{1.0};  // Tree, Mover: prototype frame -> world; Region: translation to its origin
        uint32_t moverId = 0;       // Mover: its label (instance: its index in the last placeMovers)
        uint8_t moverClass = 0;
        int still = -1;  // Mover: its still slot (then instance is -1), or -1 for a moving one
    };
    std::vector<TopGeom> geoms;
    std::vector<MeshInfo> flatMeshes;
    std::shared_ptr<PrototypeSet> flatProtos;  // trees of the flat layout
    std::vector<unsigned> flatTreeIds;
    std::vector<Region> regions;
    std::shared_ptr<PrototypeSet> moverProtos;  // setMoverPrototypes
    std::vector<glm::dvec4> moverBounds;        // per prototype: bounding sphere in its frame
    std::vector<glm::dvec4> moverSpheres;       // per placed object: world bounding sphere
    RTCScene movers = nullptr;                  // the movers' scene (setMoverPrototypes makes it)
    std::vector<TopGeom> moverTops;             // per geometry id of `movers`
    std::vector<unsigned> moverGeoms;           // the pool of mover instances (ids in `movers`)
    size_t moversLive = 0;
    bool moversOn = false;  // some mover instance is enabled: queries trace `movers` too
    // Still objects (placeMovers' `still` list): per slot what it shows, its instance in
    // `movers` and its state for the far field's cache.
    std::vector<StillPlacement> stills;
    std::vector<unsigned> stillGeoms;
    std::vector<StillState> stillStates;
    uint64_t stillSerial = 0;
    size_t stillsOn = 0;  // slots whose instance is enabled
    uint64_t moverCommits = 0;

    // A new instance geometry in `movers` (disabled until placed); returns its id.
    unsigned newMoverInstance() {
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
        rtcSetGeometryTimeStepCount(g, 1);
        const unsigned id = rtcAttachGeometry(movers, g);
        rtcReleaseGeometry(g);
        rtcDisableGeometry(rtcGetGeometry(movers, id));
        if (moverTops.size() <= id) moverTops.resize(size_t(id) + 1);
        return id;
    }
    // Shows prototype p.prototype at p.transform on instance `id` of `movers`; false (and the
    // instance disabled) for an empty prototype. Labels and bookkeeping in moverTops[id].
    bool placeMoverInstance(unsigned id, const MoverPlacement& p, int instance, int still) {
        RTCScene child = moverProtos->scenes[p.prototype];
        RTCGeometry g = rtcGetGeometry(movers, id);
        TopGeom& tg = moverTops[id];
        if (!child) {  // an empty prototype: nothing to hit
            rtcDisableGeometry(g);
            tg.kind = TopGeom::Kind::None;
            return false;
        }
        if (tg.kind != TopGeom::Kind::Mover || tg.prototype != int(p.prototype) || tg.protos != moverProtos.get())
            rtcSetGeometryInstancedScene(g, child);
        float m[12];
        embreeTransform(p.transform, origin, m);
        rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, m);
        rtcEnableGeometry(g);
        rtcCommitGeometry(g);
        tg.kind = TopGeom::Kind::Mover;
        tg.index = -1;
        tg.prototype = int(p.prototype);
        tg.instance = instance;
        tg.still = still;
        tg.protos = moverProtos.get();
        tg.transform = p.transform;
        tg.normalMatrix = glm::transpose(glm::inverse(glm::mat3(glm::dmat3(p.transform))));
        tg.moverId = p.id;
        tg.moverClass = p.cls;
        return true;
    }
    glm::dvec4 worldSphere(const MoverPlacement& p) const {
        const glm::dvec4 b = moverBounds[p.prototype];
        return glm::dvec4(glm::dvec3(p.transform * glm::dvec4(glm::dvec3(b), 1.0)), b.w);
    }

    ~Impl() {
        for (Region& r : regions)
            if (r.scene) rtcReleaseScene(r.scene);
        if (movers) rtcReleaseScene(movers);
        if (scene) rtcReleaseScene(scene);
        regions.clear();
        flatProtos.reset();
        if (device) rtcReleaseDevice(device);
    }

    Status checkDevice(const char* what) {
        RTCError e = rtcGetDeviceError(device);
        std::lock_guard<std::mutex> lock(errors.mutex);
        if (!errors.first.empty()) return Status::error(std::string("ray scene: ") + what + ": " + errors.first);
        if (e != RTC_ERROR_NONE)
            return Status::error(std::string("ray scene: ") + what + ": Embree error " + embreeErrorName(e));
        return Status::ok();
    }

    TopGeom& top(unsigned id) {
        if (geoms.size() <= id) geoms.resize(size_t(id) + 1);
        return geoms[id];
    }

    // What instance id `instID` (RTC_INVALID_GEOMETRY_ID: none) of a hit names:
    // a mover (kMoverInstBit) or a top-level geometry; null when out of range.
    const TopGeom* instanceOf(unsigned instID) const {
        if (instID == RTC_INVALID_GEOMETRY_ID) return nullptr;
        if (instID & kMoverInstBit) {
            const unsigned m = instID & ~kMoverInstBit;
            return m < moverTops.size() ? &moverTops[m] : nullptr;
        }
        return instID < geoms.size() ? &geoms[instID] : nullptr;
    }

    // The mesh a hit of (geomID, instID) struck, or null for a tree or a mover.
    const MeshInfo* meshOf(unsigned geomID, unsigned instID) const {
        if (instID != RTC_INVALID_GEOMETRY_ID && (instID & kMoverInstBit)) return nullptr;
        const unsigned t = instID != RTC_INVALID_GEOMETRY_ID ? instID : geomID;
        if (t >= geoms.size()) return nullptr;
        const TopGeom& g = geoms[t];
        if (g.kind == TopGeom::Kind::Mesh) return &flatMeshes[size_t(g.index)];
        if (g.kind == TopGeom::Kind::Region) {
            const Region& r = regions[size_t(g.index)];
            return geomID < r.meshes.size() ? &r.meshes[geomID] : nullptr;
        }
        return nullptr;
    }
    const std::vector<TriColors>* colorsOf(unsigned geomID, unsigned instID, const TopGeom** tree) const {
        *tree = nullptr;
        if (const MeshInfo* m = meshOf(geomID, instID)) return &m->colors;
        const TopGeom* g = instanceOf(instID);
        if (!g || (g->kind != TopGeom::Kind::Tree && g->kind != TopGeom::Kind::Mover)) return nullptr;
        *tree = g;
        return &g->protos->colors[size_t(g->prototype)];
    }

    // One ray: the top level, then the movers nearer than its hit. rh as
    // rtcIntersect1 leaves it; a mover's hit has kMoverInstBit in instID[0].
    void intersect1(RTCIntersectContext& ctx, RTCRayHit& rh) const {
        rtcIntersect1(scene, &ctx, &rh);
        if (!moversOn) return;
        RTCRayHit m = rh;
        m.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        m.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(movers, &ctx, &m);
        if (m.hit.geomID == RTC_INVALID_GEOMETRY_ID || !(m.ray.tfar < rh.ray.tfar)) return;
        m.hit.instID[0] |= kMoverInstBit;
        rh = m;
    }
    // A packet of 8, as intersect1 per lane.
    void intersect8(const int* valid, RTCIntersectContext& ctx, RTCRayHit8& rh) const {
        rtcIntersect8(valid, scene, &ctx, &rh);
        if (!moversOn) return;
        alignas(32) RTCRayHit8 m;
        m.ray = rh.ray;  // tfar: the top level's hit where there is one
        for (int k = 0; k < 8; ++k) {
            m.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
            m.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
        }
        rtcIntersect8(valid, movers, &ctx, &m);
        for (int k = 0; k < 8; ++k) {
            if (!valid[k] || m.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID || !(m.ray.tfar[k] < rh.ray.tfar[k])) continue;
            rh.ray.tfar[k] = m.ray.tfar[k];
            rh.hit.Ng_x[k] = m.hit.Ng_x[k];
            rh.hit.Ng_y[k] = m.hit.Ng_y[k];
            rh.hit.Ng_z[k] = m.hit.Ng_z[k];
            rh.hit.u[k] = m.hit.u[k];
            rh.hit.v[k] = m.hit.v[k];
            rh.hit.primID[k] = m.hit.primID[k];
            rh.hit.geomID[k] = m.hit.geomID[k];
            rh.hit.instID[0][k] = m.hit.instID[0][k] | kMoverInstBit;
        }
    }
    // Occlusion of one ray: the top level, then (not occluded there) the movers.
    void occluded1(RTCIntersectContext& ctx, RTCRay& r) const {
        rtcOccluded1(scene, &ctx, &r);
        if (moversOn && !(r.tfar < 0.0f)) rtcOccluded1(movers, &ctx, &r);
    }
    // A packet of 8, as occluded1 per lane (valid: the lanes to test; changed).
    void occluded8(int* valid, RTCIntersectContext& ctx, RTCRay8& r) const {
        rtcOccluded8(valid, scene, &ctx, &r);
        if (!moversOn) return;
        alignas(32) int rest[8];
        bool any = false;
        for (int k = 0; k < 8; ++k) {
            rest[k] = valid[k] && !(r.tfar[k] < 0.0f) ? -1 : 0;
            any = any || rest[k];
        }
        if (any) rtcOccluded8(rest, movers, &ctx, &r);
    }

    void fill(RayHit& h, unsigned geomID, unsigned primID, unsigned instID, float u, float v, float t, float nx,
              float ny, float nz) const {
        h.hit = true;
        h.t = t;
        h.u = u;
        h.v = v;
        h.primId = primID;
        h.geomId = geomID;
        h.instId = instID != RTC_INVALID_GEOMETRY_ID ? instID : 0xFFFFFFFFu;
        glm::vec3 n(nx, ny, nz);
        const TopGeom* tree = nullptr;
        const std::vector<TriColors>* tris = colorsOf(geomID, instID, &tree);
        h.color = tris ? interpolateColor(*tris, primID, u, v) : glm::u8vec4(255, 0, 255, 255);
        if (tree) n = tree->normalMatrix * n;  // regions are translations: their normals are world normals
        float len = glm::length(n);
        h.normal = len > 0 ? n / len : glm::vec3(0, 0, 1);
    }

    Status initCity(const glm::dvec3& cityOrigin);
    Result<std::shared_ptr<PrototypeSet>> buildPrototypes(const SceneModel& model);
    Status attachTrees(const std::vector<SceneInstance>& allInstances, const std::vector<SceneInstance>& allImpostors,
                       size_t prototypeCount, const std::vector<uint32_t>& instances,
                       const std::vector<uint32_t>& impostors, const std::shared_ptr<PrototypeSet>& protos, int region,
                       std::vector<unsigned>* ids, size_t* tris);
    Status buildRegionScene(const SceneModel& model, const std::vector<uint32_t>& meshes,
                            const std::vector<uint32_t>& instances, const std::vector<uint32_t>& impostors,
                            const glm::dvec3& frame, Region& r);
    Result<int> attachRegion(Region r, const std::vector<SceneInstance>& allInstances,
                             const std::vector<SceneInstance>& allImpostors, size_t prototypeCount,
                             const std::vector<uint32_t>& instances, const std::vector<uint32_t>& impostors);
    Result<int> addRegionItems(const SceneModel& model, const std::vector<uint32_t>& meshes,
                               const std::vector<uint32_t>& instances, const std::vector<uint32_t>& impostors,
                               const std::shared_ptr<PrototypeSet>& protos);
    void dropRegion(Region& r);
};

RayScene::RayScene() : _impl(new Impl) {}
RayScene::~RayScene() = default;

namespace {

// Builds one triangle geometry; returns false (and leaves no geometry) for empty/invalid meshes.
bool addTriangles(RTCDevice device, RTCScene scene, const std::vector<glm::vec3>& positions,
                  const std::vector<uint32_t>& indices, const glm::dvec3& shift, bool cullBack, unsigned* geomIdOut) {
    size_t nv = positions.size(), nt = indices.size() / 3;
    if (nv == 0 || nt == 0) return false;
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    if (!g) return false;
    auto* vb = static_cast<float*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv));
    auto* ib = static_cast<uint32_t*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), nt));
    if (!vb || !ib) {
        rtcReleaseGeometry(g);
        return false;
    }
    for (size_t i = 0; i < nv; ++i) {
        glm::dvec3 p = glm::dvec3(positions[i]) + shift;
        vb[3 * i] = float(p.x);
        vb[3 * i + 1] = float(p.y);
        vb[3 * i + 2] = float(p.z);
    }
    for (size_t i = 0; i < nt * 3; ++i) ib[i] = indices[i] < nv ? indices[i] : 0;
    if (cullBack) {
        rtcSetGeometryIntersectFilterFunction(g, cullBackFaces);
        rtcSetGeometryOccludedFilterFunction(g, cullBackFaces);
    }
    rtcCommitGeometry(g);
    *geomIdOut = rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    return true;
}

bool validMesh(const SceneMesh& m) {
    if (m.indices.size() % 3 != 0 || m.colors.size() != m.positions.size()) return false;
    for (uint32_t i : m.indices)
        if (i >= m.positions.size()) return false;
    return true;
}

RTCDevice sharedSoupDevice() {
    static std::once_flag once;
    static RTCDevice device = nullptr;
    std::call_once(once, [] { device = rtcNewDevice("threads=0"); });
    return device;
}

RTCBuildQuality embreeQuality(RayBuildQuality q) {
    switch (q) {
        case RayBuildQuality::Low: return RTC_BUILD_QUALITY_LOW;
        case RayBuildQuality::Medium: return RTC_BUILD_QUALITY_MEDIUM;
        case RayBuildQuality::High: return RTC_BUILD_QUALITY_HIGH;
    }
    return RTC_BUILD_QUALITY_MEDIUM;
}

}  // namespace

namespace {

Status malformedMesh(size_t mi) {
    return Status::error("ray scene: mesh " + std::to_string(mi) +
                         " is malformed (index out of range, "
                         "index count not a multiple of 3 or colour count != vertex count)");
}

// Column-major 3x4 float matrix of `xf` with `shift` subtracted from its translation.
void embreeTransform(const glm::dmat4& xf, const glm::dvec3& shift, float m[12]) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 3; ++r) m[c * 3 + r] = float(c == 3 ? xf[c][r] - shift[r] : xf[c][r]);
}

// World position of a region anchored at `anchor`: a whole number of metres
// from the frame origin, so that the region's translation in the float top
// level is exact (below 2^24 m).
glm::dvec3 regionOrigin(const glm::dvec3& frame, const glm::dvec3& anchor) {
    const glm::dvec3 d = anchor - frame;
    return frame + glm::dvec3(std::round(d.x), std::round(d.y), std::round(d.z));
}

}  // namespace

// A city scene's device and empty top-level scene, around `origin`.
Status RayScene::Impl::initCity(const glm::dvec3& cityOrigin) {
    enableFtzDaz();
    city = true;
    origin = buildOrigin = cityOrigin;
    device = rtcNewDevice("");
    if (!device) {
        return Status::error(std::string("ray scene: cannot create Embree device (") +
                             embreeErrorName(rtcGetDeviceError(nullptr)) + ")");
    }
    rtcSetDeviceErrorFunction(device, errorCallback, &errors);
    scene = rtcNewScene(device);
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    return Status::ok();
}

Result<std::shared_ptr<PrototypeSet>> RayScene::Impl::buildPrototypes(const SceneModel& model) {
    auto set = std::make_shared<PrototypeSet>();
    set->scenes.assign(model.prototypes.size(), nullptr);
    set->triangles.assign(model.prototypes.size(), 0);
    for (size_t pi = 0; pi < model.prototypes.size(); ++pi) {
        const SceneMesh& p = model.prototypes[pi];
        if (!validMesh(p)) return Status::error("ray scene: tree prototype " + std::to_string(pi) + " is malformed");
        set->colors.push_back(triangleColors(p.colors, p.indices));
        if (p.indices.empty()) continue;
        RTCScene s = rtcNewScene(device);
        rtcSetSceneFlags(s, RTC_SCENE_FLAG_ROBUST);
        unsigned id = 0;
        if (!addTriangles(device, s, p.positions, p.indices, p.origin, true, &id)) {
            rtcReleaseScene(s);
            VISTA_RETURN_IF_ERROR(checkDevice("building prototype geometry"));
            continue;
        }
        rtcCommitScene(s);
        set->scenes[pi] = s;
        set->triangles[pi] = p.indices.size() / 3;
    }
    VISTA_RETURN_IF_ERROR(checkDevice("building tree prototypes"));
    return set;
}

// Attaches the trees (allInstances[instances], allImpostors[impostors]) of a
// model with `prototypeCount` prototypes to the top level; their ids go to `ids`.
Status RayScene::Impl::attachTrees(const std::vector<SceneInstance>& allInstances,
                                   const std::vector<SceneInstance>& allImpostors, size_t prototypeCount,
                                   const std::vector<uint32_t>& instances, const std::vector<uint32_t>& impostors,
                                   const std::shared_ptr<PrototypeSet>& protos, int region, std::vector<unsigned>* ids,
                                   size_t* tris) {
    for (int pass = 0; pass < 2; ++pass) {
        const std::vector<uint32_t>& list = pass == 0 ? instances : impostors;
        const std::vector<SceneInstance>& all = pass == 0 ? allInstances : allImpostors;
        for (uint32_t ii : list) {
            const SceneInstance& inst = all[ii];
            if (inst.prototype >= prototypeCount)
                return Status::error(std::string("ray scene: ") + (pass == 0 ? "instance " : "impostor ") +
                                     std::to_string(ii) + " refers to prototype " + std::to_string(inst.prototype) +
                                     " (have " + std::to_string(prototypeCount) + ")");
            RTCScene child = protos->scenes[inst.prototype];
            if (!child) continue;
            float m[12];
            embreeTransform(inst.transform, origin, m);
            RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
            rtcSetGeometryInstancedScene(g, child);
            rtcSetGeometryTimeStepCount(g, 1);
            rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, m);
            rtcCommitGeometry(g);
            const unsigned id = rtcAttachGeometry(scene, g);
            rtcReleaseGeometry(g);
            TopGeom& tg = top(id);
            tg = TopGeom();
            tg.kind = TopGeom::Kind::Tree;
            tg.index = region;
            tg.prototype = int(inst.prototype);
            (pass == 0 ? tg.instance : tg.impostor) = int(ii);
            tg.protos = protos.get();
            tg.transform = inst.transform;
            const glm::mat3 lin(glm::dmat3(inst.transform));
            tg.normalMatrix = glm::transpose(glm::inverse(lin));
            ids->push_back(id);
            *tris += protos->triangles[inst.prototype];
        }
    }
    return Status::ok();
}

void RayScene::Impl::dropRegion(Region& r) {
    if (r.topId != RTC_INVALID_GEOMETRY_ID) {
        rtcDetachGeometry(scene, r.topId);
        geoms[r.topId] = TopGeom();
    }
    for (unsigned id : r.treeIds) {
        rtcDetachGeometry(scene, id);
        geoms[id] = TopGeom();
    }
    if (r.scene) rtcReleaseScene(r.scene);
    triangles -= r.triangles;
    r = Region();
}

// The region's own Embree scene of `meshes` in r (r.origin on the lattice of
// whole metres around `frame`, r.meshes, r.triangles): touches only the
// device, so it may run on another thread while the scene is queried or
// changed. On error r.scene may hold a partial scene (the caller releases it).
Status RayScene::Impl::buildRegionScene(const SceneModel& model, const std::vector<uint32_t>& meshes,
                                        const std::vector<uint32_t>& instances, const std::vector<uint32_t>& impostors,
                                        const glm::dvec3& frame, Region& r) {
    // Anchor: the first mesh's origin (else the first tree's position).
    glm::dvec3 anchor = frame;
    if (!meshes.empty()) anchor = model.meshes[meshes[0]].origin;
    else if (!instances.empty()) anchor = glm::dvec3(model.instances[instances[0]].transform[3]);
    else if (!impostors.empty()) anchor = glm::dvec3(model.impostors[impostors[0]].transform[3]);
    r.origin = regionOrigin(frame, anchor);
    for (uint32_t mi : meshes) {
        const SceneMesh& m = model.meshes[mi];
        if (!validMesh(m)) return malformedMesh(mi);
        if (!r.scene) {
            r.scene = rtcNewScene(device);
            rtcSetSceneFlags(r.scene, compact ? RTCSceneFlags(RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_COMPACT)
                                              : RTC_SCENE_FLAG_ROBUST);
            rtcSetSceneBuildQuality(r.scene, RTC_BUILD_QUALITY_HIGH);
        }
        unsigned gid = 0;
        if (!addTriangles(device, r.scene, m.positions, m.indices, m.origin - r.origin, true, &gid)) {
            VISTA_RETURN_IF_ERROR(checkDevice("building tile geometry"));
            continue;
        }
        if (r.meshes.size() <= gid) r.meshes.resize(size_t(gid) + 1);
        r.meshes[gid].sceneMesh = int(mi);
        r.meshes[gid].colors = triangleColors(m.colors, m.indices);
        r.triangles += m.indices.size() / 3;
    }
    if (r.scene) {
        rtcCommitScene(r.scene);
        VISTA_RETURN_IF_ERROR(checkDevice("committing a region"));
    }
    return Status::ok();
}

// Instances a region built by buildRegionScene into the top level, with its trees.
Result<int> RayScene::Impl::attachRegion(Region r, const std::vector<SceneInstance>& allInstances,
                                         const std::vector<SceneInstance>& allImpostors, size_t prototypeCount,
                                         const std::vector<uint32_t>& instances,
                                         const std::vector<uint32_t>& impostors) {
    const int id = int(regions.size());
    regions.emplace_back();
    r.live = true;
    const size_t meshTris = r.triangles;
    auto fail = [&](Status st) -> Result<int> {
        r.triangles = 0;  // not yet counted in the scene's total
        regions[size_t(id)] = std::move(r);
        dropRegion(regions[size_t(id)]);
        return st;
    };
    if (r.scene) {
        const glm::dvec3 t = r.origin - origin;  // whole metres: exact in float
        const float m[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, float(t.x), float(t.y), float(t.z)};
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
        rtcSetGeometryInstancedScene(g, r.scene);
        rtcSetGeometryTimeStepCount(g, 1);
        rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, m);
        rtcCommitGeometry(g);
        r.topId = rtcAttachGeometry(scene, g);
        rtcReleaseGeometry(g);
        TopGeom& tg = top(r.topId);
        tg = TopGeom();
        tg.kind = TopGeom::Kind::Region;
        tg.index = id;
        tg.transform = glm::translate(glm::dmat4(1.0), r.origin);
    }
    size_t treeTris = 0;
    Status st = attachTrees(allInstances, allImpostors, prototypeCount, instances, impostors, r.protos, id, &r.treeIds,
                            &treeTris);
    r.triangles = meshTris + treeTris;
    if (!st.isOk()) return fail(st);
    st = checkDevice("adding a region");
    if (!st.isOk()) return fail(st);
    triangles += r.triangles;
    regions[size_t(id)] = std::move(r);
    return id;
}

Result<int> RayScene::Impl::addRegionItems(const SceneModel& model, const std::vector<uint32_t>& meshes,
                                           const std::vector<uint32_t>& instances,
                                           const std::vector<uint32_t>& impostors,
                                           const std::shared_ptr<PrototypeSet>& protos) {
    Region r;
    r.protos = protos;
    Status st = buildRegionScene(model, meshes, instances, impostors, origin, r);
    if (!st.isOk()) {
        if (r.scene) rtcReleaseScene(r.scene);
        return st;
    }
    return attachRegion(std::move(r), model.instances, model.impostors, model.prototypes.size(), instances, impostors);
}

namespace {

// The meshes and instances of `tiles` of `model`, in tile order.
Status tileItems(const SceneModel& model, const std::vector<uint32_t>& tiles, std::vector<uint32_t>& meshes,
                 std::vector<uint32_t>& instances) {
    for (uint32_t t : tiles) {
        if (t >= model.tiles.size())
            return Status::error("ray scene: tile " + std::to_string(t) + " out of range (the model has " +
                                 std::to_string(model.tiles.size()) + " tiles)");
        const SceneTile& tile = model.tiles[t];
        for (uint32_t m : tile.meshes) {
            if (m >= model.meshes.size())
                return Status::error("ray scene: tile " + std::to_string(t) + " lists mesh " + std::to_string(m) +
                                     " (the model has " + std::to_string(model.meshes.size()) + ")");
            meshes.push_back(m);
        }
        for (uint32_t i : tile.instances) {
            if (i >= model.instances.size())
                return Status::error("ray scene: tile " + std::to_string(t) + " lists instance " + std::to_string(i) +
                                     " (the model has " + std::to_string(model.instances.size()) + ")");
            instances.push_back(i);
        }
    }
    return Status::ok();
}

// The items of one paged region span (SceneModel::regions) of `model`.
Status spanItems(const SceneModel& model, const SceneRegionSpan& span, std::vector<uint32_t>& meshes,
                 std::vector<uint32_t>& instances, std::vector<uint32_t>& impostors) {
    if (uint64_t(span.firstTile) + span.tileCount > model.tiles.size() ||
        uint64_t(span.firstImpostor) + span.impostorCount > model.impostors.size())
        return Status::error("ray scene: region span of region " + std::to_string(span.region) +
                             " lies outside the model's tiles or impostors");
    std::vector<uint32_t> tiles(span.tileCount);
    for (uint32_t k = 0; k < span.tileCount; ++k) tiles[k] = span.firstTile + k;
    VISTA_RETURN_IF_ERROR(tileItems(model, tiles, meshes, instances));
    for (uint32_t k = span.firstImpostor; k < span.firstImpostor + span.impostorCount; ++k)
        if (model.impostors[k].prototype < model.prototypes.size()) impostors.push_back(k);
    return Status::ok();
}

}  // namespace

Result<std::unique_ptr<RayScene>> RayScene::build(const SceneModel& city, const RaySceneOptions& options) {
    std::unique_ptr<RayScene> rs(new RayScene());
    Impl& im = *rs->_impl;
    VISTA_RETURN_IF_ERROR(im.initCity(glm::dvec3(city.params.origin_x, city.params.origin_y, 0.0)));
    for (size_t mi = 0; mi < city.meshes.size(); ++mi)
        if (!validMesh(city.meshes[mi])) return malformedMesh(mi);
    auto protos = im.buildPrototypes(city);
    if (!protos) return protos.status();
    // Impostors (coarse levels) are traced as their prototype's mesh where the model has it.
    std::vector<uint32_t> impostors;
    for (size_t k = 0; k < city.impostors.size(); ++k)
        if (city.impostors[k].prototype < city.prototypes.size()) impostors.push_back(uint32_t(k));

    if (!(options.regionSizeM > 0)) {
        im.flat = true;
        for (size_t mi = 0; mi < city.meshes.size(); ++mi) {
            const SceneMesh& m = city.meshes[mi];
            unsigned id = 0;
            if (!addTriangles(im.device, im.scene, m.positions, m.indices, m.origin - im.origin, true, &id)) {
                VISTA_RETURN_IF_ERROR(im.checkDevice("building tile geometry"));
                continue;
            }
            Impl::TopGeom& tg = im.top(id);
            tg.kind = Impl::TopGeom::Kind::Mesh;
            tg.index = int(im.flatMeshes.size());
            im.flatMeshes.push_back({int(mi), triangleColors(m.colors, m.indices)});
            im.triangles += m.indices.size() / 3;
        }
        std::vector<uint32_t> all(city.instances.size());
        for (size_t k = 0; k < all.size(); ++k) all[k] = uint32_t(k);
        im.flatProtos = *protos;
        VISTA_RETURN_IF_ERROR(im.attachTrees(city.instances, city.impostors, city.prototypes.size(), all, impostors,
                                             im.flatProtos, -1, &im.flatTreeIds, &im.triangles));
    } else if (!city.regions.empty()) {
        // A merged paged city: one region per span, as the streamed scene adds them.
        for (const SceneRegionSpan& span : city.regions) {
            std::vector<uint32_t> meshes, instances, spanImpostors;
            VISTA_RETURN_IF_ERROR(spanItems(city, span, meshes, instances, spanImpostors));
            auto id = im.addRegionItems(city, meshes, instances, spanImpostors, *protos);
            if (!id) return id.status();
        }
    } else {
        // Regions: meshes by their origin, trees by their position, on a grid of
        // regionSizeM around the frame origin.
        struct Items {
            std::vector<uint32_t> meshes, instances, impostors;
        };
        std::map<std::pair<int64_t, int64_t>, Items> cells;
        auto cellOf = [&](const glm::dvec3& p) {
            const double s = options.regionSizeM;
            return std::make_pair(int64_t(std::floor((p.x - im.origin.x) / s)),
                                  int64_t(std::floor((p.y - im.origin.y) / s)));
        };
        for (size_t mi = 0; mi < city.meshes.size(); ++mi) {
            const SceneMesh& m = city.meshes[mi];
            cells[cellOf(m.origin)].meshes.push_back(uint32_t(mi));  // a tile's meshes share its origin
        }
        for (size_t k = 0; k < city.instances.size(); ++k)
            cells[cellOf(glm::dvec3(city.instances[k].transform[3]))].instances.push_back(uint32_t(k));
        for (uint32_t k : impostors) cells[cellOf(glm::dvec3(city.impostors[k].transform[3]))].impostors.push_back(k);
        for (const auto& [key, items] : cells) {
            auto id = im.addRegionItems(city, items.meshes, items.instances, items.impostors, *protos);
            if (!id) return id.status();
        }
    }
    rtcCommitScene(im.scene);
    VISTA_RETURN_IF_ERROR(im.checkDevice("committing the scene"));
    return rs;
}

Result<std::unique_ptr<RayScene>> RayScene::empty(const glm::dvec3& frameOrigin) {
    std::unique_ptr<RayScene> rs(new RayScene());
    VISTA_RETURN_IF_ERROR(rs->_impl->initCity(frameOrigin));
    rtcCommitScene(rs->_impl->scene);
    VISTA_RETURN_IF_ERROR(rs->_impl->checkDevice("committing the scene"));
    return rs;
}

Result<int> RayScene::addRegion(const SceneModel& model, const std::vector<uint32_t>& tiles) {
    Impl& im = *_impl;
    if (!im.city || im.flat) return Status::error("ray scene: regions can be added to a city scene of regions only");
    std::vector<uint32_t> meshes, instances, impostors;
    VISTA_RETURN_IF_ERROR(tileItems(model, tiles, meshes, instances));
    // Impostors belong to no tile: those within the tiles' xy bounds come with them.
    for (size_t k = 0; k < model.impostors.size(); ++k) {
        const glm::dvec3 p(model.impostors[k].transform[3]);
        if (model.impostors[k].prototype >= model.prototypes.size()) continue;
        for (uint32_t t : tiles) {
            const SceneTile& tile = model.tiles[t];
            if (p.x >= tile.lo.x && p.x <= tile.hi.x && p.y >= tile.lo.y && p.y <= tile.hi.y) {
                impostors.push_back(uint32_t(k));
                break;
            }
        }
    }
    auto protos = im.buildPrototypes(model);
    if (!protos) return protos.status();
    return im.addRegionItems(model, meshes, instances, impostors, *protos);
}

Result<int> RayScene::addRegion(const SceneModel& model) {
    auto p = prepareRegion(model);
    if (!p) return p.status();
    return addPrepared(*p);
}

struct RayScene::PreparedRegion {
    const Impl* owner = nullptr;
    bool added = false;
    Impl::Region region;  // scene built, not instanced
    std::vector<SceneInstance> instances, impostors;
    std::vector<uint32_t> instanceList, impostorList;
    size_t prototypeCount = 0;
    ~PreparedRegion() {
        if (region.scene) rtcReleaseScene(region.scene);
    }
};

void RayScene::setCompactRegions(bool compact) { _impl->compact = compact; }

Result<std::shared_ptr<RayScene::PreparedRegion>> RayScene::prepareRegion(const SceneModel& model) const {
    // Only the device and the error sink are used (both thread-safe).
    Impl& im = const_cast<Impl&>(*_impl);
    if (!im.city || im.flat) return Status::error("ray scene: regions can be added to a city scene of regions only");
    if (model.tiles.empty()) return Status::error("ray scene: a region model without tiles");
    SceneRegionSpan whole;
    whole.tileCount = uint32_t(model.tiles.size());
    whole.impostorCount = uint32_t(model.impostors.size());
    auto p = std::make_shared<PreparedRegion>();
    std::vector<uint32_t> meshes;
    VISTA_RETURN_IF_ERROR(spanItems(model, whole, meshes, p->instanceList, p->impostorList));
    auto protos = im.buildPrototypes(model);
    if (!protos) return protos.status();
    p->owner = &im;
    p->region.protos = *protos;
    // Region origins lie on the lattice of whole metres around the build origin, as every frame origin does.
    VISTA_RETURN_IF_ERROR(
        im.buildRegionScene(model, meshes, p->instanceList, p->impostorList, im.buildOrigin, p->region));
    p->instances = model.instances;
    p->impostors = model.impostors;
    p->prototypeCount = model.prototypes.size();
    return p;
}

Result<int> RayScene::addPrepared(const std::shared_ptr<PreparedRegion>& p) {
    Impl& im = *_impl;
    if (!p || p->owner != &im) return Status::error("ray scene: a region prepared by another scene");
    if (p->added) return Status::error("ray scene: a prepared region added twice");
    p->added = true;
    Impl::Region r = std::move(p->region);
    p->region = Impl::Region();
    return im.attachRegion(std::move(r), p->instances, p->impostors, p->prototypeCount, p->instanceList,
                           p->impostorList);
}

Status RayScene::removeRegion(int region) {
    Impl& im = *_impl;
    if (region < 0 || size_t(region) >= im.regions.size() || !im.regions[size_t(region)].live)
        return Status::error("ray scene: no region " + std::to_string(region) + " to remove");
    im.dropRegion(im.regions[size_t(region)]);
    return Status::ok();
}

Status RayScene::commit() {
    rtcCommitScene(_impl->scene);
    return _impl->checkDevice("committing the scene");
}

Status RayScene::setMoverPrototypes(const std::vector<SceneMesh>& prototypes) {
    Impl& im = *_impl;
    if (!im.scene) return Status::error("ray scene: no scene for moving objects");
    SceneModel model;
    model.prototypes = prototypes;
    auto protos = im.buildPrototypes(model);
    if (!protos.isOk()) return protos.status();
    if (!im.movers) {
        // Small and rebuilt per frame: the quick build; robust traversal as the top level.
        im.movers = rtcNewScene(im.device);
        rtcSetSceneFlags(im.movers, RTCSceneFlags(RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_DYNAMIC));
        rtcSetSceneBuildQuality(im.movers, RTC_BUILD_QUALITY_LOW);
        rtcCommitScene(im.movers);
        VISTA_RETURN_IF_ERROR(im.checkDevice("making the scene of moving objects"));
    }
    // Placed objects of the old prototypes are hidden (their scenes are released with the old set).
    for (size_t i = 0; i < im.moversLive && i < im.moverGeoms.size(); ++i) {
        rtcDisableGeometry(rtcGetGeometry(im.movers, im.moverGeoms[i]));
        im.moverTops[im.moverGeoms[i]] = Impl::TopGeom();
    }
    // Still slots likewise: each shown one changes (hidden).
    bool stillChanged = false;
    for (size_t i = 0; i < im.stills.size(); ++i) {
        rtcDisableGeometry(rtcGetGeometry(im.movers, im.stillGeoms[i]));
        im.moverTops[im.stillGeoms[i]] = Impl::TopGeom();
        if (!im.stills[i].shown) continue;
        im.stills[i].shown = false;
        if (!stillChanged) ++im.stillSerial;
        stillChanged = true;
        im.stillStates[i].shown = false;
        im.stillStates[i].version = im.stillSerial;
    }
    if (im.moversLive > 0 || im.stillsOn > 0) rtcCommitScene(im.movers);
    im.moversLive = 0;
    im.stillsOn = 0;
    im.moversOn = false;
    im.moverSpheres.clear();
    im.moverProtos = *protos;
    im.moverBounds.clear();
    for (const SceneMesh& p : prototypes) {
        glm::dvec3 lo(1e300), hi(-1e300);
        for (const glm::vec3& v : p.positions) {
            lo = glm::min(lo, glm::dvec3(v) + p.origin);
            hi = glm::max(hi, glm::dvec3(v) + p.origin);
        }
        const bool any = !p.positions.empty();
        im.moverBounds.push_back(any ? glm::dvec4(0.5 * (lo + hi), 0.5 * glm::length(hi - lo)) : glm::dvec4(0.0));
    }
    return Status::ok();
}

Status RayScene::placeMovers(const std::vector<MoverPlacement>& movers, const std::vector<StillPlacement>* still) {
    Impl& im = *_impl;
    const size_t protoCount = im.moverProtos ? im.moverProtos->scenes.size() : 0;
    auto bad = [&](uint32_t proto) {
        return Status::error("ray scene: moving object of prototype " + std::to_string(proto) + " (have " +
                             std::to_string(protoCount) + ")");
    };
    for (const MoverPlacement& p : movers)
        if (p.prototype >= protoCount) return bad(p.prototype);
    if (still)
        for (const StillPlacement& p : *still)
            if (p.shown && p.object.prototype >= protoCount) return bad(p.object.prototype);
    if (!im.movers) return Status::ok();  // no prototypes, so nothing to place (movers is empty)
    im.moverSpheres.clear();
    for (const MoverPlacement& p : movers) im.moverSpheres.push_back(im.worldSphere(p));
    bool on = false;
    for (size_t i = 0; i < movers.size(); ++i) {
        if (i == im.moverGeoms.size()) im.moverGeoms.push_back(im.newMoverInstance());
        on = im.placeMoverInstance(im.moverGeoms[i], movers[i], int(i), -1) || on;
    }
    for (size_t i = movers.size(); i < im.moversLive && i < im.moverGeoms.size(); ++i) {
        rtcDisableGeometry(rtcGetGeometry(im.movers, im.moverGeoms[i]));
        im.moverTops[im.moverGeoms[i]].kind = Impl::TopGeom::Kind::None;
    }
    im.moversLive = movers.size();
    if (still) {
        // Only the slots whose entry differs from what they show are re-placed.
        bool changed = false;
        const size_t slots = std::max(still->size(), im.stills.size());
        for (size_t i = 0; i < slots; ++i) {
            const StillPlacement want = i < still->size() ? (*still)[i] : StillPlacement{MoverPlacement(), false};
            if (i == im.stills.size()) {
                im.stills.push_back(StillPlacement{MoverPlacement(), false});
                im.stillGeoms.push_back(im.newMoverInstance());
                im.stillStates.push_back(StillState());
            }
            StillPlacement& have = im.stills[i];
            const bool same = want.shown == have.shown &&
                              (!want.shown || (want.object.prototype == have.object.prototype &&
                                               want.object.transform == have.object.transform &&
                                               want.object.id == have.object.id && want.object.cls == have.object.cls));
            if (same) continue;
            const unsigned id = im.stillGeoms[i];
            const bool wasOn = im.moverTops[id].kind == Impl::TopGeom::Kind::Mover;
            bool nowOn = false;
            if (want.shown) {
                nowOn = im.placeMoverInstance(id, want.object, -1, int(i));
            } else {
                rtcDisableGeometry(rtcGetGeometry(im.movers, id));
                im.moverTops[id].kind = Impl::TopGeom::Kind::None;
            }
            im.stillsOn = im.stillsOn - (wasOn ? 1 : 0) + (nowOn ? 1 : 0);
            if (!changed) ++im.stillSerial;
            changed = true;
            have = want;
            StillState& st = im.stillStates[i];
            if (want.shown) st.sphere = im.worldSphere(want.object);
            st.shown = want.shown;
            st.version = im.stillSerial;
        }
    }
    rtcCommitScene(im.movers);  // the movers' scene alone: the top level is left as it is
    ++im.moverCommits;
    im.moversOn = on || im.stillsOn > 0;
    return im.checkDevice("placing moving objects");
}

size_t RayScene::moverCount() const { return _impl->moversLive; }

const std::vector<glm::dvec4>& RayScene::moverSpheres() const { return _impl->moverSpheres; }

const std::vector<StillState>& RayScene::stillObjects() const { return _impl->stillStates; }

uint64_t RayScene::stillSerial() const { return _impl->stillSerial; }

uint64_t RayScene::moverCommits() const { return _impl->moverCommits; }

Status RayScene::setFrameOrigin(const glm::dvec3& frameOrigin) {
    Impl& im = *_impl;
    if (!im.city || im.flat) return Status::error("ray scene: only a city scene of regions can move its frame");
    // Whole metres from the current frame, as every region origin: translations stay exact.
    const glm::dvec3 d = frameOrigin - im.origin;
    const glm::dvec3 next = im.origin + glm::dvec3(std::round(d.x), std::round(d.y), std::round(d.z));
    if (next == im.origin) return Status::ok();
    im.origin = next;
    for (size_t id = 0; id < im.geoms.size(); ++id) {
        const Impl::TopGeom& g = im.geoms[id];
        if (g.kind != Impl::TopGeom::Kind::Region && g.kind != Impl::TopGeom::Kind::Tree) continue;
        RTCGeometry geom = rtcGetGeometry(im.scene, unsigned(id));
        float m[12];
        embreeTransform(g.transform, im.origin, m);
        rtcSetGeometryTransform(geom, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, m);
        rtcCommitGeometry(geom);
    }
    rtcCommitScene(im.scene);
    if (im.movers) {
        for (size_t id = 0; id < im.moverTops.size(); ++id) {
            const Impl::TopGeom& g = im.moverTops[id];
            if (g.kind != Impl::TopGeom::Kind::Mover) continue;
            RTCGeometry geom = rtcGetGeometry(im.movers, unsigned(id));
            float m[12];
            embreeTransform(g.transform, im.origin, m);
            rtcSetGeometryTransform(geom, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, m);
            rtcCommitGeometry(geom);
        }
        rtcCommitScene(im.movers);
    }
    return im.checkDevice("moving the frame origin");
}

Status RayScene::placeFrameNear(const glm::dvec3& eye) {
    Impl& im = *_impl;
    if (!im.city || im.flat) return Status::ok();
    const glm::dvec3 d = (eye - im.buildOrigin) / kFrameCellM;
    const glm::dvec3 cell = im.buildOrigin + kFrameCellM * glm::dvec3(std::round(d.x), std::round(d.y), 0.0);
    return setFrameOrigin(glm::dvec3(cell.x, cell.y, im.buildOrigin.z));
}

int RayScene::regionCount() const {
    int n = 0;
    for (const auto& r : _impl->regions) n += r.live ? 1 : 0;
    return n;
}

Result<std::unique_ptr<RayScene>> RayScene::build(const TriangleSoup& soup, const SoupSceneOptions& options) {
    if (soup.colors.size() != soup.positions.size())
        return Status::error("ray scene: soup colour count " + std::to_string(soup.colors.size()) +
                             " != vertex count " + std::to_string(soup.positions.size()));
    if (soup.indices.size() % 3 != 0)
        return Status::error("ray scene: soup index count " + std::to_string(soup.indices.size()) +
                             " is not a multiple of 3");
    for (uint32_t i : soup.indices)
        if (i >= soup.positions.size())
            return Status::error("ray scene: soup index " + std::to_string(i) + " out of range (" +
                                 std::to_string(soup.positions.size()) + " vertices)");
    for (const auto& p : soup.positions)
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            return Status::error("ray scene: soup has a non-finite vertex");
    std::unique_ptr<RayScene> rs(new RayScene());
    Impl& im = *rs->_impl;
    im.ftz = false;
    im.flat = true;
    im.origin = options.frameOrigin;
    RTCDevice device = sharedSoupDevice();
    if (!device) return Status::error("ray scene: cannot create the Embree device for soups");
    rtcRetainDevice(device);
    im.device = device;
    im.scene = rtcNewScene(device);
    rtcSetSceneBuildQuality(im.scene, embreeQuality(options.quality));
    if (soup.triangleCount() > 0) {
        unsigned id = 0;
        if (!addTriangles(device, im.scene, soup.positions, soup.indices, glm::dvec3(0.0), options.cullBackFaces, &id))
            return Status::error("ray scene: Embree buffer allocation failed for a soup of " +
                                 std::to_string(soup.triangleCount()) + " triangles");
        Impl::TopGeom& tg = im.top(id);
        tg.kind = Impl::TopGeom::Kind::Mesh;
        tg.index = 0;
        im.flatMeshes.push_back({-1, triangleColors(soup.colors, soup.indices)});
        im.triangles = soup.triangleCount();
    }
    rtcCommitScene(im.scene);
    const RTCError e = rtcGetDeviceError(device);  // per thread: this build's error
    if (e != RTC_ERROR_NONE)
        return Status::error(std::string("ray scene: Embree error while building a soup: ") + embreeErrorName(e));
    return rs;
}

glm::dvec3 RayScene::frameOrigin() const { return _impl->origin; }

HitSource RayScene::source(const RayHit& h) const {
    HitSource s;
    if (!h.hit) return s;
    const Impl& im = *_impl;
    const unsigned instId = h.instId != 0xFFFFFFFFu ? h.instId : RTC_INVALID_GEOMETRY_ID;
    if (const Impl::MeshInfo* m = im.meshOf(h.geomId, instId)) {
        s.mesh = m->sceneMesh;
        if (instId != RTC_INVALID_GEOMETRY_ID) s.region = im.geoms[instId].index;
        return s;
    }
    const Impl::TopGeom* gp = im.instanceOf(instId);
    if (!gp) return s;
    const Impl::TopGeom& g = *gp;
    if (g.kind == Impl::TopGeom::Kind::Mover) {
        s.mover = g.instance;
        s.still = g.still;
        s.moverId = g.moverId;
        s.moverClass = g.moverClass;
        return s;
    }
    if (g.kind != Impl::TopGeom::Kind::Tree) return s;
    s.instance = g.instance;
    s.impostor = g.impostor;
    s.region = g.index;
    return s;
}

RayHit RayScene::intersect(const glm::vec3& org, const glm::vec3& dir, float tnear, float tfar) const {
    if (_impl->ftz) enableFtzDaz();
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh;
    std::memset(&rh, 0, sizeof(rh));
    rh.ray.org_x = org.x;
    rh.ray.org_y = org.y;
    rh.ray.org_z = org.z;
    rh.ray.dir_x = dir.x;
    rh.ray.dir_y = dir.y;
    rh.ray.dir_z = dir.z;
    rh.ray.tnear = tnear;
    rh.ray.tfar = tfar;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    RayHit out;
    if (!(tnear <= tfar)) return out;
    _impl->intersect1(ctx, rh);
    if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID)
        _impl->fill(out, rh.hit.geomID, rh.hit.primID, rh.hit.instID[0], rh.hit.u, rh.hit.v, rh.ray.tfar, rh.hit.Ng_x,
                    rh.hit.Ng_y, rh.hit.Ng_z);
    return out;
}

// Calls packet(ctx, rh, valid, base, m) for the n rays in packets of 8 (m valid lanes from base),
// with a coherent intersect context and FTZ/DAZ as the scene asks.
namespace {
template <class F>
void forPackets8(bool ftz, int n, F&& packet) {
    if (ftz) enableFtzDaz();
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    alignas(32) RTCRayHit8 rh;
    alignas(32) int valid[8];
    for (int base = 0; base < n; base += 8) packet(ctx, rh, valid, base, std::min(8, n - base));
}
}  // namespace

void RayScene::intersectMany(const glm::vec3* org, const glm::vec3* dir, int n, RayHit* out, float tfar,
                             const float* tfars, float tnear) const {
    forPackets8(_impl->ftz, n, [&](RTCIntersectContext& ctx, RTCRayHit8& rh, int* valid, int base, int m) {
        fillPacket8(rh, valid, org, dir, tfars, tfar, size_t(base), m, tnear);
        _impl->intersect8(valid, ctx, rh);
        for (int k = 0; k < m; ++k) {
            RayHit& h = out[base + k];
            h = RayHit();
            if (rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID)
                _impl->fill(h, rh.hit.geomID[k], rh.hit.primID[k], rh.hit.instID[0][k], rh.hit.u[k], rh.hit.v[k],
                            rh.ray.tfar[k], rh.hit.Ng_x[k], rh.hit.Ng_y[k], rh.hit.Ng_z[k]);
        }
    });
}

void RayScene::occludedMany(const glm::vec3* org, const glm::vec3* dir, int n, const float* tfars, uint8_t* out,
                            float tnear) const {
    forPackets8(_impl->ftz, n, [&](RTCIntersectContext& ctx, RTCRayHit8& rh, int* valid, int base, int m) {
        fillPacket8(rh, valid, org, dir, tfars, 0.0f, size_t(base), m, tnear);
        for (int k = 0; k < m; ++k)
            if (!(rh.ray.tnear[k] <= rh.ray.tfar[k])) valid[k] = 0;  // empty interval: not occluded
        _impl->occluded8(valid, ctx, rh.ray);
        for (int k = 0; k < m; ++k) out[base + k] = valid[k] && rh.ray.tfar[k] < 0.0f ? 1 : 0;
    });
}

bool RayScene::occluded(const glm::vec3& org, const glm::vec3& dir, float tnear, float tfar) const {
    if (_impl->ftz) enableFtzDaz();
    if (!(tnear <= tfar)) return false;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay r;
    std::memset(&r, 0, sizeof(r));
    r.org_x = org.x;
    r.org_y = org.y;
    r.org_z = org.z;
    r.dir_x = dir.x;
    r.dir_y = dir.y;
    r.dir_z = dir.z;
    r.tnear = tnear;
    r.tfar = tfar;
    r.mask = 0xFFFFFFFFu;
    _impl->occluded1(ctx, r);
    return r.tfar < 0.0f;  // Embree sets tfar = -inf on occlusion
}

int RayScene::allHits(const glm::vec3& org, const glm::vec3& dir, float tnear, float tfar, int maxHits, float minGap,
                      RayHit* out) const {
    int n = 0;
    float t0 = tnear;
    while (n < maxHits) {
        const RayHit h = intersect(org, dir, t0, tfar);
        if (!h.hit) break;
        out[n++] = h;
        t0 = h.t + std::max(minGap, h.t * 1e-5f);
    }
    return n;
}

void RayScene::allHitsMany(const glm::vec3* org, const glm::vec3* dir, int n, const float* tnears, const float* tfars,
                           int maxHits, float minGap, RayHit* out, int* counts) const {
    forPackets8(_impl->ftz, n, [&](RTCIntersectContext& ctx, RTCRayHit8& rh, int* valid, int base, int m) {
        float t0[8];
        int live[8];
        for (int k = 0; k < m; ++k) {
            counts[base + k] = 0;
            t0[k] = tnears[base + k];
            live[k] = maxHits > 0 && tnears[base + k] <= tfars[base + k];
        }
        for (int k = m; k < 8; ++k) live[k] = 0;
        for (int layer = 0; layer < maxHits; ++layer) {
            fillPacket8(rh, valid, org, dir, tfars, 0.0f, size_t(base), m);
            bool any = false;
            for (int k = 0; k < 8; ++k) {
                valid[k] = live[k] ? -1 : 0;
                any = any || live[k];
                if (k < m) rh.ray.tnear[k] = t0[k];
            }
            if (!any) break;
            _impl->intersect8(valid, ctx, rh);
            for (int k = 0; k < m; ++k) {
                if (!live[k]) continue;
                if (rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) {
                    live[k] = 0;
                    continue;
                }
                const size_t i = size_t(base) + size_t(k);
                RayHit& h = out[i * size_t(maxHits) + size_t(counts[i])];
                h = RayHit();
                _impl->fill(h, rh.hit.geomID[k], rh.hit.primID[k], rh.hit.instID[0][k], rh.hit.u[k], rh.hit.v[k],
                            rh.ray.tfar[k], rh.hit.Ng_x[k], rh.hit.Ng_y[k], rh.hit.Ng_z[k]);
                ++counts[i];
                t0[k] = h.t + std::max(minGap, h.t * 1e-5f);
                if (counts[i] >= maxHits || !(t0[k] <= tfars[i])) live[k] = 0;
            }
        }
    });
}

glm::vec3 RayScene::hitColor(const RayHit& h) const {
    if (!h.hit) return glm::vec3(0.0f);
    const Impl::TopGeom* tree = nullptr;
    const auto* tris = _impl->colorsOf(h.geomId, h.instId != 0xFFFFFFFFu ? h.instId : RTC_INVALID_GEOMETRY_ID, &tree);
    if (!tris || h.primId >= tris->size()) return {1.0f, 0.0f, 1.0f};  // cannot happen for a hit of this scene
    const TriColors& t = (*tris)[h.primId];
    const glm::vec3 c0 = glm::vec3(t.c[0]) / 255.0f, c1 = glm::vec3(t.c[1]) / 255.0f, c2 = glm::vec3(t.c[2]) / 255.0f;
    return (1.0f - h.u - h.v) * c0 + h.u * c1 + h.v * c2;
}

size_t RayScene::triangleCount() const { return _impl->triangles; }

RTCSceneTy* RayScene::embreeScene() const { return _impl->scene; }

RTCSceneTy* RayScene::embreeMoverScene() const { return _impl->movers; }

}  // namespace vista
