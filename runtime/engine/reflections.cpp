// Reflection stage (reflections.h).
#include "runtime/engine/reflections.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <vector>

#include <tbb/parallel_for.h>

#include "citygen/lighting.h"
#include "foundation/timing.h"
#include "runtime/engine/far_field_rays.h"
#include "runtime/engine/ray_scene.h"

namespace vista {

namespace {

// Alpha kGlassAlpha - 1 .. 254, as one unsigned compare: the loops over a frame's pixels vectorise.
bool marked(uint32_t a) { return a - uint32_t(kGlassAlpha - 1) < uint32_t(255 - (kGlassAlpha - 1)); }
float coverage(uint8_t a) { return std::min(1.0f, float(255 - a) / float(255 - kGlassAlpha)); }

// Over the pixels as 32-bit words (alpha in the top byte): a third faster than over the alpha bytes.
size_t countMarks(const Image& img) {
    size_t n = 0;
    for (size_t i = 0, N = img.rgba.size() / 4; i < N; ++i) {
        uint32_t w;
        std::memcpy(&w, &img.rgba[i * 4], 4);
        n += marked(w >> 24) ? 1 : 0;
    }
    return n;
}

void clearMarks(Image& img) {
    for (size_t i = 3; i < img.rgba.size(); i += 4) img.rgba[i] = 255;
}

// Number of s x s blocks holding a marked pixel.
size_t blocksAt(const std::vector<uint32_t>& glass, int W, int s) {
    const int bw = (W + s - 1) / s;
    std::vector<uint32_t> keys;
    keys.reserve(glass.size());
    for (uint32_t i : glass)
        keys.push_back(uint32_t((i / uint32_t(W)) / uint32_t(s)) * uint32_t(bw) + (i % uint32_t(W)) / uint32_t(s));
    std::sort(keys.begin(), keys.end());
    return size_t(std::unique(keys.begin(), keys.end()) - keys.begin());
}

}  // namespace

bool hasGlassPixels(const Image& img) {
    for (size_t i = 3; i < img.rgba.size(); i += 4)
        if (marked(img.rgba[i])) return true;
    return false;
}

void reflectionStage(const RayScene* rays, const Camera& camera, const FrameEffects& fx, Image& img,
                     FrameStats& stats) {
    const int W = img.width, H = img.height;
    // One vectorised count first: most frames of a run without reflections only clear the marks.
    const size_t marks = countMarks(img);
    if (marks == 0) return;  // nothing of it on screen: costs nothing more
    stats.glassPixels += marks;
    if (!fx.glass || fx.rayBudget <= 0 || !rays || camera.width != W || camera.height != H) {
        clearMarks(img);
        if (fx.glass) stats.notes.push_back("reflections off: ray budget 0 or no ray scene");
        return;
    }
    std::vector<uint32_t> glass;
    glass.reserve(marks);
    for (size_t i = 0, n = size_t(W) * size_t(H); i < n; ++i)
        if (marked(img.rgba[i * 4 + 3])) glass.push_back(uint32_t(i));
    Stopwatch sw;
    // Every stride below sqrt(glass / budget) has more blocks than the budget
    // (a block holds at most s^2 pixels): start there, then step up.
    int s = std::clamp(int(std::sqrt(double(glass.size()) / double(fx.rayBudget))), 1, 64);
    while (s < 64 && blocksAt(glass, W, s) > size_t(fx.rayBudget)) ++s;
    // Blocks: marked pixels grouped by block, in pixel order.
    const int bw = (W + s - 1) / s;
    std::vector<std::pair<uint32_t, uint32_t>> byBlock;  // (block, pixel)
    byBlock.reserve(glass.size());
    for (uint32_t i : glass)
        byBlock.emplace_back(uint32_t((i / uint32_t(W)) / uint32_t(s)) * uint32_t(bw) + (i % uint32_t(W)) / uint32_t(s),
                             i);
    std::stable_sort(byBlock.begin(), byBlock.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<size_t> starts;
    for (size_t k = 0; k < byBlock.size(); ++k)
        if (k == 0 || byBlock[k].first != byBlock[k - 1].first) starts.push_back(k);
    starts.push_back(byBlock.size());

    const PixelRays gen(camera);
    const glm::dvec3 fwd = camera.forward();
    const glm::vec3 eye(camera.eye - rays->frameOrigin());
    const float zLimit = fx.haze ? float(fx.hazeFar() / minForwardCosine(camera)) : 1e30f;
    std::atomic<uint64_t> cast{0};
    tbb::parallel_for(size_t(0), starts.size() - 1, [&](size_t b) {
        const size_t k0 = starts[b], k1 = starts[b + 1];
        const uint32_t block = byBlock[k0].first;
        const double cx = (double(block % uint32_t(bw)) + 0.5) * s, cy = (double(block / uint32_t(bw)) + 0.5) * s;
        uint32_t sample = byBlock[k0].second;
        double best = 1e300;
        for (size_t k = k0; k < k1; ++k) {
            const uint32_t i = byBlock[k].second;
            const double dx = double(i % uint32_t(W)) + 0.5 - cx, dy = double(i / uint32_t(W)) + 0.5 - cy,
                         d2 = dx * dx + dy * dy;
            if (d2 < best) best = d2, sample = i;
        }
        const glm::dvec3 d = gen.dir(int(sample % uint32_t(W)), int(sample / uint32_t(W)));
        const RayHit h = rays->intersect(eye, glm::vec3(d), 0.0f, zLimit);
        uint64_t n = 1;
        if (!h.hit || h.color.w == 255) {  // not glass after all (an edge): base colour stays
            cast += n;
            return;
        }
        glm::dvec3 N = glm::normalize(glm::dvec3(h.normal));
        if (!std::isfinite(N.x) || glm::length(N) < 0.5) N = -d;
        if (glm::dot(N, d) > 0) N = -N;
        const double cosI = std::min(1.0, std::abs(glm::dot(N, d)));
        glm::dvec3 r = d - 2.0 * glm::dot(d, N) * N;
        const double rl = glm::length(r);
        r = rl > 0 ? r / rl : d;
        const glm::dvec3 p = glm::dvec3(eye) + d * double(h.t);
        const double eps = 1e-3 * (1.0 + double(h.t));
        const glm::vec3 org(p + N * eps);
        const RayHit rh = rays->intersect(org, glm::vec3(r), 0.0f, fx.haze ? float(fx.hazeFar()) : 1e30f);
        ++n;
        glm::u8vec4 refl = rh.hit ? fx.applyHaze(rh.color, double(rh.t)) : fx.sky(r);
        const double zPrimary = double(h.t) * glm::dot(d, fwd);
        refl = fx.applyHaze(refl, zPrimary);
        const double F = fx.reflectance + (1.0 - fx.reflectance) * std::pow(1.0 - cosI, 5.0);
        for (size_t k = k0; k < k1; ++k) {
            uint8_t* px = &img.rgba[size_t(byBlock[k].second) * 4];
            const double w = F * coverage(px[3]);
            for (int c = 0; c < 3; ++c)
                px[c] = uint8_t(std::lround(std::clamp(px[c] * (1.0 - w) + refl[c] * w, 0.0, 255.0)));
        }
        cast += n;
    });
    clearMarks(img);
    const double ms = sw.ms();
    stats.stages.add(Stage::Reflect, ms);
    stats.effects.add(EffectId::Glass, ms);
    stats.reflectionRays += cast.load();
    stats.raysCast += cast.load();
}

}  // namespace vista
