// The walkthrough loader shared by view, bench and render. See walkthrough.h.
#include "nodes/render/walkthrough.h"

#include <algorithm>
#include <cstdio>
#include <utility>

#include "foundation/timing.h"
#include "nodes/baked_file.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/scene_graph.h"

namespace vista {

Result<Walkthrough> loadWalkthrough(const WalkthroughRequest& req, ModeOptions& options) {
    Walkthrough w;
    bool havePath = false;
    Stopwatch sw;
    if (req.allowPaged && isPagedCityPath(req.city)) {
        auto paged = openPagedCity(req.city, req.pathNeedsStreets);
        if (!paged) return paged.status();
        auto path = req.makePath(paged->stub);
        if (!path) return path.status();
        w.path = std::move(*path);
        havePath = true;
        if (req.streamPaged) {
            if (req.beforePagedLoad) VISTA_RETURN_IF_ERROR(req.beforePagedLoad(0));
            w.city = std::move(paged->stub);
            w.pagedJson = "{\"streamed\": true, \"regions_total\": " + std::to_string(paged->manifest.nonEmpty()) + "}";
        } else {
            auto city = loadPagedNear(*paged, w.path, req.paged, req.cmd, req.quiet, &w.pagedJson, req.beforePagedLoad);
            if (!city) return city.status();
            w.city = std::move(*city);
        }
        w.manifest = std::make_shared<const PagedManifest>(std::move(paged->manifest));
    } else {
        auto city = loadCityFile(req.city);
        if (!city) return city.status();
        w.city = std::move(*city);
    }
    w.cityLoadMs = sw.ms();
    if (req.cityLoaded) req.cityLoaded();
    if (req.checkCity) VISTA_RETURN_IF_ERROR(req.checkCity(w.city));
    VISTA_RETURN_IF_ERROR(loadPairedBakes(req.cmd, req.city, sceneRoot(w.city), req.bakedModes, options));
    if (!havePath) {
        auto path = req.makePath(w.city);
        if (!path) return path.status();
        w.path = std::move(*path);
    }
    auto fx = req.effects(w.city.params.effects);
    if (!fx) return fx.status();
    options.effects = *fx;
    return w;
}

Status loadPairedBakes(const std::string& cmd, const std::string& cityPath, const osg::Node* cityRoot,
                       const std::vector<std::string>& modes, ModeOptions& o) {
    auto has = [&](const char* m) { return modes.empty() || std::find(modes.begin(), modes.end(), m) != modes.end(); };
    std::vector<std::pair<const char*, std::string>> files;
    if (!o.bakedFile.empty() && (has("impostor") || (has("lodmesh") && o.bakedMeshFile.empty())))
        files.push_back({"--baked", o.bakedFile});
    if (!o.bakedMeshFile.empty() && has("lodmesh")) files.push_back({"--baked-mesh", o.bakedMeshFile});
    for (const auto& [flag, path] : files) {
        if (o.loadedBakes.count(path)) continue;
        Stopwatch sw;
        auto bf = loadBakedFile(path);
        if (!bf) return Status::error(std::string(flag) + ": " + bf.status().message());
        // Each flag takes one representation (a user error, refused before anything is drawn).
        const std::string f = flag;
        if (f == "--baked-mesh" && !bf->meshes)
            return Status::error("--baked-mesh: '" + path +
                                 "' holds point impostors; --baked-mesh takes a file from 'vista bake "
                                 "--representation mesh' (pass a points bake as --baked)");
        if (f == "--baked" && bf->meshes && !modes.empty() && has("impostor"))
            return Status::error("--baked: '" + path +
                                 "' holds textured depth meshes, and mode impostor needs point impostors; pass it as "
                                 "--baked-mesh (for mode lodmesh) and a points bake as --baked");
        const double ms = sw.ms();
        std::string warning;
        VISTA_RETURN_IF_ERROR(checkBakedFromCity(path, *bf, cityPath, cityRoot, &warning));
        if (!warning.empty()) std::fprintf(stderr, "%s: warning: %s\n", cmd.c_str(), warning.c_str());
        o.loadedBakes[path] = {bf->root, ms};
    }
    return Status::ok();
}

Result<Path> walkthroughPath(const std::string& csvFile, const PathOptions& options, const SceneModel& city) {
    if (!csvFile.empty()) return loadPathCsv(csvFile);
    return generatePath(city.streets, city.params, options);
}

}  // namespace vista
