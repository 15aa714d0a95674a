#include "bake/view_cells.h"

#include <algorithm>
#include <cmath>

namespace vista {

std::vector<ViewCell> makeViewCells(const StreetGraph& g, const glm::dvec2& origin,
                                    const std::function<double(const glm::dvec2&)>& ground, const ViewCellParams& p,
                                    std::vector<SkippedCell>* skipped) {
    std::vector<ViewCell> out;
    for (size_t e = 0; e < g.edges.size(); ++e) {
        const StreetEdge& ed = g.edges[e];
        auto skip = [&](const std::string& why) {
            if (skipped) skipped->push_back({uint32_t(e), why});
        };
        if (ed.a >= g.nodes.size() || ed.b >= g.nodes.size()) {
            skip("node index out of range");
            continue;
        }
        const glm::dvec2 a = g.nodes[ed.a], b = g.nodes[ed.b];
        if (!std::isfinite(a.x) || !std::isfinite(a.y) || !std::isfinite(b.x) || !std::isfinite(b.y)) {
            skip("non-finite node position");
            continue;
        }
        const double len = glm::length(b - a);
        if (!(len >= p.minLength)) {
            skip("length " + std::to_string(len) + " m below the minimum " + std::to_string(p.minLength) + " m");
            continue;
        }
        // Ground range along the segment (5 samples, ends included).
        double gmin = 1e300, gmax = -1e300;
        for (int i = 0; i <= 4; ++i) {
            const double h = ground(a + (b - a) * (double(i) / 4.0));
            gmin = std::min(gmin, h);
            gmax = std::max(gmax, h);
        }
        ViewCell c;
        c.id = uint32_t(e);
        c.groundMin = gmin;
        c.groundMax = gmax;
        const double width = std::max(double(ed.width), p.minWidth);
        const double z0 = gmin + p.eyeMin, z1 = gmax + p.eyeMax;
        const glm::dvec2 mid = (a + b) * 0.5 + origin;
        c.box.center = glm::dvec3(mid, 0.5 * (z0 + z1));
        c.box.axis = (b - a) / len;
        c.box.halfLength = 0.5 * len;
        c.box.halfWidth = 0.5 * width;
        c.box.halfHeight = 0.5 * (z1 - z0);
        out.push_back(c);
    }
    return out;
}

}  // namespace vista
