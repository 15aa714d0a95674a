// The ray scene of a paged city fed by the region pager. See ray_streaming.h.
#include "runtime/engine/ray_streaming.h"

namespace vista {

Result<std::unique_ptr<StreamedRayScene>> StreamedRayScene::follower(const PagedManifest& manifest,
                                                                     std::vector<SceneMesh> prototypes) {
    std::unique_ptr<StreamedRayScene> s(new StreamedRayScene());
    if (prototypes.empty()) {
        // The first full region file that loads (set-up: before the first frame).
        for (size_t i = 0; i < manifest.regions.size() && prototypes.empty(); ++i) {
            if (manifest.regions[i].empty) continue;
            auto r = loadPagedRegion(manifest, int(i), false);
            if (r) prototypes = std::move(r->prototypes);
        }
    }
    s->_prototypes = std::move(prototypes);
    auto rays = RayScene::empty(glm::dvec3(manifest.params.origin_x, manifest.params.origin_y, 0.0));
    if (!rays) return rays.status();
    s->_rays = std::move(*rays);
    // What streaming bounds is memory: the regions' scenes in Embree's compact layout.
    s->_rays->setCompactRegions(true);
    return s;
}

std::shared_ptr<RayScene::PreparedRegion> StreamedRayScene::prepare(SceneModel& model) const {
    // Tree shapes the region model lacks: the city's.
    if (model.prototypes.size() == _prototypes.size())
        for (size_t p = 0; p < _prototypes.size(); ++p)
            if (model.prototypes[p].indices.empty()) model.prototypes[p] = _prototypes[p];
    auto r = _rays->prepareRegion(model);
    return r ? *r : nullptr;
}

Result<RayStreamFrame> StreamedRayScene::apply(RegionPagerDelta& d,
                                               const std::vector<std::shared_ptr<RayScene::PreparedRegion>>& prepared) {
    RayStreamFrame f;
    f.waited = d.waited;
    f.damaged = d.damaged;
    for (const RegionDrop& x : d.dropped) {
        if (x.chunks) continue;  // a chunk part: nothing of it is traced
        auto it = _ids.find({x.region, x.coarse});
        if (it == _ids.end()) continue;  // never added (it failed to add)
        VISTA_RETURN_IF_ERROR(_rays->removeRegion(it->second));
        _ids.erase(it);
        ++f.dropped;
    }
    for (size_t k = 0; k < d.arrived.size(); ++k) {
        RegionArrival& a = d.arrived[k];
        if (a.chunks) continue;
        std::shared_ptr<RayScene::PreparedRegion> p = k < prepared.size() ? prepared[k] : nullptr;
        if (!p) p = prepare(a.model);
        if (!p) {
            auto made = _rays->prepareRegion(a.model);  // fails again: its message
            return Status::error("paged region " + std::to_string(a.region) + (a.coarse ? " (coarse)" : "") + ": " +
                                 (made ? std::string("cannot be built") : made.status().message()));
        }
        auto id = _rays->addPrepared(p);
        if (!id)
            return Status::error("paged region " + std::to_string(a.region) + (a.coarse ? " (coarse)" : "") + ": " +
                                 id.status().message());
        _ids[{a.region, a.coarse}] = *id;
        ++f.arrived;
    }
    if (f.arrived > 0 || f.dropped > 0) VISTA_RETURN_IF_ERROR(_rays->commit());
    return f;
}

}  // namespace vista
