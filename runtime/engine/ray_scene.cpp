// RayScene: Embree 3 scene of a loaded city (see ray_scene.h for the contract).
//
// Layout: one RTCScene; one triangle geometry per tile mesh (vertices in a
// scene-local float frame around frameOrigin); one child scene per tree
// prototype, instanced with RTC_GEOMETRY_TYPE_INSTANCE per SceneInstance.
// Hit colours: barycentric interpolation of the prelit vertex colours, rounded
// to 8 bits exactly as the fixed-function rasteriser does; the colours are kept
// per triangle (primID -> its three corners), so a hit costs one memory fetch
// (docs/measurements/raw-rays.md: the colour fetch was the wrapper's largest cost).
// A soup scene: one triangle geometry on a device shared by all soup scenes
// (so the bake does not create a device per impostor); no robust flag.
#include "runtime/engine/ray_scene.h"

#include "runtime/engine/ray_packet.h"

#include <embree3/rtcore.h>
#include <pmmintrin.h>
#include <xmmintrin.h>

#include <algorithm>
#include <cmath>
#include <cstring>
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

}  // namespace

struct RayScene::Impl {
    RTCDevice device = nullptr;
    bool ftz = true;  // set FTZ/DAZ on casting threads (city scenes)
    RTCScene scene = nullptr;
    std::vector<RTCScene> protoScenes;
    ErrorSink errors;
    glm::dvec3 origin{0.0};
    size_t triangles = 0;

    // Per top-level geometry id: what it is.
    struct GeomInfo {
        int mesh = -1;       // index into meshColors, or -1 for an instance
        int prototype = -1;  // prototype index for an instance
        int sceneMesh = -1;  // SceneModel::meshes index (city scenes)
        int instance = -1;   // SceneModel::instances index (city scenes)
        glm::mat3 normalMatrix{1.0f};
    };
    std::vector<GeomInfo> geoms;
    std::vector<std::vector<TriColors>> meshColors, protoColors;  // per triangle (primID)

    ~Impl() {
        if (scene) rtcReleaseScene(scene);
        for (RTCScene s : protoScenes)
            if (s) rtcReleaseScene(s);
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

    void fill(RayHit& h, unsigned geomID, unsigned primID, unsigned instID, float u, float v, float t, float nx,
              float ny, float nz) const {
        h.hit = true;
        h.t = t;
        h.u = u;
        h.v = v;
        h.primId = primID;
        glm::vec3 n(nx, ny, nz);
        if (instID != RTC_INVALID_GEOMETRY_ID) {
            h.instId = instID;
            h.geomId = geomID;
            const GeomInfo& gi = geoms[instID];
            h.color = interpolateColor(protoColors[size_t(gi.prototype)], primID, u, v);
            n = gi.normalMatrix * n;
        } else {
            h.instId = 0xFFFFFFFFu;
            h.geomId = geomID;
            const GeomInfo& gi = geoms[geomID];
            h.color = interpolateColor(meshColors[size_t(gi.mesh)], primID, u, v);
        }
        float len = glm::length(n);
        h.normal = len > 0 ? n / len : glm::vec3(0, 0, 1);
    }
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

Result<std::unique_ptr<RayScene>> RayScene::build(const SceneModel& city) {
    enableFtzDaz();
    std::unique_ptr<RayScene> rs(new RayScene());
    Impl& im = *rs->_impl;
    im.origin = glm::dvec3(city.params.origin_x, city.params.origin_y, 0.0);
    im.device = rtcNewDevice("");
    if (!im.device) {
        return Status::error(std::string("ray scene: cannot create Embree device (") +
                             embreeErrorName(rtcGetDeviceError(nullptr)) + ")");
    }
    rtcSetDeviceErrorFunction(im.device, errorCallback, &im.errors);
    im.scene = rtcNewScene(im.device);
    rtcSetSceneFlags(im.scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(im.scene, RTC_BUILD_QUALITY_HIGH);

    for (size_t mi = 0; mi < city.meshes.size(); ++mi) {
        const SceneMesh& m = city.meshes[mi];
        if (!validMesh(m))
            return Status::error("ray scene: mesh " + std::to_string(mi) +
                                 " is malformed (index out of range, "
                                 "index count not a multiple of 3 or colour count != vertex count)");
        unsigned id = 0;
        if (!addTriangles(im.device, im.scene, m.positions, m.indices, m.origin - im.origin, true, &id)) {
            VISTA_RETURN_IF_ERROR(im.checkDevice("building tile geometry"));
            continue;
        }
        if (im.geoms.size() <= id) im.geoms.resize(id + 1);
        im.geoms[id].mesh = int(im.meshColors.size());
        im.geoms[id].sceneMesh = int(mi);
        im.meshColors.push_back(triangleColors(m.colors, m.indices));
        im.triangles += m.indices.size() / 3;
    }

    // Prototypes: one child scene each.
    std::vector<size_t> protoTris(city.prototypes.size(), 0);
    im.protoScenes.assign(city.prototypes.size(), nullptr);
    for (size_t pi = 0; pi < city.prototypes.size(); ++pi) {
        const SceneMesh& p = city.prototypes[pi];
        if (!validMesh(p)) return Status::error("ray scene: tree prototype " + std::to_string(pi) + " is malformed");
        im.protoColors.push_back(triangleColors(p.colors, p.indices));
        if (p.indices.empty()) continue;
        RTCScene s = rtcNewScene(im.device);
        rtcSetSceneFlags(s, RTC_SCENE_FLAG_ROBUST);
        unsigned id = 0;
        if (!addTriangles(im.device, s, p.positions, p.indices, p.origin, true, &id)) {
            rtcReleaseScene(s);
            VISTA_RETURN_IF_ERROR(im.checkDevice("building prototype geometry"));
            continue;
        }
        rtcCommitScene(s);
        im.protoScenes[pi] = s;
        protoTris[pi] = p.indices.size() / 3;
    }
    VISTA_RETURN_IF_ERROR(im.checkDevice("building tree prototypes"));

    for (size_t ii = 0; ii < city.instances.size(); ++ii) {
        const SceneInstance& inst = city.instances[ii];
        if (inst.prototype >= city.prototypes.size())
            return Status::error("ray scene: instance " + std::to_string(ii) + " refers to prototype " +
                                 std::to_string(inst.prototype) + " (have " + std::to_string(city.prototypes.size()) +
                                 ")");
        RTCScene child = im.protoScenes[inst.prototype];
        if (!child) continue;
        glm::dmat4 xf = inst.transform;
        xf[3] -= glm::dvec4(im.origin, 0.0);  // scene-local translation
        float m[12];
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 3; ++r) m[c * 3 + r] = float(xf[c][r]);
        RTCGeometry g = rtcNewGeometry(im.device, RTC_GEOMETRY_TYPE_INSTANCE);
        rtcSetGeometryInstancedScene(g, child);
        rtcSetGeometryTimeStepCount(g, 1);
        rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, m);
        rtcCommitGeometry(g);
        unsigned id = rtcAttachGeometry(im.scene, g);
        rtcReleaseGeometry(g);
        if (im.geoms.size() <= id) im.geoms.resize(id + 1);
        im.geoms[id].prototype = int(inst.prototype);
        im.geoms[id].instance = int(ii);
        glm::mat3 lin(glm::dmat3(inst.transform));
        im.geoms[id].normalMatrix = glm::transpose(glm::inverse(lin));
        im.triangles += protoTris[inst.prototype];
    }
    rtcCommitScene(im.scene);
    VISTA_RETURN_IF_ERROR(im.checkDevice("committing the scene"));
    return rs;
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
        if (im.geoms.size() <= id) im.geoms.resize(id + 1);
        im.geoms[id].mesh = 0;
        im.meshColors.push_back(triangleColors(soup.colors, soup.indices));
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
    const bool inst = h.instId != 0xFFFFFFFFu;
    const uint32_t g = inst ? h.instId : h.geomId;
    if (g >= _impl->geoms.size()) return s;
    const Impl::GeomInfo& gi = _impl->geoms[g];
    if (inst) s.instance = gi.instance;
    else s.mesh = gi.sceneMesh;
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
    rtcIntersect1(_impl->scene, &ctx, &rh);
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
        rtcIntersect8(valid, _impl->scene, &ctx, &rh);
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
        rtcOccluded8(valid, _impl->scene, &ctx, &rh.ray);
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
    rtcOccluded1(_impl->scene, &ctx, &r);
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
            rtcIntersect8(valid, _impl->scene, &ctx, &rh);
            for (int k = 0; k < m; ++k) {
                if (!live[k]) continue;
                if (rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) {
                    live[k] = 0;
                    continue;
                }
                const size_t i = size_t(base + k);
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
    const bool inst = h.instId != 0xFFFFFFFFu;
    const Impl::GeomInfo& gi = _impl->geoms[inst ? h.instId : h.geomId];
    const auto& tris = inst ? _impl->protoColors[size_t(gi.prototype)] : _impl->meshColors[size_t(gi.mesh)];
    if (h.primId >= tris.size()) return {1.0f, 0.0f, 1.0f};  // cannot happen for a hit of this scene
    const TriColors& t = tris[h.primId];
    const glm::vec3 c0 = glm::vec3(t.c[0]) / 255.0f, c1 = glm::vec3(t.c[1]) / 255.0f, c2 = glm::vec3(t.c[2]) / 255.0f;
    return (1.0f - h.u - h.v) * c0 + h.u * c1 + h.v * c2;
}

size_t RayScene::triangleCount() const { return _impl->triangles; }

RTCSceneTy* RayScene::embreeScene() const { return _impl->scene; }

}  // namespace vista
