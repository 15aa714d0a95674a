#include "bake/far_scene.h"

#include <cmath>
#include <mutex>

#include <embree3/rtcore.h>

namespace vista {
namespace {

RTCDevice sharedDevice() {
    static std::once_flag once;
    static RTCDevice dev = nullptr;
    std::call_once(once, [] { dev = rtcNewDevice("threads=0"); });
    return dev;
}

}  // namespace

struct FarScene::Impl {
    RTCScene scene = nullptr;
    std::vector<glm::vec3> colors;  // per vertex, 0..1
    std::vector<uint32_t> indices;
    size_t tris = 0;
    ~Impl() {
        if (scene) rtcReleaseScene(scene);
    }
};

FarScene::FarScene() : _impl(new Impl) {}
FarScene::~FarScene() = default;
size_t FarScene::triangleCount() const { return _impl->tris; }

Result<std::unique_ptr<FarScene>> FarScene::build(const TriangleSoup& soup) {
    if (soup.colors.size() != soup.positions.size())
        return Status::error("far scene: colour count " + std::to_string(soup.colors.size()) + " != vertex count " +
                             std::to_string(soup.positions.size()));
    if (soup.indices.size() % 3 != 0) return Status::error("far scene: index count is not a multiple of 3");
    for (uint32_t i : soup.indices)
        if (i >= soup.positions.size()) return Status::error("far scene: index " + std::to_string(i) + " out of range");
    for (const auto& p : soup.positions)
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return Status::error("far scene: non-finite vertex");
    RTCDevice dev = sharedDevice();
    if (!dev) return Status::error("far scene: Embree device creation failed");
    std::unique_ptr<FarScene> fs(new FarScene);
    Impl& im = *fs->_impl;
    im.scene = rtcNewScene(dev);
    rtcSetSceneBuildQuality(im.scene, RTC_BUILD_QUALITY_MEDIUM);
    im.tris = soup.triangleCount();
    if (im.tris > 0) {
        RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* vb = static_cast<float*>(
            rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), soup.positions.size()));
        auto* ib = static_cast<uint32_t*>(
            rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), im.tris));
        if (!vb || !ib) {
            rtcReleaseGeometry(g);
            return Status::error("far scene: Embree buffer allocation failed");
        }
        for (size_t i = 0; i < soup.positions.size(); ++i) {
            vb[3 * i] = soup.positions[i].x; vb[3 * i + 1] = soup.positions[i].y; vb[3 * i + 2] = soup.positions[i].z;
        }
        std::copy(soup.indices.begin(), soup.indices.end(), ib);
        rtcCommitGeometry(g);
        rtcAttachGeometry(im.scene, g);
        rtcReleaseGeometry(g);
    }
    rtcCommitScene(im.scene);
    if (rtcGetDeviceError(dev) != RTC_ERROR_NONE) return Status::error("far scene: Embree error while building");
    im.colors.resize(soup.colors.size());
    for (size_t i = 0; i < soup.colors.size(); ++i) im.colors[i] = glm::vec3(soup.colors[i]) / 255.0f;
    im.indices = soup.indices;
    return fs;
}

FarHit FarScene::intersect(const glm::vec3& org, const glm::vec3& dir, float tnear, float tfar) const {
    FarHit h;
    if (_impl->tris == 0 || !(tfar > tnear)) return h;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh;
    rh.ray.org_x = org.x; rh.ray.org_y = org.y; rh.ray.org_z = org.z;
    rh.ray.dir_x = dir.x; rh.ray.dir_y = dir.y; rh.ray.dir_z = dir.z;
    rh.ray.tnear = tnear; rh.ray.tfar = tfar;
    rh.ray.time = 0; rh.ray.mask = 0xFFFFFFFFu; rh.ray.id = 0; rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(_impl->scene, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return h;
    h.hit = true;
    h.t = rh.ray.tfar;
    glm::vec3 n(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
    const float len = glm::length(n);
    h.normal = len > 0 ? n / len : glm::vec3(0, 0, 1);
    const uint32_t* tri = &_impl->indices[size_t(rh.hit.primID) * 3];
    const float u = rh.hit.u, v = rh.hit.v;
    h.color = (1.0f - u - v) * _impl->colors[tri[0]] + u * _impl->colors[tri[1]] + v * _impl->colors[tri[2]];
    return h;
}

bool FarScene::occluded(const glm::vec3& org, const glm::vec3& dir, float tnear, float tfar) const {
    if (_impl->tris == 0 || !(tfar > tnear)) return false;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay r;
    r.org_x = org.x; r.org_y = org.y; r.org_z = org.z;
    r.dir_x = dir.x; r.dir_y = dir.y; r.dir_z = dir.z;
    r.tnear = tnear; r.tfar = tfar; r.time = 0; r.mask = 0xFFFFFFFFu; r.id = 0; r.flags = 0;
    rtcOccluded1(_impl->scene, &ctx, &r);
    return r.tfar < 0;
}

int FarScene::allHits(const glm::vec3& org, const glm::vec3& dir, float tnear, float tfar, int maxHits, float minGap,
                      FarHit* out) const {
    int n = 0;
    float t0 = tnear;
    while (n < maxHits) {
        FarHit h = intersect(org, dir, t0, tfar);
        if (!h.hit) break;
        out[n++] = h;
        t0 = h.t + std::max(minGap, h.t * 1e-5f);
    }
    return n;
}

}  // namespace vista
