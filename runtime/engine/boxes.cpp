// Bounding boxes for dataset ground truth (boxes.h): 3D boxes per object
// instance, 2D boxes per frame, and their writers.
#include "runtime/engine/boxes.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <unordered_map>

#include <nlohmann/json.hpp>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "foundation/status.h"
#include "foundation/units.h"
#include "runtime/engine/far_field_stages.h"

namespace vista {

bool isObjectKind(InstanceKind k) {
    switch (k) {
        case InstanceKind::Building:
        case InstanceKind::Tree:
        case InstanceKind::StreetLight:
        case InstanceKind::TrafficLight:
        case InstanceKind::TrafficSign:
        case InstanceKind::Car:
        case InstanceKind::Vehicle:
        case InstanceKind::Pedestrian: return true;
        default: return false;
    }
}

glm::dvec3 OrientedBox::lengthAxis() const { return {std::cos(yaw), std::sin(yaw), 0.0}; }
glm::dvec3 OrientedBox::widthAxis() const { return {-std::sin(yaw), std::cos(yaw), 0.0}; }

std::array<glm::dvec3, 8> OrientedBox::corners() const {
    const glm::dvec3 a = 0.5 * size.x * lengthAxis(), b = 0.5 * size.y * widthAxis(), h(0.0, 0.0, 0.5 * size.z);
    const glm::dvec3 ring[4] = {-a - b, a - b, a + b, -a + b};
    std::array<glm::dvec3, 8> out;
    for (int k = 0; k < 4; ++k) {
        out[size_t(k)] = center + ring[k] - h;
        out[size_t(k) + 4] = center + ring[k] + h;
    }
    return out;
}

bool OrientedBox::contains(const glm::dvec3& p, double margin) const {
    const glm::dvec3 d = p - center;
    return std::abs(glm::dot(d, lengthAxis())) <= 0.5 * size.x + margin &&
           std::abs(glm::dot(d, widthAxis())) <= 0.5 * size.y + margin && std::abs(d.z) <= 0.5 * size.z + margin;
}

namespace {

double cross2(const glm::dvec2& o, const glm::dvec2& a, const glm::dvec2& b) {
    return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

// Counter-clockwise convex hull without collinear points (Andrew's monotone chain).
std::vector<glm::dvec2> convexHull(std::vector<glm::dvec2> p) {
    std::sort(p.begin(), p.end(),
              [](const glm::dvec2& a, const glm::dvec2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
    p.erase(std::unique(p.begin(), p.end()), p.end());
    if (p.size() < 3) return p;
    std::vector<glm::dvec2> h(2 * p.size());
    size_t k = 0;
    for (size_t i = 0; i < p.size(); ++i) {
        while (k >= 2 && cross2(h[k - 2], h[k - 1], p[i]) <= 0) --k;
        h[k++] = p[i];
    }
    for (size_t i = p.size() - 1, t = k + 1; i-- > 0;) {
        while (k >= t && cross2(h[k - 2], h[k - 1], p[i]) <= 0) --k;
        h[k++] = p[i];
    }
    h.resize(k - 1);
    return h;
}

double wrapHalfTurn(double yaw) {  // into (-pi/2, pi/2]
    while (yaw > kHalfPi) yaw -= kPi;
    while (yaw <= -kHalfPi) yaw += kPi;
    return yaw;
}

}  // namespace

OrientedBox fitUprightBox(const std::vector<glm::dvec3>& points) {
    OrientedBox box;
    if (points.empty()) return box;
    const glm::dvec2 ref(points[0]);
    double zLo = points[0].z, zHi = points[0].z;
    std::vector<glm::dvec2> xy(points.size());
    for (size_t i = 0; i < points.size(); ++i) {
        xy[i] = glm::dvec2(points[i]) - ref;
        zLo = std::min(zLo, points[i].z);
        zHi = std::max(zHi, points[i].z);
    }
    const std::vector<glm::dvec2> hull = convexHull(std::move(xy));
    box.center = glm::dvec3(ref + hull[0], 0.5 * (zLo + zHi));
    box.size = glm::dvec3(0.0, 0.0, zHi - zLo);
    double best = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < hull.size() && hull.size() > 1; ++i) {
        const glm::dvec2 edge = hull[(i + 1) % hull.size()] - hull[i];
        if (glm::length(edge) <= 0) continue;
        const glm::dvec2 e = glm::normalize(edge), n(-e.y, e.x);
        double eLo = 1e300, eHi = -1e300, nLo = 1e300, nHi = -1e300;
        for (const glm::dvec2& q : hull) {
            const double a = glm::dot(q, e), b = glm::dot(q, n);
            eLo = std::min(eLo, a), eHi = std::max(eHi, a), nLo = std::min(nLo, b), nHi = std::max(nHi, b);
        }
        const double area = (eHi - eLo) * (nHi - nLo);
        if (!(area < best)) continue;
        best = area;
        const glm::dvec2 c = ref + e * (0.5 * (eLo + eHi)) + n * (0.5 * (nLo + nHi));
        box.center = glm::dvec3(c, 0.5 * (zLo + zHi));
        const bool swap = nHi - nLo > eHi - eLo;
        const glm::dvec2 axis = swap ? n : e;
        box.size = glm::dvec3(swap ? nHi - nLo : eHi - eLo, swap ? eHi - eLo : nHi - nLo, zHi - zLo);
        box.yaw = wrapHalfTurn(std::atan2(axis.y, axis.x));
    }
    return box;
}

const InstanceBox* CityBoxes::find(uint32_t id) const {
    auto it =
        std::lower_bound(boxes.begin(), boxes.end(), id, [](const InstanceBox& b, uint32_t v) { return b.id < v; });
    return it != boxes.end() && it->id == id ? &*it : nullptr;
}

namespace {

// The label id of triangle `prim` of a tile mesh (its first vertex's; 0 without labels).
uint32_t triangleLabel(const SceneMesh& m, size_t prim) {
    const uint32_t v = m.indices[prim * 3];
    return v < m.ids.size() ? m.ids[v] : 0u;
}

bool labelledMesh(const SceneMesh& m) { return !m.ids.empty() && m.ids.size() == m.positions.size(); }

// Calls f(world a, world b, world c) for every triangle of the instance.
template <class F>
void forEachTriangle(const SceneModel& city, const CityBoxes& boxes, const InstanceBox& box, const F& f) {
    for (uint32_t k = 0; k < box.triangleCount; ++k) {
        const MeshTriangle& t = boxes.triangles[box.firstTriangle + k];
        const SceneMesh& m = city.meshes[t.mesh];
        const uint32_t* idx = &m.indices[size_t(t.prim) * 3];
        f(m.origin + glm::dvec3(m.positions[idx[0]]), m.origin + glm::dvec3(m.positions[idx[1]]),
          m.origin + glm::dvec3(m.positions[idx[2]]));
    }
    auto trees = [&](const std::vector<SceneInstance>& list, const std::vector<uint32_t>& which) {
        std::vector<glm::dvec3> world;
        for (uint32_t i : which) {
            const SceneInstance& in = list[i];
            if (in.prototype >= city.prototypes.size()) continue;
            const SceneMesh& p = city.prototypes[in.prototype];
            world.resize(p.positions.size());
            for (size_t v = 0; v < p.positions.size(); ++v)
                world[v] = glm::dvec3(in.transform * glm::dvec4(glm::dvec3(p.positions[v]), 1.0));
            for (size_t t = 0; t + 2 < p.indices.size(); t += 3)
                f(world[p.indices[t]], world[p.indices[t + 1]], world[p.indices[t + 2]]);
        }
    };
    trees(city.instances, box.trees);
    trees(city.impostors, box.impostors);
}

}  // namespace

std::vector<glm::dvec3> instancePoints(const SceneModel& city, const CityBoxes& boxes, const InstanceBox& box) {
    std::vector<glm::dvec3> out;
    forEachTriangle(city, boxes, box, [&](const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
        out.push_back(a), out.push_back(b), out.push_back(c);
    });
    return out;
}

namespace {

// The tile-mesh triangles of object instances, sorted by (id, mesh, prim).
struct TriangleRef {
    uint32_t id, mesh, prim;
};

std::vector<TriangleRef> objectTriangles(const SceneModel& city) {
    std::vector<TriangleRef> refs;
    for (size_t mi = 0; mi < city.meshes.size(); ++mi) {
        const SceneMesh& m = city.meshes[mi];
        if (!labelledMesh(m)) continue;
        for (size_t t = 0; t < m.indices.size() / 3; ++t) {
            const uint32_t id = triangleLabel(m, t);
            if (id != 0 && isObjectKind(instanceKind(id))) refs.push_back({id, uint32_t(mi), uint32_t(t)});
        }
    }
    std::sort(refs.begin(), refs.end(), [](const TriangleRef& a, const TriangleRef& b) {
        return a.id != b.id ? a.id < b.id : a.mesh != b.mesh ? a.mesh < b.mesh : a.prim < b.prim;
    });
    return refs;
}

}  // namespace

CityBoxes buildCityBoxes(const SceneModel& city, int threads) {
    CityBoxes out;
    std::map<uint32_t, size_t> at;  // id -> index in out.boxes
    auto boxOf = [&](uint32_t id) -> InstanceBox& {
        auto [it, fresh] = at.emplace(id, out.boxes.size());
        if (fresh) {
            out.boxes.emplace_back();
            out.boxes.back().id = id;
        }
        return out.boxes[it->second];
    };
    const std::vector<TriangleRef> refs = objectTriangles(city);
    out.triangles.reserve(refs.size());
    for (size_t i = 0; i < refs.size(); ++i) {
        InstanceBox& b = boxOf(refs[i].id);
        if (b.triangleCount == 0) b.firstTriangle = uint32_t(i);
        ++b.triangleCount;
        out.triangles.push_back({refs[i].mesh, refs[i].prim});
    }
    std::vector<uint32_t> treeIds;
    for (size_t i = 0; i < city.instances.size(); ++i) {
        const uint32_t id = city.instances[i].id;
        if (id == 0 || !isObjectKind(instanceKind(id))) continue;
        boxOf(id).trees.push_back(uint32_t(i));
        treeIds.push_back(id);
    }
    std::sort(treeIds.begin(), treeIds.end());
    for (size_t i = 0; i < city.impostors.size(); ++i) {
        const uint32_t id = city.impostors[i].id;
        if (id == 0 || !isObjectKind(instanceKind(id)) || std::binary_search(treeIds.begin(), treeIds.end(), id))
            continue;
        boxOf(id).impostors.push_back(uint32_t(i));
    }
    std::sort(out.boxes.begin(), out.boxes.end(),
              [](const InstanceBox& a, const InstanceBox& b) { return a.id < b.id; });
    inArena(threads, [&] {
        tbb::parallel_for(size_t(0), out.boxes.size(),
                          [&](size_t i) { out.boxes[i].box = fitUprightBox(instancePoints(city, out, out.boxes[i])); });
    });
    return out;
}

OrientedBox boxInVehicleFrame(const OrientedBox& world, const LidarPose& pose) {
    Camera c;
    c.heading = pose.heading;
    c.pitch = pose.pitch;
    c.roll = pose.roll;
    const glm::dvec3 fwd = c.forward(), left = -c.right(), up = c.up();
    const glm::dvec3 d = world.center - pose.position, axis = world.lengthAxis();
    OrientedBox v = world;
    v.center = glm::dvec3(glm::dot(d, fwd), glm::dot(d, left), glm::dot(d, up));
    v.yaw = wrapHalfTurn(std::atan2(glm::dot(axis, left), glm::dot(axis, fwd)));
    return v;
}

PinholeIntrinsics pinholeIntrinsics(const Camera& camera) {
    PinholeIntrinsics k;
    k.fy = 0.5 * camera.height / std::tan(0.5 * camera.fovY);
    k.fx = k.fy;
    k.cx = 0.5 * (camera.width - 1);
    k.cy = 0.5 * (camera.height - 1);
    return k;
}

BoxCamera boxCamera(const Camera& camera) {
    BoxCamera b;
    b.eye = camera.eye;
    b.axes = glm::dmat3(camera.right(), -camera.up(), camera.forward());
    const PinholeIntrinsics k = pinholeIntrinsics(camera);
    b.model.kind = CameraModel::Kind::Pinhole;
    b.model.width = camera.width, b.model.height = camera.height;
    b.model.fx = k.fx, b.model.fy = k.fy, b.model.cx = k.cx, b.model.cy = k.cy;
    b.zNear = camera.zNear;
    return b;
}

glm::dvec3 cameraPoint(const Camera& camera, const glm::dvec3& world) {
    const glm::dvec3 d = world - camera.eye;
    return {glm::dot(d, camera.right()), -glm::dot(d, camera.up()), glm::dot(d, camera.forward())};
}

namespace {

void extend(PixelBox& b, const glm::dvec2& p) {
    if (!b.valid()) {
        b = {p.x, p.y, p.x, p.y};
        return;
    }
    b.u0 = std::min(b.u0, p.x), b.v0 = std::min(b.v0, p.y);
    b.u1 = std::max(b.u1, p.x), b.v1 = std::max(b.v1, p.y);
}

void extend(PixelBox& b, const PixelBox& o) {
    if (o.valid()) extend(b, glm::dvec2(o.u0, o.v0)), extend(b, glm::dvec2(o.u1, o.v1));
}

// The camera's axes and model, evaluated once.
struct Projector {
    glm::dvec3 eye;
    glm::dmat3 toCam;  // world offsets -> camera coordinates
    CameraModel m;
    double zNear;
    double thetaMax;  // fisheye: the image circle's half angle
    double cosMax;    // its cosine
    explicit Projector(const BoxCamera& c)
        : eye(c.eye),
          toCam(glm::transpose(c.axes)),
          m(c.model),
          zNear(c.zNear),
          thetaMax(std::min(kPi, 0.5 * c.model.maxFovDeg * kPi / 180.0)),
          cosMax(std::cos(thetaMax)) {
        VISTA_CHECK(m.fisheye() || zNear > 0.0);
    }
    glm::dvec3 toCamera(const glm::dvec3& w) const { return toCam * (w - eye); }
    // Pinhole pixel coordinates of a camera point with z > 0.
    glm::dvec2 pixel(const glm::dvec3& p) const { return {m.fx * p.x / p.z + m.cx, m.fy * p.y / p.z + m.cy}; }
    // The point where segment a-b crosses the near plane (a and b on either side).
    glm::dvec3 nearCrossing(const glm::dvec3& a, const glm::dvec3& b) const {
        const double t = (zNear - a.z) / (b.z - a.z);
        glm::dvec3 p = a + t * (b - a);
        p.z = zNear;
        return p;
    }
    // Fisheye: true when the direction of p lies within the image circle's
    // cone, atan2(|p.xy|, p.z) <= thetaMax. Where the cosine of p's angle to
    // the axis lies more than 1e-12 from cosMax it decides (an angle differs
    // from thetaMax by at least as much as its cosine from cosMax, and both
    // sides round by some 1e-16), without the arc tangent; the answer is the
    // same.
    bool inCone(const glm::dvec3& p) const {
        const double l2 = p.x * p.x + p.y * p.y + p.z * p.z;
        if (l2 > 1e-200 && l2 < 1e200) {
            const double c = p.z / std::sqrt(l2);
            if (c > cosMax + 1e-12) return true;
            if (c < cosMax - 1e-12) return false;
        }
        const double rho = std::hypot(p.x, p.y);
        return (rho > 0.0 || p.z > 0.0) && std::atan2(rho, p.z) <= thetaMax;
    }
    // Fisheye: inCone(p) and, when it holds, uv = fisheyePixel(p), from one
    // hypot and one atan2 (the same expressions as inCone and project).
    bool conePixel(const glm::dvec3& p, glm::dvec2& uv) const {
        const double rho = std::hypot(p.x, p.y);
        if (!(rho > 0.0 || p.z > 0.0)) return false;
        const double theta = std::atan2(rho, p.z);
        if (!(theta <= thetaMax)) return false;
        if (rho == 0.0) uv = {m.cx, m.cy};
        else uv = {m.cx + m.fx * theta * p.x / rho, m.cy + m.fy * theta * p.y / rho};
        return true;
    }
    // Fisheye: the pixel of a camera point (not the origin).
    glm::dvec2 fisheyePixel(const glm::dvec3& p) const {
        glm::dvec2 uv(m.cx, m.cy);
        m.project(p, uv);
        return uv;
    }
};

bool within(const PixelBox& inner, const PixelBox& outer) {
    return outer.valid() && (!inner.valid() || (inner.u0 >= outer.u0 && inner.v0 >= outer.v0 && inner.u1 <= outer.u1 &&
                                                inner.v1 <= outer.v1));
}

// The point where p moves into or out of the cone between a (inside == aIn) and b.
glm::dvec3 coneCrossing(const Projector& pr, glm::dvec3 a, glm::dvec3 b, bool aIn) {
    for (int i = 0; i < 40; ++i) {
        const glm::dvec3 mid = 0.5 * (a + b);
        (pr.inCone(mid) == aIn ? a : b) = mid;
    }
    return aIn ? a : b;
}

PixelBox fisheyeCapBound(const Projector& pr, const glm::dvec3& c, double r);

// An upper bound of acos(c) for c in [0, 1] without the call: with x = 1 - c,
// acos(c) / sqrt(2 x) is a series in x with positive coefficients (convex,
// 1 at x = 0, pi / (2 sqrt 2) = 1.11072... at x = 1), so it lies below the
// chord 1 + 0.1108 x. Within a few parts in 10^4 of acos for the small caps
// of a triangle's or an edge run's directions.
double acosAbove(double c) {
    const double x = 1.0 - std::min(1.0, c);
    return std::sqrt(2.0 * x) * (1.0 + 0.1108 * x);
}

// The cap of the directions of segment a-b (camera coordinates): around the
// mean of its end directions, half the angle between them (padded); false
// when an end is the origin or the cap is not narrower than 80 degrees.
bool segmentCap(const glm::dvec3& a, const glm::dvec3& b, glm::dvec3& c, double& r) {
    const double la = glm::length(a), lb = glm::length(b);
    if (!(la > 0.0 && lb > 0.0)) return false;
    const glm::dvec3 na = a / la, nb = b / lb, sum = na + nb;
    const double ls = glm::length(sum);
    if (!(ls > 0.0)) return false;
    c = sum / ls;
    const double cosR = std::min(glm::dot(c, na), glm::dot(c, nb));
    if (!(cosR > 0.2)) return false;
    r = acosAbove(cosR) + 1e-9;
    return true;
}

// The fisheye image of segment a-b within the cone, sampled at most about 1
// px apart. With `known` (an extent the result is merged into): a run of
// kEdgeRun samples (or the last kMinRun or more of the edge) whose segment's
// cap lies wholly inside the cone and whose image (fisheyeCapBound) lies
// within `known` and the extent so far cannot widen the merged extent and is
// not sampled; `skipped` is then set. A run that fails the test is sampled
// and not tested again.
constexpr int kEdgeRun = 32, kMinRun = 4;
void fisheyeEdge(const Projector& pr, const glm::dvec3& a, const glm::dvec3& b, PixelBox& out,
                 const PixelBox* known = nullptr, bool* skipped = nullptr) {
    const double la = glm::length(a), lb = glm::length(b);
    const double angle = la > 0 && lb > 0 ? std::acos(std::clamp(glm::dot(a, b) / (la * lb), -1.0, 1.0)) : kPi;
    const int n = int(std::clamp(std::ceil(angle * std::max(pr.m.fx, pr.m.fy)), 1.0, 4096.0));
    glm::dvec3 prev = a;
    glm::dvec2 uv;
    bool prevIn = pr.conePixel(a, uv);
    if (prevIn) extend(out, uv);
    int nextTest = 1;  // the first sample of the next run to test
    for (int k = 1; k <= n; ++k) {
        if (known && prevIn && k >= nextTest && n - k + 1 >= kMinRun) {
            // Samples k .. last lie on the segment from prev (inside the cone) to the run's last.
            const int last = std::min(n, k + kEdgeRun - 1);
            nextTest = last + 1;
            const glm::dvec3 q = a + (double(last) / n) * (b - a);
            glm::dvec3 c;
            double r;
            if (segmentCap(prev, q, c, r) && std::atan2(std::hypot(c.x, c.y), c.z) + r < pr.thetaMax - 1e-9) {
                PixelBox merged = *known;
                extend(merged, out);
                if (within(fisheyeCapBound(pr, c, r), merged)) {
                    prev = q, prevIn = true, k = last;
                    *skipped = true;
                    continue;
                }
            }
        }
        const glm::dvec3 p = a + (double(k) / n) * (b - a);
        const bool in = pr.conePixel(p, uv);
        if (in) extend(out, uv);
        if (in != prevIn) extend(out, pr.fisheyePixel(coneCrossing(pr, prev, p, prevIn)));
        prev = p, prevIn = in;
    }
}

// A triangle (camera coordinates) with the cross products that decide
// whether a ray from the origin passes through it (rayThroughTriangle),
// computed once for the many pixels a fill tests.
struct RayTriangle {
    glm::dvec3 n0, n1, n2;  // p1 x p2, p2 x p0, p0 x p1
    double det;             // p0 . (p1 x p2)
    explicit RayTriangle(const glm::dvec3* p)
        : n0(glm::cross(p[1], p[2])), n1(glm::cross(p[2], p[0])), n2(glm::cross(p[0], p[1])), det(glm::dot(p[0], n0)) {}
    bool hit(const glm::dvec3& d) const {
        if (det == 0.0) return false;
        const double a = glm::dot(d, n0), b = glm::dot(d, n1), c = glm::dot(d, n2);
        return det > 0 ? a >= 0 && b >= 0 && c >= 0 : a <= 0 && b <= 0 && c <= 0;
    }
};

// True when the ray from the origin along d passes through triangle p0 p1 p2 (edges included).
bool rayThroughTriangle(const glm::dvec3& d, const glm::dvec3* p) { return RayTriangle(p).hit(d); }

// A bound of the fisheye image within the cone of the cap of directions
// around the unit vector c with half angle r (r < pi/2): the cap's points
// have theta in [theta_c - r, theta_c + r] (clamped to [0, thetaMax]) and,
// when the cap holds neither pole, an azimuth within h of c's azimuth phi,
// sin h = sin r / sin theta_c (r in place of sin r, which is no larger); u - cx = fx theta cos(phi) and v - cy = fy
// theta sin(phi) over that polar rectangle take their extremes at its
// corners (theta >= 0), the cosine and sine ranges including their extremes
// inside the azimuth interval (azimuth x lies within h of phi when cos(x -
// phi) >= cos h). The azimuths' cosines and sines come from c's components
// (sin theta_c = |c.xy|) by the angle-sum rules, without a trigonometric
// call. An invalid box when the cap lies outside the image circle. Padded
// (1e-9 on the cosines and sines, 1e-6 px) so that rounding never makes it
// too small.
PixelBox fisheyeCapBound(const Projector& pr, const glm::dvec3& c, double r) {
    const double rhoC = std::sqrt(c.x * c.x + c.y * c.y), thetaC = std::atan2(rhoC, c.z);
    const double lo = std::max(0.0, thetaC - r), hi = std::min(pr.thetaMax, thetaC + r);
    if (lo > hi) return PixelBox{};
    double cLo = -1, cHi = 1, sLo = -1, sHi = 1;
    if (lo > 0.0 && thetaC + r < kPi && rhoC > 0.0) {
        constexpr double kEps = 1e-9;
        const double sinH = r / rhoC;  // r >= sin r: a wider interval, never a narrower one
        if (sinH < 1.0 - 1e-6) {
            const double cosH = std::sqrt(1.0 - sinH * sinH), cp = c.x / rhoC, sp = c.y / rhoC;
            const double ca = cp * cosH + sp * sinH, sa = sp * cosH - cp * sinH;  // azimuth phi - h
            const double cb = cp * cosH - sp * sinH, sb = sp * cosH + cp * sinH;  // azimuth phi + h
            cLo = std::max(-1.0, std::min(ca, cb) - kEps), cHi = std::min(1.0, std::max(ca, cb) + kEps);
            sLo = std::max(-1.0, std::min(sa, sb) - kEps), sHi = std::min(1.0, std::max(sa, sb) + kEps);
            // Extremes inside the interval: cos at azimuth 0 and pi, sin at pi/2 and -pi/2.
            if (cp >= cosH - kEps) cHi = 1;
            if (-cp >= cosH - kEps) cLo = -1;
            if (sp >= cosH - kEps) sHi = 1;
            if (-sp >= cosH - kEps) sLo = -1;
        }
    }
    const double uLo = std::min({lo * cLo, lo * cHi, hi * cLo, hi * cHi}),
                 uHi = std::max({lo * cLo, lo * cHi, hi * cLo, hi * cHi});
    const double vLo = std::min({lo * sLo, lo * sHi, hi * sLo, hi * sHi}),
                 vHi = std::max({lo * sLo, lo * sHi, hi * sLo, hi * sHi});
    const double pad = 1e-6;
    return {pr.m.cx + pr.m.fx * uLo - pad, pr.m.cy + pr.m.fy * vLo - pad, pr.m.cx + pr.m.fx * uHi + pad,
            pr.m.cy + pr.m.fy * vHi + pad};
}

// A bound of the fisheye image of a triangle (camera coordinates) within the
// cone, without sampling its edges: the triangle's directions lie in the cap
// around their mean direction c whose radius r is the largest angle from c to
// a vertex (a cap narrower than a hemisphere is a convex cone, so it holds
// the whole triangle), bounded by fisheyeCapBound. False (no bound) for a
// degenerate triangle or a cap of 87 degrees or more; an invalid box when the
// cap lies outside the image circle.
bool fisheyeTriangleBound(const Projector& pr, const glm::dvec3* p, PixelBox& out) {
    glm::dvec3 n[3];
    for (int i = 0; i < 3; ++i) {
        const double l = glm::length(p[i]);
        if (!(l > 0.0)) return false;
        n[i] = p[i] / l;
    }
    const glm::dvec3 sum = n[0] + n[1] + n[2];
    const double ls = glm::length(sum);
    if (!(ls > 0.0)) return false;
    const glm::dvec3 c = sum / ls;
    const double cosR = std::min({glm::dot(c, n[0]), glm::dot(c, n[1]), glm::dot(c, n[2])});
    if (!(cosR > 0.05)) return false;
    out = fisheyeCapBound(pr, c, acosAbove(cosR) + 1e-9);
    return true;
}

// The fisheye image of a triangle (camera coordinates) within the cone: its
// edges and the image circle's extreme points its area covers.
PixelBox fisheyeTriangleExtent(const Projector& pr, const glm::dvec3* p, const PixelBox* known = nullptr,
                               bool* skipped = nullptr) {
    PixelBox out;
    for (int i = 0; i < 3; ++i) fisheyeEdge(pr, p[i], p[(i + 1) % 3], out, known, skipped);
    const double st = std::sin(pr.thetaMax), ct = std::cos(pr.thetaMax);
    const double r[4][2] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};  // azimuth 0, 90, 180, 270 degrees
    for (const auto& q : r)
        if (rayThroughTriangle({st * q[0], st * q[1], ct}, p))
            extend(out, glm::dvec2(pr.m.cx + pr.m.fx * pr.thetaMax * q[0], pr.m.cy + pr.m.fy * pr.thetaMax * q[1]));
    return out;
}

}  // namespace

PixelBox projectedExtent(const BoxCamera& camera, const std::vector<glm::dvec3>& vertices,
                         const std::vector<std::array<int, 2>>& edges) {
    const Projector pr(camera);
    VISTA_CHECK(!pr.m.fisheye());
    std::vector<glm::dvec3> c(vertices.size());
    PixelBox out;
    for (size_t i = 0; i < vertices.size(); ++i) {
        c[i] = pr.toCamera(vertices[i]);
        if (c[i].z >= pr.zNear) extend(out, pr.pixel(c[i]));
    }
    for (const auto& e : edges) {
        const glm::dvec3 &a = c[size_t(e[0])], &b = c[size_t(e[1])];
        if ((a.z < pr.zNear) != (b.z < pr.zNear)) extend(out, pr.pixel(pr.nearCrossing(a, b)));
    }
    return out;
}

PixelBox projectedExtent(const Camera& camera, const std::vector<glm::dvec3>& vertices,
                         const std::vector<std::array<int, 2>>& edges) {
    return projectedExtent(boxCamera(camera), vertices, edges);
}

PixelBox projectedBox(const BoxCamera& camera, const OrientedBox& box) {
    const std::array<glm::dvec3, 8> c = box.corners();
    if (camera.model.fisheye()) {
        static const int kFaces[12][3] = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                                          {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
        const Projector pr(camera);
        PixelBox out;
        for (const auto& f : kFaces) {
            const glm::dvec3 p[3] = {pr.toCamera(c[size_t(f[0])]), pr.toCamera(c[size_t(f[1])]),
                                     pr.toCamera(c[size_t(f[2])])};
            bool skipped = false;  // runs within the faces' extent so far cannot widen it
            extend(out, fisheyeTriangleExtent(pr, p, &out, &skipped));
        }
        return out;
    }
    static const std::vector<std::array<int, 2>> kEdges = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6},
                                                           {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
    return projectedExtent(camera, std::vector<glm::dvec3>(c.begin(), c.end()), kEdges);
}

PixelBox projectedBox(const Camera& camera, const OrientedBox& box) { return projectedBox(boxCamera(camera), box); }

PixelBox clipToImage(const PixelBox& b, int width, int height) {
    if (!b.valid()) return b;
    PixelBox c{std::max(b.u0, -0.5), std::max(b.v0, -0.5), std::min(b.u1, width - 0.5), std::min(b.v1, height - 0.5)};
    return c.valid() ? c : PixelBox{};
}

PixelBox clipToImage(const PixelBox& b, const Camera& camera) { return clipToImage(b, camera.width, camera.height); }

namespace {

// The extent and pixel count of every id in an instance image, sorted by id.
struct VisibleStats {
    uint32_t id;
    int u0, v0, u1, v1;
    uint32_t count;
};

// The stats of rows [y0, y1) (in the order of their first pixel).
std::vector<VisibleStats> visibleRows(const std::vector<uint32_t>& ids, int width, int y0, int y1) {
    std::unordered_map<uint32_t, size_t> at;
    std::vector<VisibleStats> s;
    uint32_t lastId = 0;
    size_t last = 0;
    for (int y = y0; y < y1; ++y)
        for (int x = 0; x < width; ++x) {
            const uint32_t id = ids[size_t(y) * size_t(width) + size_t(x)];
            if (id == 0) continue;
            if (id != lastId) {
                auto [it, fresh] = at.emplace(id, s.size());
                if (fresh) s.push_back({id, x, y, x, y, 0});
                last = it->second;
                lastId = id;
            }
            VisibleStats& v = s[last];
            v.u0 = std::min(v.u0, x), v.v0 = std::min(v.v0, y), v.u1 = std::max(v.u1, x), v.v1 = std::max(v.v1, y);
            ++v.count;
        }
    return s;
}

// Bands of rows in parallel (in the caller's arena), merged: extents and
// counts combine exactly, so the result does not depend on the split.
std::vector<VisibleStats> visibleStats(const std::vector<uint32_t>& ids, int width, int height) {
    constexpr int kBand = 32;
    const int bands = (height + kBand - 1) / kBand;
    std::vector<std::vector<VisibleStats>> part(size_t(std::max(bands, 0)));
    tbb::parallel_for(0, bands, [&](int b) {
        part[size_t(b)] = visibleRows(ids, width, b * kBand, std::min(height, (b + 1) * kBand));
    });
    std::unordered_map<uint32_t, size_t> at;
    std::vector<VisibleStats> s;
    for (const std::vector<VisibleStats>& p : part)
        for (const VisibleStats& v : p) {
            auto [it, fresh] = at.emplace(v.id, s.size());
            if (fresh) {
                s.push_back(v);
                continue;
            }
            VisibleStats& w = s[it->second];
            w.u0 = std::min(w.u0, v.u0), w.v0 = std::min(w.v0, v.v0), w.u1 = std::max(w.u1, v.u1),
            w.v1 = std::max(w.v1, v.v1);
            w.count += v.count;
        }
    std::sort(s.begin(), s.end(), [](const VisibleStats& a, const VisibleStats& b) { return a.id < b.id; });
    return s;
}

// One instance's triangles through the camera: `full` = the extent of every
// triangle clipped against the near plane (pinhole) or the image circle's
// cone (fisheye); `covered` = the pixels whose centres its front faces
// cover (marked with `mark` in `stamp`, so each pixel counts once). A
// fisheye tile (camera_ray_table.h) whose pixels inside the image circle
// are all marked is marked in `tileStamp`, and later triangles skip it.
struct MaskStamps {
    std::vector<uint32_t> pixels, tiles;  // a mark per pixel, per ray-table tile
};
class MaskRaster {
public:
    MaskRaster(const Projector& pr, const CameraRayTable* rays, int width, int height, MaskStamps& stamps,
               uint32_t mark)
        : _pr(pr), _rays(rays), _w(width), _h(height), _stamp(stamps.pixels), _tileStamp(stamps.tiles), _mark(mark) {}
    PixelBox full;
    uint32_t covered = 0;

    // Fisheye: extends `full` by the vertices' pixels (those inside the cone).
    // Every vertex is the first sample of an edge of its triangle, so seeding
    // the extent with some of them first changes no extent, while the bounds
    // and runs of the triangles that follow fall within it more often.
    void seed(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
        glm::dvec2 uv;
        for (const glm::dvec3* w : {&a, &b, &c})
            if (_pr.conePixel(_pr.toCamera(*w), uv)) extend(full, uv);
    }

    void triangle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
        const glm::dvec3 p[3] = {_pr.toCamera(a), _pr.toCamera(b), _pr.toCamera(c)};
        // Camera coordinates are a rotation of the world's: counter-clockwise
        // seen from the eye (the origin) is a front face.
        const bool front = glm::dot(glm::cross(p[1] - p[0], p[2] - p[0]), p[0]) < 0;
        if (_pr.m.fisheye()) {
            // A triangle whose bound lies within the extent so far cannot widen
            // it: its edges are not sampled, and its pixels are sought in the
            // bound. With a bound, runs of edge samples that cannot widen the
            // extent are not sampled either, and when some were skipped the
            // triangle's extent is partial: its pixels are sought in the bound.
            PixelBox bound;
            const bool bounded = fisheyeTriangleBound(_pr, p, bound);
            if (bounded && full.valid() && within(bound, full)) {
                if (front && bound.valid()) fillSphere(p, bound, true);
                return;
            }
            bool skipped = false;
            const PixelBox e = fisheyeTriangleExtent(_pr, p, bounded ? &full : nullptr, &skipped);
            extend(full, e);
            const PixelBox& seek = skipped ? bound : e;
            if (front && seek.valid()) fillSphere(p, seek, skipped);
            return;
        }
        glm::dvec3 poly[4];
        int n = 0;
        for (int i = 0; i < 3; ++i) {
            const glm::dvec3 &cur = p[i], &nxt = p[(i + 1) % 3];
            const bool curIn = cur.z >= _pr.zNear, nxtIn = nxt.z >= _pr.zNear;
            if (curIn) poly[n++] = cur;
            if (curIn != nxtIn) poly[n++] = _pr.nearCrossing(cur, nxt);
        }
        if (n < 3) return;
        glm::dvec2 q[4];
        for (int i = 0; i < n; ++i) extend(full, q[i] = _pr.pixel(poly[i]));
        if (front) fill(q, n);
    }

private:
    // Marks the pixels whose centres lie in the convex polygon q (edges included).
    void fill(const glm::dvec2* q, int n) {
        double vLo = q[0].y, vHi = q[0].y;
        for (int i = 1; i < n; ++i) vLo = std::min(vLo, q[i].y), vHi = std::max(vHi, q[i].y);
        const int y0 = int(std::max(0.0, std::ceil(vLo))), y1 = int(std::min(double(_h - 1), std::floor(vHi)));
        for (int y = y0; y <= y1; ++y) {
            double uL = 1e300, uR = -1e300;
            for (int i = 0; i < n; ++i) {
                const glm::dvec2 &s = q[i], &e = q[(i + 1) % n];
                if (std::min(s.y, e.y) > y || std::max(s.y, e.y) < y) continue;
                if (s.y == e.y) {
                    uL = std::min(uL, std::min(s.x, e.x)), uR = std::max(uR, std::max(s.x, e.x));
                    continue;
                }
                const double u = s.x + (double(y) - s.y) * (e.x - s.x) / (e.y - s.y);
                uL = std::min(uL, u), uR = std::max(uR, u);
            }
            const int x0 = int(std::max(0.0, std::ceil(uL))), x1 = int(std::min(double(_w - 1), std::floor(uR)));
            uint32_t* row = &_stamp[size_t(y) * size_t(_w)];
            for (int x = x0; x <= x1; ++x)
                if (row[x] != _mark) row[x] = _mark, ++covered;
        }
    }
    static constexpr int kDirectFill = 48;  // pixels; fewer are tested one by one
    // Marks the pixels of extent e whose ray passes through the triangle p:
    // the pixels whose centre lies in e when e is a bound of the triangle's
    // image (`bounding`: fisheyeTriangleBound, which holds every direction
    // of the triangle), else e grown by a pixel for the sampling of curved
    // edges. Tile by tile
    // (CameraRayTable tiles): a tile whose cap lies beyond one of the
    // triangle's three planes through the eye by more than a margin is
    // skipped, one whose cap lies within all three by more than the margin
    // is marked whole (its pixels inside the circle), the others test each
    // pixel; the margin (1e-9 of a unit direction) dwarfs the rounding of
    // the per-pixel test, so the marked pixels are those the test marks. An
    // extent of a few pixels is tested pixel by pixel.
    void fillSphere(const glm::dvec3* p, const PixelBox& e, bool bounding) {
        const int x0 = int(std::max(0.0, bounding ? std::ceil(e.u0) : std::floor(e.u0) - 1)),
                  x1 = int(std::min(double(_w - 1), bounding ? std::floor(e.u1) : std::ceil(e.u1) + 1));
        const int y0 = int(std::max(0.0, bounding ? std::ceil(e.v0) : std::floor(e.v0) - 1)),
                  y1 = int(std::min(double(_h - 1), bounding ? std::floor(e.v1) : std::ceil(e.v1) + 1));
        if (x0 > x1 || y0 > y1) return;
        const RayTriangle tri(p);
        if (tri.det == 0.0) return;
        if ((x1 - x0 + 1) * (y1 - y0 + 1) <= kDirectFill) {  // a few pixels: no tile tests
            for (int y = y0; y <= y1; ++y) {
                const size_t at = size_t(y) * size_t(_w);
                uint32_t* row = &_stamp[at];
                for (int x = x0; x <= x1; ++x) {
                    const size_t q = at + size_t(x);
                    if (row[x] != _mark && _rays->inside(q) && tri.hit(_rays->dir(q))) row[x] = _mark, ++covered;
                }
            }
            return;
        }
        // The planes as unit normals m with the triangle's directions on m . d <= 0.
        const double side = tri.det > 0 ? -1.0 : 1.0;
        glm::dvec3 m[3] = {tri.n0, tri.n1, tri.n2};
        bool planes = true;
        for (glm::dvec3& n : m) {
            const double l = glm::length(n);
            if (!(l > 1e-200)) planes = false;
            else n *= side / l;
        }
        const int T = CameraRayTable::kTile;
        for (int ty = y0 / T; ty <= y1 / T; ++ty)
            for (int tx = x0 / T; tx <= x1 / T; ++tx) {
                const CameraRayTable::TileCap& cap = _rays->tile(tx, ty);
                if (!cap.anyInside) continue;
                uint32_t& tileMark = _tileStamp[size_t(ty) * size_t(_rays->tilesX()) + size_t(tx)];
                if (tileMark == _mark) continue;  // every pixel of it is marked already
                const int u0 = std::max(x0, tx * T), u1 = std::min(x1, tx * T + T - 1);
                const int v0 = std::max(y0, ty * T), v1 = std::min(y1, ty * T + T - 1);
                bool whole = false;
                if (planes && cap.hasCap) {
                    constexpr double kMargin = 1e-9;
                    bool outside = false;
                    whole = true;
                    for (const glm::dvec3& n : m) {
                        const double c = glm::dot(n, cap.axis), s = std::sqrt(std::max(0.0, 1.0 - c * c));
                        if (c * cap.cosR - s * cap.sinR > kMargin) outside = true;     // the cap's least m . d
                        if (!(c * cap.cosR + s * cap.sinR < -kMargin)) whole = false;  // its greatest
                    }
                    if (outside) continue;
                }
                // The whole tile lies in the extent: it is done when all its pixels inside the circle are marked.
                bool all = u0 == tx * T && v0 == ty * T && u1 == std::min(_w - 1, tx * T + T - 1) &&
                           v1 == std::min(_h - 1, ty * T + T - 1);
                for (int y = v0; y <= v1; ++y) {
                    const size_t at = size_t(y) * size_t(_w);
                    uint32_t* row = &_stamp[at];
                    for (int x = u0; x <= u1; ++x) {
                        const size_t q = at + size_t(x);
                        if (row[x] == _mark || !_rays->inside(q)) continue;
                        if (whole || tri.hit(_rays->dir(q))) row[x] = _mark, ++covered;
                        else all = false;
                    }
                }
                if (all) tileMark = _mark;
            }
    }
    const Projector& _pr;
    const CameraRayTable* _rays;  // fisheye: the model's pixel rays
    int _w, _h;
    std::vector<uint32_t>& _stamp;
    std::vector<uint32_t>& _tileStamp;
    uint32_t _mark;
};

constexpr uint32_t kSeedStride = 4;

// The share of `whole` outside `inside` (per axis, so a zero-width extent counts too).
double truncation(const PixelBox& whole, const PixelBox& inside) {
    if (!whole.valid()) return 0.0;
    if (!inside.valid()) return 1.0;
    auto share = [](double lo, double hi, double inLo, double inHi) {
        return hi > lo ? (inHi - inLo) / (hi - lo) : 1.0;
    };
    const double f = share(whole.u0, whole.u1, inside.u0, inside.u1) * share(whole.v0, whole.v1, inside.v0, inside.v1);
    return std::clamp(1.0 - f, 0.0, 1.0);
}

}  // namespace

const MovingObject* findMover(const std::vector<MovingObject>& movers, uint32_t id) {
    auto it =
        std::lower_bound(movers.begin(), movers.end(), id, [](const MovingObject& m, uint32_t v) { return m.id < v; });
    return it != movers.end() && it->id == id ? &*it : nullptr;
}

std::vector<FrameBox> frameBoxes(const SceneModel& city, const CityBoxes& boxes, const BoxCamera& camera,
                                 const std::vector<uint32_t>& ids, const FrameBoxOptions& options) {
    return frameBoxes(city, boxes, {}, camera, ids, options);
}

std::vector<FrameBox> frameBoxes(const SceneModel& city, const CityBoxes& boxes,
                                 const std::vector<MovingObject>& movers, const BoxCamera& camera,
                                 const std::vector<uint32_t>& ids, const FrameBoxOptions& options) {
    const int W = camera.model.width, H = camera.model.height;
    VISTA_CHECK(W > 0 && H > 0 && ids.size() == size_t(W) * size_t(H));
    std::vector<FrameBox> out;
    std::vector<const InstanceBox*> src;
    std::vector<const MovingObject*> moving;
    std::vector<VisibleStats> stats;
    // Isolated: a rig run boxes one camera while the next one casts in the
    // same arena, and a thread waiting here for the boxes' tasks takes none of
    // the caller's other work, so the boxes end when their own work does.
    auto isolated = [&](const auto& body) { inArena(options.threads, [&] { tbb::this_task_arena::isolate(body); }); };
    isolated([&] { stats = visibleStats(ids, W, H); });
    for (const VisibleStats& s : stats) {
        if (s.count < options.minPixels) continue;
        const InstanceBox* ib = boxes.find(s.id);
        const MovingObject* mo = ib ? nullptr : findMover(movers, s.id);
        if (!ib && !mo) continue;
        FrameBox f;
        f.id = s.id;
        f.box = ib ? ib->box : mo->box;
        if (mo) f.semantic = mo->semantic, f.velocity = mo->velocity;
        f.visibleU0 = s.u0, f.visibleV0 = s.v0, f.visibleU1 = s.u1, f.visibleV1 = s.v1;
        f.pixels = s.count;
        out.push_back(f);
        src.push_back(ib);
        moving.push_back(mo);
    }
    const Projector pr(camera);
    // Fisheye masks test pixel rays: the caller's table of this model, else one built here.
    CameraRayTable own;
    const CameraRayTable* rays = options.rays;
    if (camera.model.fisheye() && !out.empty() && !(rays && rays->matches(camera.model))) {
        own = CameraRayTable(camera.model, options.threads);
        rays = &own;
    }
    MaskStamps blank;
    blank.pixels.assign(size_t(W) * size_t(H), 0xFFFFFFFFu);
    if (rays) blank.tiles.assign(size_t(rays->tilesX()) * size_t(rays->tilesY()), 0xFFFFFFFFu);
    tbb::enumerable_thread_specific<MaskStamps> stamps(blank);
    // The instances with the most triangles first, so that the workers end together.
    std::vector<size_t> order(out.size());
    std::vector<size_t> weight(out.size());
    for (size_t i = 0; i < out.size(); ++i) {
        order[i] = i;
        if (const InstanceBox* ib = src[i]) {
            weight[i] = ib->triangleCount;
            for (uint32_t t : ib->trees)
                if (city.instances[t].prototype < city.prototypes.size())
                    weight[i] += city.prototypes[city.instances[t].prototype].indices.size() / 3;
            for (uint32_t t : ib->impostors)
                if (city.impostors[t].prototype < city.prototypes.size())
                    weight[i] += city.prototypes[city.impostors[t].prototype].indices.size() / 3;
        } else if (moving[i]->mesh) {
            weight[i] = moving[i]->mesh->indices.size() / 3;
        }
    }
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return weight[a] > weight[b]; });
    isolated([&] {
        tbb::parallel_for(size_t(0), out.size(), [&](size_t j) {
            const size_t i = order[j];
            FrameBox& f = out[i];
            MaskRaster r(pr, rays, W, H, stamps.local(), uint32_t(i));
            if (pr.m.fisheye() && src[i]) {  // the vertices of every kSeedStride-th triangle first
                uint32_t k = 0;
                forEachTriangle(city, boxes, *src[i],
                                [&](const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
                                    if (k++ % kSeedStride == 0) r.seed(a, b, c);
                                });
            }
            if (src[i]) {
                forEachTriangle(
                    city, boxes, *src[i],
                    [&](const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) { r.triangle(a, b, c); });
            } else if (const Mesh* m = moving[i]->mesh) {
                const glm::dmat4& T = moving[i]->toWorld;
                auto world = [&](uint32_t v) { return glm::dvec3(T * glm::dvec4(glm::dvec3(m->positions[v]), 1.0)); };
                for (size_t t = 0; t + 2 < m->indices.size(); t += 3)
                    r.triangle(world(m->indices[t]), world(m->indices[t + 1]), world(m->indices[t + 2]));
            }
            f.full = clipToImage(r.full, W, H);
            f.truncated = truncation(r.full, f.full);
            f.boxExtent = clipToImage(projectedBox(camera, f.box), W, H);
            f.unoccludedPixels = r.covered;
            f.visibleFraction = r.covered > 0 ? std::min(1.0, double(f.pixels) / double(r.covered)) : 1.0;
        });
    });
    return out;
}

std::vector<FrameBox> frameBoxes(const SceneModel& city, const CityBoxes& boxes, const Camera& camera,
                                 const std::vector<uint32_t>& ids, const FrameBoxOptions& options) {
    return frameBoxes(city, boxes, boxCamera(camera), ids, options);
}

namespace {

double round3(double v) { return std::round(v * 1000.0) / 1000.0; }

nlohmann::json vec3Json(const glm::dvec3& v) { return {round3(v.x), round3(v.y), round3(v.z)}; }

nlohmann::json pixelBoxJson(const PixelBox& b) {
    if (!b.valid()) return nullptr;
    return {round3(b.u0), round3(b.v0), round3(b.u1), round3(b.v1)};
}

double wrapTurn(double a) {  // into [-pi, pi]
    while (a > kPi) a -= kTwoPi;
    while (a < -kPi) a += kTwoPi;
    return a;
}

// KITTI's rotation_y (about the camera's y axis, 0 = length axis along camera x) and alpha.
struct CameraYaw {
    double rotationY, alpha;
};
CameraYaw cameraYaw(const BoxCamera& camera, const OrientedBox& box, const glm::dvec3& location) {
    const glm::dvec3 h = box.lengthAxis();
    const double ry = wrapTurn(std::atan2(-glm::dot(h, camera.axes[2]), glm::dot(h, camera.axes[0])));
    return {ry, wrapTurn(ry - std::atan2(location.x, location.z))};
}

glm::dvec3 bottomCenter(const OrientedBox& b) { return b.center - glm::dvec3(0.0, 0.0, 0.5 * b.size.z); }

}  // namespace

std::string frameBoxesJson(const std::vector<FrameBox>& boxes, const BoxCamera& camera, const glm::dvec3& worldOffset,
                           const std::string& cameraName) {
    const CameraModel& k = camera.model;
    nlohmann::json list = nlohmann::json::array();
    for (const FrameBox& f : boxes) {
        const glm::dvec3 bottom = camera.toCamera(bottomCenter(f.box));
        const CameraYaw cy = cameraYaw(camera, f.box, bottom);
        list.push_back({{"id", f.id},
                        {"kind", instanceKindName(instanceKind(f.id))},
                        {"index", instanceIndex(f.id)},
                        {"visible", {f.visibleU0, f.visibleV0, f.visibleU1, f.visibleV1}},
                        {"pixels", f.pixels},
                        {"full", pixelBoxJson(f.full)},
                        {"box_extent", pixelBoxJson(f.boxExtent)},
                        {"unoccluded_pixels", f.unoccludedPixels},
                        {"visible_fraction", round3(f.visibleFraction)},
                        {"truncated", round3(f.truncated)},
                        {"velocity", vec3Json(f.velocity)},
                        {"box",
                         {{"center", vec3Json(f.box.center - worldOffset)},
                          {"size", vec3Json(f.box.size)},
                          {"yaw", round3(f.box.yaw)}}},
                        {"camera",
                         {{"center", vec3Json(camera.toCamera(f.box.center))},
                          {"bottom_center", vec3Json(bottom)},
                          {"rotation_y", round3(cy.rotationY)},
                          {"alpha", round3(cy.alpha)}}}});
    }
    nlohmann::json doc = {{"format", "vista.boxes"},
                          {"version", 1},
                          {"model", k.fisheye() ? "fisheye" : "pinhole"},
                          {"width", k.width},
                          {"height", k.height},
                          {"fx", k.fx},
                          {"fy", k.fy},
                          {"cx", k.cx},
                          {"cy", k.cy},
                          {"world_offset", {worldOffset.x, worldOffset.y, worldOffset.z}},
                          {"boxes", list}};
    if (k.fisheye()) doc["max_fov_deg"] = k.maxFovDeg;
    else doc["z_near_m"] = camera.zNear;
    if (!cameraName.empty()) doc["camera_name"] = cameraName;
    return doc.dump(1) + "\n";
}

std::string frameBoxesJson(const std::vector<FrameBox>& boxes, const Camera& camera, const glm::dvec3& worldOffset) {
    return frameBoxesJson(boxes, boxCamera(camera), worldOffset);
}

const char* kittiType(InstanceKind k) {
    switch (k) {
        case InstanceKind::Car: return "Car";
        case InstanceKind::Building: return "Building";
        case InstanceKind::Tree: return "Tree";
        case InstanceKind::StreetLight: return "StreetLight";
        case InstanceKind::TrafficLight: return "TrafficLight";
        case InstanceKind::TrafficSign: return "TrafficSign";
        default: return "DontCare";
    }
}

const char* kittiType(const FrameBox& box) {
    if (box.semantic == 255) return kittiType(instanceKind(box.id));
    switch (SemanticClass(box.semantic)) {
        case SemanticClass::Car: return "Car";
        case SemanticClass::Van: return "Van";
        case SemanticClass::Truck: return "Truck";
        case SemanticClass::Bus: return "Bus";
        case SemanticClass::Bicycle: return "Cyclist";
        case SemanticClass::Pedestrian: return "Pedestrian";
        default: return "Misc";
    }
}

std::string kittiLabels(const std::vector<FrameBox>& boxes, const BoxCamera& camera) {
    std::string out;
    char line[512];
    for (const FrameBox& f : boxes) {
        const glm::dvec3 loc = camera.toCamera(bottomCenter(f.box));
        const CameraYaw cy = cameraYaw(camera, f.box, loc);
        const int occluded = f.visibleFraction >= 0.8 ? 0 : f.visibleFraction >= 0.4 ? 1 : 2;
        std::snprintf(line, sizeof line, "%s %.2f %d %.2f %.2f %.2f %.2f %.2f %.2f %.2f %.2f %.2f %.2f %.2f %.2f\n",
                      kittiType(f), f.truncated, occluded, cy.alpha, double(f.visibleU0), double(f.visibleV0),
                      double(f.visibleU1), double(f.visibleV1), f.box.size.z, f.box.size.y, f.box.size.x, loc.x, loc.y,
                      loc.z, cy.rotationY);
        out += line;
    }
    return out;
}

std::string kittiLabels(const std::vector<FrameBox>& boxes, const Camera& camera) {
    return kittiLabels(boxes, boxCamera(camera));
}

std::string kittiCalib(const Camera& camera, const LidarPose& lidar) {
    const PinholeIntrinsics k = pinholeIntrinsics(camera);
    Camera l;
    l.heading = lidar.heading, l.pitch = lidar.pitch, l.roll = lidar.roll;
    const glm::dvec3 camAxes[3] = {camera.right(), -camera.up(), camera.forward()};
    const glm::dvec3 lidarAxes[3] = {l.forward(), -l.right(), l.up()};
    const double P[12] = {k.fx, 0, k.cx, 0, 0, k.fy, k.cy, 0, 0, 0, 1, 0};
    double tr[12];
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) tr[i * 4 + j] = glm::dot(camAxes[i], lidarAxes[j]);
        tr[i * 4 + 3] = glm::dot(camAxes[i], lidar.position - camera.eye);
    }
    const double id3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, id34[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    std::string out;
    auto row = [&](const char* name, const double* v, int n) {
        out += name;
        out += ':';
        char buf[32];
        for (int i = 0; i < n; ++i) {
            std::snprintf(buf, sizeof buf, " %.12e", v[i]);
            out += buf;
        }
        out += '\n';
    };
    for (const char* p : {"P0", "P1", "P2", "P3"}) row(p, P, 12);
    row("R0_rect", id3, 9);
    row("Tr_velo_to_cam", tr, 12);
    row("Tr_imu_to_velo", id34, 12);
    return out;
}

}  // namespace vista
