// Tree impostors: cross-billboard quads and their baked atlas (tree_impostor.h).
#include "citygen/tree_impostor.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/parallel_for.h>

#include "foundation/status.h"

namespace vista {
namespace {

// Horizontal axes of the vertical quads at yaw 0, 60 and 120 degrees, as
// exact constants (not std::cos/sin: the atlas must not depend on libm).
constexpr double kSqrt3Half = 0.86602540378443864676;
constexpr double kQuadCos[kImpostorVerticalQuads] = {1.0, 0.5, -0.5};
constexpr double kQuadSin[kImpostorVerticalQuads] = {0.0, kSqrt3Half, kSqrt3Half};

constexpr int64_t kSubpixel = 256;  // fixed point: 1/256 texel

struct Sample {
    double depth = -std::numeric_limits<double>::infinity();
    float r = 0, g = 0, b = 0;
    bool covered = false;
};

int64_t edge(int64_t ax, int64_t ay, int64_t bx, int64_t by, int64_t px, int64_t py) {
    return (bx - ax) * (py - ay) - (by - ay) * (px - ax);
}

// Bakes one cell into `atlas` (its own texels only).
void bakeCell(int cell, const TreeImpostor& imp, const std::vector<glm::vec3>& positions,
              const std::vector<glm::u8vec4>& colors, const std::vector<uint32_t>& indices,
              std::vector<uint8_t>& atlas) {
    const int px = imp.cellPixels, ss = kImpostorSupersample, n = px * ss;
    const int inner = px - 2 * kImpostorPadPixels;
    const ImpostorView view = impostorView(cell, imp.radius, imp.zMin, imp.zMax);
    const int64_t step = kSubpixel / ss, offset = step / 2;  // sample sx at sx * step + offset
    std::vector<Sample> samples(size_t(n) * size_t(n));
    // Vertices in fixed-point texel coordinates of the cell.
    std::vector<int64_t> fx(positions.size()), fy(positions.size());
    std::vector<double> depth(positions.size());
    for (size_t i = 0; i < positions.size(); ++i) {
        const glm::dvec3 q = view.project(positions[i]);
        fx[i] = std::llround((kImpostorPadPixels + q.x * inner) * double(kSubpixel));
        fy[i] = std::llround((kImpostorPadPixels + q.y * inner) * double(kSubpixel));
        depth[i] = q.z;
    }
    auto sampleLo = [&](int64_t v) { return int(std::clamp<int64_t>((v - offset + step - 1) / step - 1, 0, n - 1)); };
    auto sampleHi = [&](int64_t v) { return int(std::clamp<int64_t>((v - offset) / step + 1, 0, n - 1)); };
    for (size_t t = 0; t + 2 < indices.size(); t += 3) {
        const uint32_t a = indices[t], b = indices[t + 1], c = indices[t + 2];
        const int64_t area = edge(fx[a], fy[a], fx[b], fy[b], fx[c], fy[c]);
        if (area == 0) continue;
        const int x0 = sampleLo(std::min({fx[a], fx[b], fx[c]})), x1 = sampleHi(std::max({fx[a], fx[b], fx[c]}));
        const int y0 = sampleLo(std::min({fy[a], fy[b], fy[c]})), y1 = sampleHi(std::max({fy[a], fy[b], fy[c]}));
        const double inv = 1.0 / double(area);
        for (int sy = y0; sy <= y1; ++sy) {
            const int64_t py = sy * step + offset;
            for (int sx = x0; sx <= x1; ++sx) {
                const int64_t pxf = sx * step + offset;
                int64_t w0 = edge(fx[b], fy[b], fx[c], fy[c], pxf, py);
                int64_t w1 = edge(fx[c], fy[c], fx[a], fy[a], pxf, py);
                int64_t w2 = edge(fx[a], fy[a], fx[b], fy[b], pxf, py);
                if (area < 0) w0 = -w0, w1 = -w1, w2 = -w2;
                if (w0 < 0 || w1 < 0 || w2 < 0) continue;
                const double l0 = double(area < 0 ? -w0 : w0) * inv, l1 = double(area < 0 ? -w1 : w1) * inv,
                             l2 = double(area < 0 ? -w2 : w2) * inv;
                const double d = l0 * depth[a] + l1 * depth[b] + l2 * depth[c];
                Sample& s = samples[size_t(sy) * size_t(n) + size_t(sx)];
                if (s.covered && !(d > s.depth)) continue;
                s.covered = true;
                s.depth = d;
                s.r = float(l0 * colors[a].x + l1 * colors[b].x + l2 * colors[c].x);
                s.g = float(l0 * colors[a].y + l1 * colors[b].y + l2 * colors[c].y);
                s.b = float(l0 * colors[a].z + l1 * colors[b].z + l2 * colors[c].z);
            }
        }
    }
    // Resolve: coverage -> alpha, mean colour of the covered samples.
    const int cx = (cell % 2) * px, cy = (cell / 2) * px;
    std::vector<glm::vec3> rgb(size_t(px) * size_t(px), glm::vec3(0.0f));
    std::vector<uint8_t> alpha(size_t(px) * size_t(px), 0), filled(size_t(px) * size_t(px), 0);
    for (int ty = 0; ty < px; ++ty)
        for (int tx = 0; tx < px; ++tx) {
            int count = 0;
            double r = 0, g = 0, b = 0;
            for (int j = 0; j < ss; ++j)
                for (int i = 0; i < ss; ++i) {
                    const Sample& s = samples[size_t(ty * ss + j) * size_t(n) + size_t(tx * ss + i)];
                    if (!s.covered) continue;
                    ++count;
                    r += s.r, g += s.g, b += s.b;
                }
            const size_t k = size_t(ty) * size_t(px) + size_t(tx);
            if (count == 0) continue;
            alpha[k] = uint8_t((255 * count + ss * ss / 2) / (ss * ss));
            rgb[k] = glm::vec3(float(r / count), float(g / count), float(b / count));
            filled[k] = 1;
        }
    // Dilation: transparent texels take their covered neighbours' mean colour.
    for (int pass = 0; pass < kImpostorPadPixels + 2; ++pass) {
        std::vector<uint8_t> next = filled;
        std::vector<glm::vec3> nextRgb = rgb;
        for (int ty = 0; ty < px; ++ty)
            for (int tx = 0; tx < px; ++tx) {
                const size_t k = size_t(ty) * size_t(px) + size_t(tx);
                if (filled[k]) continue;
                glm::vec3 sum(0.0f);
                int count = 0;
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        const int x = tx + dx, y = ty + dy;
                        if (x < 0 || y < 0 || x >= px || y >= px) continue;
                        const size_t q = size_t(y) * size_t(px) + size_t(x);
                        if (filled[q]) sum += rgb[q], ++count;
                    }
                if (count == 0) continue;
                nextRgb[k] = sum / float(count);
                next[k] = 1;
            }
        filled.swap(next);
        rgb.swap(nextRgb);
    }
    auto to8 = [](float v) { return uint8_t(std::clamp(std::lround(v), 0L, 255L)); };
    for (int ty = 0; ty < px; ++ty)
        for (int tx = 0; tx < px; ++tx) {
            const size_t k = size_t(ty) * size_t(px) + size_t(tx);
            uint8_t* o = &atlas[(size_t(cy + ty) * size_t(imp.atlasWidth) + size_t(cx + tx)) * 4];
            o[0] = to8(rgb[k].x);
            o[1] = to8(rgb[k].y);
            o[2] = to8(rgb[k].z);
            o[3] = alpha[k];
        }
}

}  // namespace

ImpostorView impostorView(int cell, double radius, double zMin, double zMax) {
    VISTA_CHECK(cell >= 0 && cell < kImpostorCells);
    ImpostorView v;
    if (cell < kImpostorVerticalQuads) {
        const double c = kQuadCos[cell], s = kQuadSin[cell];
        v.uAxis = glm::dvec3(c, s, 0.0);
        v.vAxis = glm::dvec3(0.0, 0.0, 1.0);
        v.depthAxis = glm::dvec3(-s, c, 0.0);
        v.vMin = zMin;
        v.vSpan = zMax - zMin;
    } else {
        v.uAxis = glm::dvec3(1.0, 0.0, 0.0);
        v.vAxis = glm::dvec3(0.0, 1.0, 0.0);
        v.depthAxis = glm::dvec3(0.0, 0.0, 1.0);
        v.vMin = -radius;
        v.vSpan = 2.0 * radius;
    }
    v.uMin = -radius;
    v.uSpan = 2.0 * radius;
    return v;
}

TreeImpostor makeTreeImpostor(const std::vector<glm::vec3>& positions, const std::vector<glm::u8vec4>& colors,
                              const std::vector<uint32_t>& indices, int cellPixels) {
    VISTA_CHECK(colors.size() == positions.size());
    VISTA_CHECK(indices.size() % 3 == 0);
    for (uint32_t i : indices) VISTA_CHECK(i < positions.size());
    VISTA_CHECK(cellPixels >= kMinImpostorCellPixels && cellPixels <= kMaxImpostorCellPixels);
    TreeImpostor imp;
    imp.cellPixels = cellPixels;
    imp.atlasWidth = imp.atlasHeight = 2 * cellPixels;
    imp.atlas.assign(size_t(imp.atlasWidth) * size_t(imp.atlasHeight) * 4, 0);
    double r2 = 0, zMin = std::numeric_limits<double>::infinity(), zMax = -zMin;
    for (const glm::vec3& p : positions) {
        r2 = std::max(r2, double(p.x) * p.x + double(p.y) * p.y);
        zMin = std::min(zMin, double(p.z));
        zMax = std::max(zMax, double(p.z));
    }
    if (indices.empty() || !(r2 > 0) || !(zMax > zMin)) return imp;
    imp.radius = float(std::sqrt(r2));
    imp.zMin = float(zMin);
    imp.zMax = float(zMax);

    // Quads: corners (u, v) = (0,0), (1,0), (1,1), (0,1) of each cell's view.
    const int inner = cellPixels - 2 * kImpostorPadPixels;
    for (int cell = 0; cell < kImpostorCells; ++cell) {
        const ImpostorView v = impostorView(cell, imp.radius, imp.zMin, imp.zMax);
        const double plane =
            cell < kImpostorVerticalQuads ? 0.0 : imp.zMin + kImpostorTopQuadHeight * (imp.zMax - imp.zMin);
        const uint32_t base = uint32_t(imp.positions.size());
        for (auto [u, w] : {std::pair{0, 0}, {1, 0}, {1, 1}, {0, 1}}) {
            const glm::dvec3 p =
                v.uAxis * (v.uMin + u * v.uSpan) + v.vAxis * (v.vMin + w * v.vSpan) + v.depthAxis * plane;
            imp.positions.push_back(glm::vec3(p));
            imp.normals.push_back(glm::vec3(v.depthAxis));
            const double s = (cell % 2) * cellPixels + kImpostorPadPixels + u * inner;
            const double t = (cell / 2) * cellPixels + kImpostorPadPixels + w * inner;
            imp.texcoords.push_back(glm::vec2(float(s / imp.atlasWidth), float(t / imp.atlasHeight)));
        }
        for (uint32_t k : {0u, 1u, 2u, 0u, 2u, 3u}) imp.indices.push_back(base + k);
    }
    tbb::parallel_for(0, kImpostorCells, [&](int cell) { bakeCell(cell, imp, positions, colors, indices, imp.atlas); });
    return imp;
}

}  // namespace vista
