// A rig camera's image by ray casting (rig_camera.h).
#include "runtime/engine/rig_camera.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/parallel_for.h>

#include "citygen/labels.h"
#include "runtime/engine/far_field_rays.h"
#include "runtime/engine/far_field_stages.h"
#include "runtime/engine/ground_truth.h"
#include "runtime/engine/ray_scene.h"

namespace vista {

namespace {

// OpenCV camera frame (x right, y down, z forward) <-> sensor frame (x forward, y left, z up).
glm::dvec3 cvToBody(const glm::dvec3& c) { return {c.z, -c.x, -c.y}; }
glm::dvec3 bodyToCv(const glm::dvec3& b) { return {-b.y, -b.z, b.x}; }

// Rows per parallel task.
constexpr size_t kRowsPerTask = 4;

void resizeChannels(const CameraShot& s, CameraImages& out) {
    const int w = s.model.width, h = s.model.height;
    const size_t n = size_t(w) * size_t(h);
    out.width = w;
    out.height = h;
    if (s.channels & kRigRgb) {
        if (out.rgb.width != w || out.rgb.height != h) out.rgb = Image(w, h);
    } else {
        out.rgb = Image();
    }
    auto fit = [n](auto& v, bool asked, size_t per) {
        if (asked) v.resize(n * per);
        else std::vector<typename std::decay_t<decltype(v)>::value_type>().swap(v);
    };
    fit(out.depth, (s.channels & kRigDepth) != 0, 1);
    fit(out.classes, (s.channels & kRigSemantic) != 0, 1);
    fit(out.ids, (s.channels & (kRigInstance | kRigBoxes)) != 0, 1);
    fit(out.flow, (s.channels & kRigFlow) != 0, 2);
}

}  // namespace

bool shotRay(const CameraShot& shot, double u, double v, glm::dvec3& worldDir) {
    glm::dvec3 c;
    if (!shot.model.pixelRay(u, v, c)) return false;
    worldDir = shot.pose.rotation * cvToBody(c);
    return true;
}

bool projectWorld(const CameraModel& model, const RigPose& pose, const glm::dvec3& world, glm::dvec2& uv) {
    return model.project(bodyToCv(glm::transpose(pose.rotation) * (world - pose.position)), uv);
}

namespace {

// The motion of the mover a hit lies on, null for the static scene or a mover without one.
const ObjectMotion* motionOf(const std::vector<ObjectMotion>& motions, const RayScene& rays, const RayHit& h) {
    const HitSource src = rays.source(h);
    if (src.mover < 0) return nullptr;
    auto it = std::lower_bound(motions.begin(), motions.end(), src.moverId,
                               [](const ObjectMotion& m, uint32_t v) { return m.id < v; });
    return it != motions.end() && it->id == src.moverId ? &*it : nullptr;
}

}  // namespace

void castRigCamera(const SceneModel& city, const RayScene& rays, const CameraShot& s, CameraImages& out, int threads) {
    VISTA_CHECK(s.model.width >= 1 && s.model.height >= 1 && s.channels != 0);
    resizeChannels(s, out);
    const int W = s.model.width, H = s.model.height;
    const glm::vec3 org(s.pose.position - rays.frameOrigin());
    const bool wantRgb = (s.channels & kRigRgb) != 0, wantDepth = (s.channels & kRigDepth) != 0;
    const bool wantCls = (s.channels & kRigSemantic) != 0, wantIds = (s.channels & (kRigInstance | kRigBoxes)) != 0;
    const bool wantFlow = (s.channels & kRigFlow) != 0;
    const glm::dmat3 nextInv = glm::transpose(s.next.rotation);
    const CameraRayTable* table = s.rays && s.rays->matches(s.model) ? s.rays : nullptr;
    inArena(threads, [&] {
        tbb::parallel_for(tbb::blocked_range<int>(0, H, int(kRowsPerTask)), [&](const tbb::blocked_range<int>& br) {
            std::vector<glm::vec3> orgs, dirs;
            std::vector<glm::dvec3> ddirs;
            std::vector<int> cols;
            std::vector<RayHit> res;
            for (int y = br.begin(); y != br.end(); ++y) {
                orgs.clear(), dirs.clear(), ddirs.clear(), cols.clear();
                for (int x = 0; x < W; ++x) {
                    const size_t p = size_t(y) * size_t(W) + size_t(x);
                    glm::dvec3 d;
                    const bool inside = table ? table->inside(p) : shotRay(s, x, y, d);
                    if (table && inside) d = s.pose.rotation * cvToBody(table->dir(p));
                    if (inside) {
                        orgs.push_back(org);
                        dirs.push_back(glm::vec3(d));
                        ddirs.push_back(d);
                        cols.push_back(x);
                        continue;
                    }
                    if (wantRgb) out.rgb.set(x, y, {0, 0, 0, 255});
                    if (wantDepth) out.depth[p] = std::numeric_limits<float>::quiet_NaN();
                    if (wantCls) out.classes[p] = 255;
                    if (wantIds) out.ids[p] = 0;
                    if (wantFlow) out.flow[2 * p] = out.flow[2 * p + 1] = kUnknownFlow;
                }
                res.resize(orgs.size());
                if (!orgs.empty()) rays.intersectMany(orgs.data(), dirs.data(), int(orgs.size()), res.data());
                for (size_t k = 0; k < cols.size(); ++k) {
                    const int x = cols[k];
                    const size_t p = size_t(y) * size_t(W) + size_t(x);
                    const RayHit& h = res[k];
                    const glm::dvec3& d = ddirs[k];
                    if (wantRgb) out.rgb.set(x, y, h.hit ? h.color : s.fx ? s.fx->sky(d) : primarySkyColor(d));
                    if (wantDepth) {
                        const double along = s.model.fisheye() ? 1.0 : glm::dot(d, s.pose.rotation[0]);
                        out.depth[p] = h.hit ? float(double(h.t) * along) : std::numeric_limits<float>::infinity();
                    }
                    if (wantCls || wantIds) {
                        const PixelLabel l = h.hit ? rayLabel(city, rays, h) : PixelLabel{};
                        if (wantCls) out.classes[p] = l.cls;
                        if (wantIds) out.ids[p] = l.id;
                    }
                    if (wantFlow) {
                        // The hit point (moved with its object), or the direction of a point at infinity (sky).
                        glm::dvec3 hitAt = s.pose.position + double(h.t) * d;
                        bool known = true;
                        if (h.hit && s.motions) {
                            if (const ObjectMotion* m = motionOf(*s.motions, rays, h)) {
                                known = m->known;
                                hitAt = glm::dvec3(m->motion * glm::dvec4(hitAt, 1.0));
                            }
                        }
                        const glm::dvec3 q = h.hit ? nextInv * (hitAt - s.next.position) : nextInv * d;
                        glm::dvec2 uv;
                        const bool ok = known && s.model.project(bodyToCv(q), uv);
                        out.flow[2 * p] = ok ? float(uv.x - x) : kUnknownFlow;
                        out.flow[2 * p + 1] = ok ? float(uv.y - y) : kUnknownFlow;
                    }
                }
            }
        });
    });
}

}  // namespace vista
