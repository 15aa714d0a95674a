// Ground-truth labels from rays and the .npy writer (ground_truth.h).
#include "runtime/engine/ground_truth.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include <tbb/parallel_for.h>

#include "citygen/labels.h"
#include "runtime/engine/far_field_stages.h"
#include "runtime/engine/ray_scene.h"

namespace vista {

void LabelImage::resize(int w, int h) {
    width = w;
    height = h;
    const size_t n = size_t(w) * size_t(h);
    ids.assign(n, 0u);
    classes.assign(n, uint8_t(SemanticClass::Sky));
    depth.assign(n, std::numeric_limits<float>::infinity());
}

namespace {

uint8_t classOf(Material m) {
    const SemanticClass c = semanticClass(m);
    return c == SemanticClass::Count ? uint8_t(255) : uint8_t(c);
}

// The label id of triangle `prim`'s first vertex, 0 without labels.
uint32_t triangleId(const SceneMesh& m, uint32_t prim) {
    const size_t k = size_t(prim) * 3;
    if (k >= m.indices.size() || m.ids.size() != m.positions.size()) return 0;
    const uint32_t v = m.indices[k];
    return v < m.ids.size() ? m.ids[v] : 0u;
}

}  // namespace

PixelLabel rayLabel(const SceneModel& city, const RayScene& rays, const RayHit& hit) {
    PixelLabel out;
    const HitSource src = rays.source(hit);
    if (src.mover >= 0 || src.still >= 0) {
        out.id = src.moverId;
        out.cls = src.moverClass;
    } else if (src.mesh >= 0 && size_t(src.mesh) < city.meshes.size()) {
        const SceneMesh& m = city.meshes[size_t(src.mesh)];
        out.cls = classOf(m.material);
        out.id = triangleId(m, hit.primId);
    } else if (src.instance >= 0 && size_t(src.instance) < city.instances.size()) {
        const SceneInstance& in = city.instances[size_t(src.instance)];
        out.id = in.id;
        out.cls = uint8_t(SemanticClass::TreeLeaves);
        if (in.prototype < city.prototypes.size()) {
            const uint32_t part = triangleId(city.prototypes[in.prototype], hit.primId);
            if (part < uint32_t(kMaterialCount) && city.prototypes[in.prototype].ids.size() > 0)
                out.cls = classOf(Material(part));
        }
    } else if (hit.hit) {
        out.cls = 255;
    }
    return out;
}

void castLabels(const SceneModel& city, const RayScene& rays, const Camera& camera, const std::vector<uint32_t>& pixels,
                LabelImage& out, int threads) {
    VISTA_CHECK(out.width == camera.width && out.height == camera.height);
    const size_t n = pixels.size();
    if (n == 0) return;
    const PixelRays gen(camera);
    const glm::dvec3 fwd = camera.forward();
    const glm::vec3 org(camera.eye - rays.frameOrigin());
    const uint32_t W = uint32_t(camera.width);
    constexpr size_t kTask = 2048;
    inArena(threads, [&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kTask), [&](const tbb::blocked_range<size_t>& br) {
            const size_t b = br.begin(), m = br.end() - br.begin();
            std::vector<glm::vec3> orgs(m, org), dirs(m);
            std::vector<double> cosines(m);
            std::vector<RayHit> res(m);
            for (size_t k = 0; k < m; ++k) {
                const uint32_t i = pixels[b + k];
                VISTA_CHECK(i < W * uint32_t(camera.height));
                const glm::dvec3 d = gen.dir(int(i % W), int(i / W));
                dirs[k] = glm::vec3(d);
                cosines[k] = std::max(glm::dot(d, fwd), 1e-6);
            }
            rays.intersectMany(orgs.data(), dirs.data(), int(m), res.data());
            // The rasteriser clips at the near plane: a hit before it is cast again from there.
            for (size_t k = 0; k < m; ++k) {
                const float tnear = float(camera.zNear / cosines[k]);
                if (res[k].hit && res[k].t < tnear) res[k] = rays.intersect(orgs[k], dirs[k], tnear);
            }
            for (size_t k = 0; k < m; ++k) {
                const size_t p = pixels[b + k];
                const RayHit& h = res[k];
                if (!h.hit) {
                    out.ids[p] = 0;
                    out.classes[p] = uint8_t(SemanticClass::Sky);
                    out.depth[p] = std::numeric_limits<float>::infinity();
                    continue;
                }
                const PixelLabel l = rayLabel(city, rays, h);
                out.ids[p] = l.id;
                out.classes[p] = l.cls;
                out.depth[p] = float(double(h.t) * cosines[k]);
            }
        });
    });
}

size_t mergeLabels(const SceneModel& city, const RayScene* rays, const Camera& camera, const RasterLabels& raster,
                   double nearDistance, bool castUncovered, LabelImage& out, int threads) {
    out.resize(camera.width, camera.height);
    const bool limited = nearDistance < 1e299;
    const bool castOthers = rays && (limited || castUncovered);
    const PixelRays gen(camera);
    const glm::dvec3 fwd = camera.forward();
    std::vector<uint32_t> far;
    for (int y = 0; y < camera.height; ++y)
        for (int x = 0; x < camera.width; ++x) {
            const size_t p = size_t(y) * size_t(camera.width) + size_t(x);
            const float z = raster.depth[p];
            bool keep = z > 0.0f;
            if (keep && limited) keep = double(z) / glm::dot(gen.dir(x, y), fwd) <= nearDistance;
            if (keep) {
                out.ids[p] = raster.ids[p];
                out.classes[p] = raster.classes[p];
                out.depth[p] = z;
            } else if (castOthers) {
                far.push_back(uint32_t(p));
            }
        }
    if (!far.empty()) castLabels(city, *rays, camera, far, out, threads);
    return far.size();
}

namespace {

std::string npyHeader(const char* descr, int width, int height) {
    std::string dict = std::string("{'descr': '") + descr + "', 'fortran_order': False, 'shape': (" +
                       std::to_string(height) + ", " + std::to_string(width) + "), }";
    // magic(6) + version(2) + header length(2) + dict + padding + '\n' is a multiple of 64.
    size_t total = 10 + dict.size() + 1;
    dict.append((64 - total % 64) % 64, ' ');
    dict += '\n';
    std::string h("\x93NUMPY\x01\x00", 8);
    const uint16_t len = uint16_t(dict.size());
    h += char(len & 0xFF);
    h += char(len >> 8);
    return h + dict;
}

template <class T>
std::string npy(const char* descr, const T* data, int width, int height) {
    static_assert(sizeof(T) == 4, "4-byte elements");
    std::string s = npyHeader(descr, width, height);
    const size_t n = size_t(width) * size_t(height);
    const size_t at = s.size();
    s.resize(at + n * 4);
    std::memcpy(&s[at], data, n * 4);  // little-endian host (x86-64, AArch64)
    return s;
}

}  // namespace

std::string npyBytes(const float* data, int width, int height) { return npy("<f4", data, width, height); }
std::string npyBytes(const uint32_t* data, int width, int height) { return npy("<u4", data, width, height); }

}  // namespace vista
