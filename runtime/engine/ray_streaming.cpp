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
    return s;
}

Result<std::unique_ptr<StreamedRayScene>> StreamedRayScene::create(const PagedManifest& manifest,
                                                                   const RegionPagerOptions& options,
                                                                   std::vector<SceneMesh> prototypes) {
    auto s = follower(manifest, std::move(prototypes));
    if (!s) return s.status();
    (*s)->_pager = std::make_unique<RegionPager>(manifest, options);
    return s;
}

Result<RayStreamFrame> StreamedRayScene::advance(const glm::dvec3& eye, const glm::dvec3& velocity) {
    VISTA_CHECK(_pager != nullptr);
    _pager->update(eye, velocity);
    RegionPagerDelta d = _pager->collect();
    return apply(d);
}

Result<RayStreamFrame> StreamedRayScene::apply(RegionPagerDelta& d) {
    RayStreamFrame f;
    f.waited = d.waited;
    f.damaged = d.damaged;
    for (const RegionDrop& x : d.dropped) {
        auto it = _ids.find({x.region, x.coarse});
        if (it == _ids.end()) continue;  // never added (it failed to add)
        VISTA_RETURN_IF_ERROR(_rays->removeRegion(it->second));
        _ids.erase(it);
        ++f.dropped;
    }
    for (RegionArrival& a : d.arrived) {
        // Tree shapes the region model lacks: the city's.
        if (a.model.prototypes.size() == _prototypes.size())
            for (size_t p = 0; p < _prototypes.size(); ++p)
                if (a.model.prototypes[p].indices.empty()) a.model.prototypes[p] = _prototypes[p];
        auto id = _rays->addRegion(a.model);
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
