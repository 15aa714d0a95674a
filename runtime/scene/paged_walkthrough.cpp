// A paged city opened for a walkthrough. See paged_walkthrough.h.
#include "runtime/scene/paged_walkthrough.h"

#include <cstdio>
#include <utility>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

namespace vista {

Result<PagedOpen> openPagedCity(const std::string& dir, bool needStreets) {
    auto m = readPagedManifest(dir);
    if (!m) return m.status();
    PagedOpen out;
    out.stub.params = m->params;
    if (needStreets) {
        auto g = pagedPathStreets(*m);
        if (!g) return g.status();
        out.stub.streets = std::move(*g);
    }
    out.manifest = std::move(*m);
    return out;
}

Result<SceneModel> loadPagedNear(const PagedOpen& city, const Path& path, const PagedReach& reach, const char* cmd,
                                 bool quiet, std::string* pagedJson,
                                 const std::function<Status(uint64_t bytes)>& beforeLoad) {
    std::vector<glm::dvec2> points;
    for (const PathSample& s : path.samples) points.emplace_back(s.position.x, s.position.y);
    if (points.empty()) points.emplace_back(city.manifest.params.origin_x, city.manifest.params.origin_y);
    const double radius = reach.radius;
    const std::vector<int> regions = selectPagedRegions(city.manifest, points, radius);
    const std::vector<int> coarse =
        reach.far > radius ? selectCoarseRegions(city.manifest, points, reach.far, regions) : std::vector<int>{};
    if (beforeLoad) {
        uint64_t bytes = 0;
        for (int r : regions) bytes += city.manifest.regions[size_t(r)].bytes;
        for (int r : coarse) bytes += city.manifest.regions[size_t(r)].coarseBytes;
        VISTA_RETURN_IF_ERROR(beforeLoad(bytes));
    }
    PagedLoadReport rep;
    auto model = loadPagedCity(city.manifest, regions, radius, &rep, coarse);
    if (!model) return model.status();
    if (!quiet)
        std::fprintf(
            stderr,
            "%s: paged city: loaded %d of %d regions within %g m of the walkthrough and %d more at their coarse level "
            "(%.1f MB of region files, %zu triangles)\n",
            cmd, rep.regionsLoaded, rep.regionsTotal, radius, rep.coarseLoaded, double(rep.bytesLoaded) / 1e6,
            model->triangles);
    for (const std::string& d : rep.damaged)
        std::fprintf(stderr, "%s: warning: %s; the rest of the city is loaded\n", cmd, d.c_str());
    if (pagedJson) {
        nlohmann::json j = {{"regions_loaded", rep.regionsLoaded},
                            {"regions_total", rep.regionsTotal},
                            {"radius_m", radius},
                            {"bytes_loaded", rep.bytesLoaded},
                            {"coarse_regions_loaded", rep.coarseLoaded},
                            {"far_m", reach.far},
                            {"coarse_bytes_loaded", rep.coarseBytes},
                            {"damaged", rep.damaged}};
        *pagedJson = j.dump();
    }
    return model;
}

}  // namespace vista
