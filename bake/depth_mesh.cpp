// Textured depth meshes (bake/depth_mesh.h).
#include "bake/depth_mesh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>

#include "foundation/status.h"

namespace vista {

DepthView chooseDepthView(const TriangleSoup& soup, const glm::dvec3& eye, double minStep, int imageSize,
                          int maxEndTriangles) {
    const double kMaxX = std::tan(60.0 * 3.14159265358979323846 / 180.0), kMinY = -1.0, kMaxY = kMaxX;
    double u0 = 1e300, u1 = -1e300, v0 = 1e300, v1 = -1e300;
    for (const glm::vec3& p : soup.positions) {
        const glm::dvec3 r = glm::dvec3(p) - eye;
        if (r.x <= 1.0) continue;
        const double u = -r.y / r.x, v = r.z / r.x;
        u0 = std::min(u0, u);
        u1 = std::max(u1, u);
        v0 = std::min(v0, v);
        v1 = std::max(v1, v);
    }
    if (u0 > u1) u0 = u1 = v0 = v1 = 0;
    u0 = std::clamp(u0, -kMaxX, kMaxX);
    u1 = std::clamp(u1, -kMaxX, kMaxX);
    v0 = std::clamp(v0, kMinY, kMaxY);
    v1 = std::clamp(v1, kMinY, kMaxY);
    DepthView view;
    view.eye = eye;
    const double ext = std::max(u1 - u0, v1 - v0);
    view.step = std::max(minStep, ext / double(std::max(imageSize - 1, 1)));
    auto fit = [&](int block, int& nx, int& ny) {
        nx = std::max(1, int(std::ceil((u1 - u0) / view.step / block))) * block;
        ny = std::max(1, int(std::ceil((v1 - v0) / view.step / block))) * block;
    };
    int nx = 0, ny = 0;
    view.rootBlock = 32;
    fit(view.rootBlock, nx, ny);
    while (view.rootBlock < 4096 &&
           2 * (nx / view.rootBlock) * (ny / view.rootBlock) > std::max(maxEndTriangles / 4, 2)) {
        view.rootBlock *= 2;
        fit(view.rootBlock, nx, ny);
    }
    view.width = nx + 1;
    view.height = ny + 1;
    view.tanX0 = 0.5 * (u0 + u1) - 0.5 * nx * view.step;
    view.tanY0 = 0.5 * (v0 + v1) - 0.5 * ny * view.step;
    return view;
}

FarImage renderFarImage(const RayScene& scene, const DepthView& view) {
    FarImage img;
    img.view = view;
    const size_t n = size_t(view.width) * size_t(view.height);
    img.color.assign(n, glm::u8vec4(0));
    img.depth.assign(n, 0.0f);
    std::vector<glm::vec3> org(size_t(view.width), glm::vec3(view.eye)), dir(size_t(view.width));
    std::vector<float> len(size_t(view.width));
    std::vector<RayHit> hits(size_t(view.width));
    for (int j = 0; j < view.height; ++j) {
        for (int i = 0; i < view.width; ++i) {
            const glm::dvec3 d = view.direction(i, j);
            len[size_t(i)] = float(glm::length(d));
            dir[size_t(i)] = glm::vec3(d / glm::length(d));
        }
        scene.intersectMany(org.data(), dir.data(), view.width, hits.data());
        for (int i = 0; i < view.width; ++i) {
            const RayHit& h = hits[size_t(i)];
            if (!h.hit) continue;
            const size_t k = size_t(j) * size_t(view.width) + size_t(i);
            img.color[k] = glm::u8vec4(h.color.x, h.color.y, h.color.z, 255);
            img.depth[k] = std::max(h.t / len[size_t(i)], 1e-3f);
        }
    }
    return img;
}

namespace {

struct Leaf {
    int x = 0, y = 0, s = 0;
    double err = 0;
};

class Builder {
public:
    Builder(const FarImage& img, double cellRadius) : _img(img), _v(img.view), _W(img.view.width), _H(img.view.height) {
        _w.assign(size_t(_W) * size_t(_H), 0.0);
        _from.assign(_w.size(), -1);
        for (size_t k = 0; k < _w.size(); ++k)
            if (img.depth[k] > 0) {
                _w[k] = 1.0 / double(img.depth[k]);
                _from[k] = int64_t(k);
            }
        fillMisses();
        _scale = cellRadius / _v.step;
        markDiscontinuities();
        // Prefix counts of hit samples: empty leaves in O(1).
        _hits.assign(size_t(_W + 1) * size_t(_H + 1), 0);
        for (int j = 0; j < _H; ++j)
            for (int i = 0; i < _W; ++i)
                _hits[size_t(j + 1) * size_t(_W + 1) + size_t(i + 1)] =
                    _hits[size_t(j) * size_t(_W + 1) + size_t(i + 1)] +
                    _hits[size_t(j + 1) * size_t(_W + 1) + size_t(i)] - _hits[size_t(j) * size_t(_W + 1) + size_t(i)] +
                    (valid(i, j) ? 1 : 0);
    }

    bool valid(int i, int j) const { return _img.depth[idx(i, j)] > 0; }
    size_t idx(int i, int j) const { return size_t(j) * size_t(_W) + size_t(i); }
    // Hit samples in the closed leaf.
    uint32_t hits(int x, int y, int s) const {
        auto at = [&](int i, int j) { return _hits[size_t(j) * size_t(_W + 1) + size_t(i)]; };
        return at(x + s + 1, y + s + 1) - at(x, y + s + 1) - at(x + s + 1, y) + at(x, y);
    }

    // Parallax error of a leaf in pixels over its hit samples (misses are
    // transparent in the texture: their depth only carries the alpha edge);
    // -1 for a leaf of one interval or without a hit.
    double error(int x, int y, int s) const {
        if (s <= 1 || hits(x, y, s) == 0) return -1;
        const double w00 = _w[idx(x, y)], w10 = _w[idx(x + s, y)], w01 = _w[idx(x, y + s)], w11 = _w[idx(x + s, y + s)];
        double e = 0;
        for (int j = y; j <= y + s; ++j)
            for (int i = x; i <= x + s; ++i) {
                if (!valid(i, j)) continue;
                const double a = double(i - x) / s, b = double(j - y) / s;
                const double approx =
                    a >= b ? w00 + a * (w10 - w00) + b * (w11 - w10) : w00 + b * (w01 - w00) + a * (w11 - w01);
                e = std::max(e, std::abs(_w[idx(i, j)] - approx));
            }
        return e * _scale;
    }

    // A discontinuity between two hit samples inside the leaf.
    bool broken(int x, int y, int s) const {
        for (int j = y; j <= y + s; ++j)
            for (int i = x; i <= x + s; ++i) {
                if (i < x + s && _dh[idx(i, j)]) return true;
                if (j < y + s && _dv[idx(i, j)]) return true;
            }
        return false;
    }
    bool discH(int i, int j) const { return _dh[idx(i, j)] != 0; }  // edge (i, j) - (i + 1, j)
    bool discV(int i, int j) const { return _dv[idx(i, j)] != 0; }  // edge (i, j) - (i, j + 1)
    const std::vector<double>& invDepth() const { return _w; }
    // The hit sample whose depth and colour a sample carries (itself if a hit).
    int64_t source(size_t k) const { return _from[k]; }

private:
    // Misses take the inverse depth of the nearest hit in their column (ties:
    // below), columns without a hit that of the nearest column with one.
    void fillMisses() {
        std::vector<uint8_t> colHas(size_t(_W), 0);
        for (int i = 0; i < _W; ++i) {
            int last = -1;
            std::vector<int> below(size_t(_H), -1), above(size_t(_H), -1);
            for (int j = 0; j < _H; ++j) {
                if (valid(i, j)) last = j;
                below[size_t(j)] = last;
            }
            last = -1;
            for (int j = _H - 1; j >= 0; --j) {
                if (valid(i, j)) last = j;
                above[size_t(j)] = last;
            }
            for (int j = 0; j < _H; ++j) {
                if (valid(i, j)) continue;
                const int b = below[size_t(j)], a = above[size_t(j)];
                const int src = b < 0 ? a : a < 0 ? b : (j - b <= a - j ? b : a);
                if (src < 0) continue;
                _w[idx(i, j)] = _w[idx(i, src)];
                _from[idx(i, j)] = int64_t(idx(i, src));
            }
            colHas[size_t(i)] = below[size_t(_H - 1)] >= 0 ? 1 : 0;
        }
        for (int i = 0; i < _W; ++i) {
            if (colHas[size_t(i)]) continue;
            int src = -1;
            for (int d = 1; d < _W && src < 0; ++d) {
                if (i - d >= 0 && colHas[size_t(i - d)]) src = i - d;
                else if (i + d < _W && colHas[size_t(i + d)]) src = i + d;
            }
            if (src < 0) continue;
            for (int j = 0; j < _H; ++j) {
                _w[idx(i, j)] = _w[idx(src, j)];
                _from[idx(i, j)] = _from[idx(src, j)];
            }
        }
    }

    void markDiscontinuities() {
        _dh.assign(_w.size(), 0);
        _dv.assign(_w.size(), 0);
        auto jump = [&](int ai, int aj, int bi, int bj, int di, int dj) -> bool {
            if (!valid(ai, aj) || !valid(bi, bj)) return false;  // misses are transparent
            const double wa = _w[idx(ai, aj)], wb = _w[idx(bi, bj)], d = std::abs(wb - wa);
            if (d <= 0.05 * std::max(wa, wb)) return false;
            double side = 0;
            const int pi = ai - di, pj = aj - dj, ni = bi + di, nj = bj + dj;
            if (pi >= 0 && pj >= 0 && valid(pi, pj)) side = std::max(side, std::abs(wa - _w[idx(pi, pj)]));
            if (ni < _W && nj < _H && valid(ni, nj)) side = std::max(side, std::abs(_w[idx(ni, nj)] - wb));
            return d > 3.0 * side;
        };
        for (int j = 0; j < _H; ++j)
            for (int i = 0; i < _W; ++i) {
                if (i + 1 < _W) _dh[idx(i, j)] = jump(i, j, i + 1, j, 1, 0) ? 1 : 0;
                if (j + 1 < _H) _dv[idx(i, j)] = jump(i, j, i, j + 1, 0, 1) ? 1 : 0;
            }
    }

    const FarImage& _img;
    const DepthView& _v;
    int _W, _H;
    std::vector<double> _w;
    std::vector<int64_t> _from;
    std::vector<uint8_t> _dh, _dv;
    std::vector<uint32_t> _hits;
    double _scale = 1;
};

}  // namespace

TexturedDepthMeshData buildDepthMesh(const FarImage& img, double cellRadius, int maxTriangles, double errorPx,
                                     DepthMeshStats& stats) {
    const DepthView& v = img.view;
    VISTA_CHECK(v.width >= 2 && v.height >= 2 && v.rootBlock >= 1 && (v.width - 1) % v.rootBlock == 0 &&
                (v.height - 1) % v.rootBlock == 0);
    VISTA_CHECK(img.depth.size() == size_t(v.width) * size_t(v.height) && img.color.size() == img.depth.size());
    const int W = v.width, H = v.height, B = v.rootBlock;
    Builder b(img, cellRadius);
    stats = DepthMeshStats{};
    stats.samples = img.depth.size();
    stats.hits = uint64_t(std::count_if(img.depth.begin(), img.depth.end(), [](float z) { return z > 0; }));

    // Greedy refinement: split the worst leaf while the budget allows.
    std::vector<Leaf> leaves;
    for (int y = 0; y + 1 < H; y += B)
        for (int x = 0; x + 1 < W; x += B) leaves.push_back({x, y, B, b.error(x, y, B)});
    std::priority_queue<std::pair<double, uint32_t>> queue;
    for (uint32_t k = 0; k < leaves.size(); ++k)
        if (leaves[k].err > errorPx) queue.push({leaves[k].err, k});
    // Budget: leaves with a hit (the others draw nothing).
    size_t live = 0;
    for (const Leaf& l : leaves) live += b.hits(l.x, l.y, l.s) > 0 ? 1 : 0;
    while (!queue.empty() && 2 * (live + 3) <= size_t(std::max(maxTriangles, 0))) {
        const uint32_t k = queue.top().second;
        queue.pop();
        const Leaf l = leaves[k];
        const int h = l.s / 2;
        --live;
        const Leaf kids[4] = {{l.x, l.y, h, 0}, {l.x + h, l.y, h, 0}, {l.x, l.y + h, h, 0}, {l.x + h, l.y + h, h, 0}};
        for (int c = 0; c < 4; ++c) {
            const uint32_t at = c == 0 ? k : uint32_t(leaves.size());
            if (c == 0) leaves[k] = kids[0];
            else leaves.push_back(kids[c]);
            leaves[at].err = b.error(leaves[at].x, leaves[at].y, leaves[at].s);
            live += b.hits(leaves[at].x, leaves[at].y, leaves[at].s) > 0 ? 1 : 0;
            if (leaves[at].err > errorPx) queue.push({leaves[at].err, at});
        }
    }
    stats.leaves = leaves.size();

    // Per-sample inverse depth of the mesh vertices; T-junction vertices are
    // moved onto the coarser leaf's edge (coarsest leaves first).
    std::vector<double> w = b.invDepth();
    std::vector<uint8_t> corner(w.size(), 0);
    for (const Leaf& l : leaves)
        for (int c = 0; c < 4; ++c) corner[b.idx(l.x + (c & 1) * l.s, l.y + (c >> 1) * l.s)] = 1;
    std::vector<uint32_t> order(leaves.size());
    for (uint32_t k = 0; k < order.size(); ++k) order[k] = k;
    std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t c) { return leaves[a].s > leaves[c].s; });
    for (uint32_t k : order) {
        const Leaf& l = leaves[k];
        if (l.s <= 1 || b.hits(l.x, l.y, l.s) == 0) continue;
        const int ex[4][4] = {{l.x, l.y, 1, 0}, {l.x, l.y + l.s, 1, 0}, {l.x, l.y, 0, 1}, {l.x + l.s, l.y, 0, 1}};
        for (const auto& e : ex) {
            const size_t a = b.idx(e[0], e[1]), z = b.idx(e[0] + e[2] * l.s, e[1] + e[3] * l.s);
            for (int t = 1; t < l.s; ++t) {
                const size_t c = b.idx(e[0] + e[2] * t, e[1] + e[3] * t);
                if (!corner[c]) continue;
                w[c] = w[a] + (w[z] - w[a]) * double(t) / l.s;
                ++stats.snapped;
            }
        }
    }

    // Triangles, vertices in first-use order.
    TexturedDepthMeshData out;
    out.eye = glm::vec3(v.eye);
    out.width = W;
    out.height = H;
    out.image.resize(img.color.size());
    for (size_t k = 0; k < out.image.size(); ++k) {
        const int64_t src = b.source(k);
        out.image[k] = src >= 0 ? img.color[size_t(src)] : glm::u8vec4(0);
        out.image[k].w = img.depth[k] > 0 ? 255 : 0;
    }
    std::vector<int64_t> vertexOf(w.size(), -1);
    auto vertex = [&](int i, int j) -> uint32_t {
        const size_t k = b.idx(i, j);
        if (vertexOf[k] < 0) {
            vertexOf[k] = int64_t(out.positions.size());
            const double z = 1.0 / w[k];
            out.positions.push_back(glm::vec3(v.eye + z * v.direction(i, j)));
            const double s = (i + 0.5) / W, t = (j + 0.5) / H;
            out.texcoords.push_back(glm::vec4(float(s * z), float(t * z), 0.0f, float(z)));
        }
        return uint32_t(vertexOf[k]);
    };
    for (const Leaf& l : leaves) {
        const int x0 = l.x, y0 = l.y, x1 = l.x + l.s, y1 = l.y + l.s;
        if (b.hits(x0, y0, l.s) == 0) continue;  // all sky: nothing to draw
        bool drop1 = false, drop2 = false;
        if (l.s == 1) {
            // All corners missed (transparent), or a skin across a discontinuity.
            drop1 = (!b.valid(x0, y0) && !b.valid(x1, y0) && !b.valid(x1, y1)) || b.discH(x0, y0) || b.discV(x1, y0);
            drop2 = (!b.valid(x0, y0) && !b.valid(x1, y1) && !b.valid(x0, y1)) || b.discV(x0, y0) || b.discH(x0, y1);
        } else if (l.err > errorPx && b.broken(x0, y0, l.s)) {
            drop1 = drop2 = true;
        }
        if (l.err > stats.maxLeafErrorPx && !(drop1 && drop2)) stats.maxLeafErrorPx = l.err;
        stats.droppedTriangles += uint64_t(drop1) + uint64_t(drop2);
        // Counter-clockwise in the image (x right, y up) = front-facing from the eye.
        if (!drop1)
            for (uint32_t q : {vertex(x0, y0), vertex(x1, y0), vertex(x1, y1)}) out.indices.push_back(q);
        if (!drop2)
            for (uint32_t q : {vertex(x0, y0), vertex(x1, y1), vertex(x0, y1)}) out.indices.push_back(q);
    }
    stats.triangles = out.triangleCount();
    return out;
}

}  // namespace vista
