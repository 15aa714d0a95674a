// A paged city streamed for the render modes. See city_stream.h.
#include "nodes/render/city_stream.h"

#include "nodes/near_field_chunks.h"
#include "runtime/scene/scene_graph.h"

namespace vista {

namespace {

// What the worker thread makes of a region level for the graph: its chunks.
struct RegionChunks {
    osg::ref_ptr<osg::Group> group;
    osg::ref_ptr<osg::StateSet> rootState;
    std::shared_ptr<RayScene::PreparedRegion> rays;  // its Embree scene (null without rays)
    std::shared_ptr<NearFieldRegion> nearField;      // its chunks, block and height patch (null without)
};

}  // namespace

CityStream::~CityStream() { _pager.reset(); }

Result<std::unique_ptr<CityStream>> CityStream::create(const PagedManifest& manifest, RegionPagerOptions options,
                                                       bool rays, std::vector<SceneMesh> prototypes) {
    std::unique_ptr<CityStream> s(new CityStream());
    if (rays) {
        auto r = StreamedRayScene::follower(manifest, std::move(prototypes));
        if (!r) return r.status();
        s->_rays = std::move(*r);
    }
    s->_root = new osg::Group;
    s->_root->setName("vista.streamed_city");
    const StreamedRayScene* rayScene = s->_rays.get();
    const std::unique_ptr<StreamedNearField>* nearField = &s->_near;  // set before the first load, if at all
    s->_manifest = &manifest;
    options.prepare = [rayScene, nearField](SceneModel& model, int, bool) -> std::shared_ptr<void> {
        auto out = std::make_shared<RegionChunks>();
        // The ray scene first: it completes the model's tree prototypes, which the height patch bounds too.
        if (rayScene) out->rays = rayScene->prepare(model);
        out->group = new osg::Group;
        osg::ref_ptr<osg::Node> root = sceneRoot(model);
        if (*nearField) {
            // The chunks serve both the graph and the near field.
            out->nearField = (*nearField)->prepare(root.get(), model);
            const NearFieldScene& nf = out->nearField->scene;
            out->rootState = nf.rootState;
            for (uint32_t i : nf.drawOrder) out->group->addChild(nf.chunks[i].get());
            return out;
        }
        NearFieldScene nf = buildNearFieldScene(root.get(), kNearChunkSize, false);
        out->rootState = nf.rootState;
        for (uint32_t i : nf.drawOrder) out->group->addChild(nf.chunks[i].get());
        return out;
    };
    s->_pager = std::make_unique<RegionPager>(manifest, options);
    return s;
}

void CityStream::enableNearField(int horizonCells) {
    VISTA_CHECK(!_advanced && _rays && !_near);
    _near =
        std::make_unique<StreamedNearField>(_manifest->regionSizeM > 0 ? _manifest->regionSizeM : 2000.0,
                                            pagedHeightLattice(*_manifest, _rays->rays().frameOrigin(), horizonCells));
}

Result<CityStreamFrame> CityStream::advance(const glm::dvec3& eye, const glm::dvec3& velocity) {
    _advanced = true;
    _pager->update(eye, velocity);
    RegionPagerDelta d = _pager->collect();
    CityStreamFrame f;
    f.waited = d.waited;
    f.damaged = d.damaged;
    if (_rays) {
        std::vector<std::shared_ptr<RayScene::PreparedRegion>> prepared;
        for (const RegionArrival& a : d.arrived) {
            auto* chunks = static_cast<RegionChunks*>(a.prepared.get());
            prepared.push_back(chunks ? chunks->rays : nullptr);
        }
        VISTA_RETURN_IF_ERROR(_rays->apply(d, prepared).status());
    }
    for (const RegionDrop& x : d.dropped) {
        auto it = _groups.find({x.coarse, x.region});
        if (it == _groups.end()) continue;
        _root->removeChild(it->second.get());
        _groups.erase(it);
        if (_near) _near->remove(levelKey(x.region, x.coarse));
        ++f.dropped;
    }
    for (RegionArrival& a : d.arrived) {
        auto* chunks = static_cast<RegionChunks*>(a.prepared.get());
        if (!chunks) continue;
        if (!_root->getStateSet() && chunks->rootState) _root->setStateSet(chunks->rootState.get());
        auto it = _groups.emplace(std::make_pair(a.coarse, a.region), chunks->group).first;
        // Insert before the next group in merge order.
        auto next = std::next(it);
        const unsigned at = next == _groups.end() ? _root->getNumChildren() : _root->getChildIndex(next->second.get());
        _root->insertChild(at, chunks->group.get());
        if (_near && chunks->nearField) _near->add(levelKey(a.region, a.coarse), *chunks->nearField);
        ++f.arrived;
    }
    if (f.arrived > 0 || f.dropped > 0) ++_generation;
    return f;
}

}  // namespace vista
