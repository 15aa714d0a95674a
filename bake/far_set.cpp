#include "bake/far_set.h"

#include <algorithm>
#include <cmath>

namespace vista {

std::vector<SceneTile> bakeTiles(const SceneModel& city) {
    if (!city.tiles.empty()) return city.tiles;
    std::vector<SceneTile> tiles;
    for (uint32_t i = 0; i < city.meshes.size(); ++i) {
        SceneTile t;
        t.child = i;
        t.origin = city.meshes[i].origin;
        t.meshes.push_back(i);
        t.triangles = city.meshes[i].indices.size() / 3;
        expandBounds(city.meshes[i], t.lo, t.hi);
        tiles.push_back(t);
    }
    for (uint32_t i = 0; i < city.instances.size(); ++i) {
        const SceneInstance& in = city.instances[i];
        SceneTile t;
        t.child = uint32_t(city.meshes.size()) + i;
        t.origin = glm::dvec3(in.transform[3]);
        t.instances.push_back(i);
        if (in.prototype < city.prototypes.size()) t.triangles = city.prototypes[in.prototype].indices.size() / 3;
        expandBounds(city, in, t.lo, t.hi);
        tiles.push_back(t);
    }
    return tiles;
}

namespace {

// Appends a mesh (world = xf * position, or origin + position) in the frame.
void appendMesh(TriangleSoup& soup, const ImpostorFrame& f, const SceneMesh& m, const glm::dmat4* xf) {
    const uint32_t base = uint32_t(soup.positions.size());
    for (size_t i = 0; i < m.positions.size(); ++i) {
        const glm::dvec3 w =
            xf ? glm::dvec3(*xf * glm::dvec4(glm::dvec3(m.positions[i]), 1.0)) : m.origin + glm::dvec3(m.positions[i]);
        soup.positions.push_back(glm::vec3(f.toLocal(w)));
        soup.colors.push_back(i < m.colors.size() ? m.colors[i] : glm::u8vec4(255));
    }
    for (uint32_t idx : m.indices) soup.indices.push_back(base + idx);
}

}  // namespace

FarSet selectFarSet(const SceneModel& city, const std::vector<SceneTile>& tiles, const ViewCell& cell, int end,
                    const FarSetParams& p) {
    FarSet out;
    out.frame = impostorFrame(cell, end);
    const double hw0 = cell.box.halfWidth + p.openingExtra;
    const double slope = hw0 / (cell.box.halfLength + p.margin);
    // Haze: nothing beyond the visibility is drawn, so the far field ends there too.
    double farDepth = p.farDepth;
    if (city.params.effects.haze)
        farDepth = std::min(farDepth, std::max(0.0, city.params.effects.haze->visibility_m - p.margin));
    for (const SceneTile& t : tiles) {
        if (t.triangles == 0 || t.lo.x > t.hi.x) continue;
        double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
        bool inWedge = false;
        for (int c = 0; c < 4; ++c) {
            const glm::dvec3 l = out.frame.toLocal({(c & 1) ? t.hi.x : t.lo.x, (c & 2) ? t.hi.y : t.lo.y, 0.0});
            x0 = std::min(x0, l.x);
            x1 = std::max(x1, l.x);
            y0 = std::min(y0, l.y);
            y1 = std::max(y1, l.y);
            if (std::abs(l.y) <= hw0 + slope * (l.x - p.margin)) inWedge = true;
        }
        if (x0 < p.margin || x1 > p.margin + farDepth) continue;
        if (!inWedge && !(y0 <= 0 && y1 >= 0)) continue;
        out.tiles.push_back(t.child);
        for (uint32_t mi : t.meshes) appendMesh(out.soup, out.frame, city.meshes[mi], nullptr);
        for (uint32_t ii : t.instances) {
            const SceneInstance& inst = city.instances[ii];
            if (inst.prototype < city.prototypes.size())
                appendMesh(out.soup, out.frame, city.prototypes[inst.prototype], &inst.transform);
        }
    }
    std::sort(out.tiles.begin(), out.tiles.end());
    return out;
}

}  // namespace vista
