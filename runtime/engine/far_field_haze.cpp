// The haze stage (far_field_haze.h) and the haze of covered pixels
// (far_field_stages.h): every pass reads the transmittance from a table over
// the reciprocal eye depth (HazeTableView) and blends in fixed point.
#include "runtime/engine/far_field_haze.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <mutex>
#include <vector>

#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include "foundation/timing.h"
#include "runtime/engine/far_field_stages.h"
#include "runtime/engine/haze_kernels_impl.h"

namespace vista {

const HazeKernels& hazeKernelsBaseline() {
    static constexpr HazeKernels k{hazeWindowKernel, hazeDepthKernel};
    return k;
}

#ifdef VISTA_HAZE_AVX2
const HazeKernels* hazeKernelsAvx2Table();  // haze_kernels_avx2.cpp
const HazeKernels* hazeKernelsAvx2() {
    static const bool has = __builtin_cpu_supports("avx2");
    return has ? hazeKernelsAvx2Table() : nullptr;
}
#else
const HazeKernels* hazeKernelsAvx2() { return nullptr; }
#endif

const HazeKernels& hazeKernels() {
    static const HazeKernels& k = hazeKernelsAvx2() ? *hazeKernelsAvx2() : hazeKernelsBaseline();
    return k;
}

namespace {

HazeParams hazeParams(const FrameEffects& fx) {
    HazeParams h;
    h.beta = float(fx.extinction());
    const glm::u8vec4 c = fx.hazeColor();
    for (int k = 0; k < 3; ++k) h.colour[k] = float(c[k]);
    return h;
}

void recordHaze(double ms, FrameStats& stats) {
    stats.stages.add(Stage::Haze, ms);
    stats.effects.add(EffectId::Haze, ms);
}

}  // namespace

DepthHaze::DepthHaze(const FrameEffects& fx)
    : _on(fx.haze),
      _h(hazeParams(fx)),
      _table(fx.haze ? hazeTable(_h.beta) : HazeTableView{}),
      _kernels(&hazeKernels()) {}

void DepthHaze::operator()(uint32_t* px, const float* depth, size_t n) const {
    if (_on && n > 0) _kernels->depth(px, depth, n, _table, _h);
}

void hazeStage(const FrameEffects& fx, const uint32_t* pixels, size_t n, const float* depth, Image& out,
               FrameStats& stats) {
    if (!fx.haze || n == 0) return;
    Stopwatch sw;
    // Gathered into a block, hazed by the kernel, scattered back.
    const DepthHaze haze(fx);
    PixelWord* px = reinterpret_cast<PixelWord*>(out.rgba.data());
    constexpr size_t kBlock = 256;
    uint32_t block[kBlock];
    for (size_t b = 0; b < n; b += kBlock) {
        const size_t m = std::min(kBlock, n - b);
        for (size_t k = 0; k < m; ++k) block[k] = px[pixels[b + k]];
        haze(block, depth + b, m);
        for (size_t k = 0; k < m; ++k) px[pixels[b + k]] = block[k];
    }
    recordHaze(sw.ms(), stats);
}

void hazeCoveredRows(const HazeKernels& k, PixelWord* px, const float* depth, size_t width, size_t y0, size_t y1,
                     float invA, float b, const HazeTableView& table, const HazeParams& h) {
    // The rows as one span (the kernel leaves uncovered pixels alone).
    const size_t from = y0 * width;
    k.window(px + from, depth + from, (y1 - y0) * width, invA, b, table, h);
}

namespace {

struct TableEntry {
    float beta = 0;
    std::vector<uint16_t> t;
    HazeTableView view;
};

std::unique_ptr<TableEntry> makeTable(float beta) {
    auto e = std::make_unique<TableEntry>();
    e->beta = beta;
    auto bitsOf = [](float u) {
        uint32_t bits;
        std::memcpy(&bits, &u, sizeof bits);
        return int32_t(bits >> HazeTableView::kShift);
    };
    // From beta z = 12 (T = 0) to beta z = 2^-17 (T = 32767): about 20 binades.
    const int32_t base = bitsOf(beta / 12.0f), top = bitsOf(beta * 131072.0f);
    e->t.resize(size_t(top - base) + 2);
    for (int32_t i = 0; i <= top - base; ++i) {
        const uint32_t bits = (uint32_t(base + i) << HazeTableView::kShift) | (1u << (HazeTableView::kShift - 1));
        float u;
        std::memcpy(&u, &bits, sizeof u);
        const double T = std::round(32768.0 * std::exp(-double(beta) / double(u)));
        e->t[size_t(i)] = uint16_t(std::min(T, 32767.0));
    }
    e->t.back() = e->t[e->t.size() - 2];
    e->view = HazeTableView{e->t.data(), base, top - base};
    return e;
}

}  // namespace

HazeTableView hazeTable(float beta) {
    // A run uses one extinction, the viewer's haze slider a few: the last four are kept.
    static std::mutex mutex;
    static std::vector<std::unique_ptr<TableEntry>> tables;
    std::lock_guard<std::mutex> lock(mutex);
    for (const auto& e : tables)
        if (e->beta == beta) return e->view;
    if (tables.size() == 4) tables.erase(tables.begin());
    tables.push_back(makeTable(beta));
    return tables.back()->view;
}

void CoveredHaze::start(const FarFrame& f, const FarFieldOptions& o) {
    if (!o.hazeCovered || !o.effects.haze || !f.depth) return;
    _started = true;
    // Eye depth of window depth d: z = a / (b - d) (eyeDepthOfWindowDepth
    // rearranged; infinite far plane: a = n, b = 1), in float: its relative
    // error (1e-7) is far below an 8-bit step.
    const double zn = f.camera.zNear, zf = o.depthZFar;
    const float a = float(zf > 0 ? zn * zf / (zf - zn) : zn), b = float(zf > 0 ? zf / (zf - zn) : 1.0);
    const HazeParams h = hazeParams(o.effects);
    const float invA = 1.0f / a;
    const HazeTableView table = hazeTable(h.beta);
    const size_t W = size_t(f.width), H = size_t(f.height);
    PixelWord* px = reinterpret_cast<PixelWord*>(f.out.rgba.data());
    const float* depth = f.depth;
    auto body = [this, px, depth, W, H, invA, b, table, h] {
        Stopwatch sw;
        const HazeKernels& kernels = hazeKernels();
        tbb::parallel_for(tbb::blocked_range<size_t>(0, H, 16), [&](const tbb::blocked_range<size_t>& r) {
            hazeCoveredRows(kernels, px, depth, W, r.begin(), r.end(), invA, b, table, h);
        });
        _ms = sw.ms();
    };
    if (o.threads > 0) inArena(o.threads, body);
    else _group.run(body);
}

void CoveredHaze::finish(FrameStats& stats) {
    if (!_started) return;
    _group.wait();
    _started = false;
    recordHaze(_ms, stats);
}

}  // namespace vista
