// A paged city streamed for the render modes. See city_stream.h.
#include "nodes/render/city_stream.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "foundation/process_memory.h"
#include "nodes/near_field_chunks.h"
#include "runtime/scene/scene_graph.h"

namespace vista {

namespace {

// What the worker thread makes of a region level for the graph: its chunks.
struct RegionChunks {
    osg::ref_ptr<osg::Group> group;
    osg::ref_ptr<osg::StateSet> rootState;
    osg::ref_ptr<osg::Group> labels;  // the chunks' label twins (with labels only)
    osg::ref_ptr<osg::StateSet> labelRootState;
    std::shared_ptr<RayScene::PreparedRegion> rays;  // its Embree scene (null without rays)
    std::shared_ptr<NearFieldRegion> nearField;      // its chunks, block and height patch (null without)
};

}  // namespace

RegionCost streamRegionCost(bool rays, StreamGraph graph, bool labels) {
    const double graphPerChunkByte = 1.0 + (labels ? kStreamLabelsPerChunkByte : 0.0);
    const bool every = graph == StreamGraph::EveryLevel;
    RegionCost c;
    // A level that makes nothing (no rays, no chunks) still holds its decoded file until the frame
    // thread takes it: one byte per file byte at the least.
    c.full = std::max(
        1.0, (rays ? kStreamRaysPerFileByte : 0.0) + (every ? kStreamChunksPerFileByte * graphPerChunkByte : 0.0));
    c.coarse = std::max(1.0, (rays ? kStreamCoarseRaysPerFileByte : 0.0) +
                                 (every ? kStreamCoarseChunksPerFileByte * graphPerChunkByte : 0.0));
    c.chunks = kStreamChunksPerFileByte * graphPerChunkByte;
    c.loading = kStreamLoadingPerFileByte;
    return c;
}

CityStream::~CityStream() { _pager.reset(); }

Result<std::unique_ptr<CityStream>> CityStream::create(const PagedManifest& manifest, RegionPagerOptions options,
                                                       bool rays, std::vector<SceneMesh> prototypes, bool labels) {
    std::unique_ptr<CityStream> s(new CityStream());
    if (rays) {
        auto r = StreamedRayScene::follower(manifest, std::move(prototypes));
        if (!r) return r.status();
        s->_rays = std::move(*r);
    }
    s->_root = new osg::Group;
    s->_root->setName("vista.streamed_city");
    if (labels) {
        s->_labelRoot = new osg::Group;
        s->_labelRoot->setName("vista.streamed_city_labels");
    }
    const StreamedRayScene* rayScene = s->_rays.get();
    // Set before the first load, if at all.
    const std::unique_ptr<StreamedNearField>* nearField = &s->_near;
    const StreamGraph* graphLevels = &s->_graphLevels;
    s->_manifest = &manifest;
    options.prepare = [rayScene, nearField, graphLevels, labels](SceneModel& model,
                                                                 const RegionLoad& load) -> std::shared_ptr<void> {
        auto out = std::make_shared<RegionChunks>();
        // The ray scene first: it completes the model's tree prototypes, which the height patch bounds too.
        if (rayScene && load.level) out->rays = rayScene->prepare(model);
        out->group = new osg::Group;
        const bool chunks = load.chunks && *graphLevels != StreamGraph::None;
        // What is made no longer needs the decoded model (unless its ray scene failed: the
        // frame thread builds it again for the error's message).
        struct FreeModel {
            SceneModel& m;
            bool keep;
            ~FreeModel() {
                if (!keep) m = SceneModel();
            }
        } freeModel{model, rayScene && load.level && !out->rays};
        osg::ref_ptr<osg::Node> root = sceneRoot(model);
        if (*nearField) {
            // The chunks serve both the graph and the near field (no label twins: the label
            // channels of a streamed city come from `full` only).
            out->nearField = (*nearField)->prepare(root.get(), model, chunks, load.level);
            const NearFieldScene& nf = out->nearField->scene;
            out->rootState = nf.rootState;
            for (uint32_t i : nf.drawOrder) out->group->addChild(nf.chunks[i].get());
            return out;
        }
        if (!chunks) return out;
        NearFieldScene nf = buildNearFieldScene(root.get(), kNearChunkSize, labels);
        out->rootState = nf.rootState;
        for (uint32_t i : nf.drawOrder) out->group->addChild(nf.chunks[i].get());
        if (labels) {
            out->labels = new osg::Group;
            out->labelRootState = nf.labelRootState;
            for (uint32_t i : nf.drawOrder)
                if (i < nf.labelChunks.size()) out->labels->addChild(nf.labelChunks[i].get());
        }
        return out;
    };
    s->_options = options;  // the pager starts with the first advance(), once setGraphLevels has had its say
    s->updateCost();
    return s;
}

void CityStream::enableNearField(int horizonCells) {
    VISTA_CHECK(!_advanced && _rays && !_near);
    _near =
        std::make_unique<StreamedNearField>(_manifest->regionSizeM > 0 ? _manifest->regionSizeM : 2000.0,
                                            pagedHeightLattice(*_manifest, _rays->rays().frameOrigin(), horizonCells));
    updateCost();
}

void CityStream::setGraphLevels(StreamGraph levels, double bandM) {
    VISTA_CHECK(!_advanced && (levels != StreamGraph::NearBand || (std::isfinite(bandM) && bandM >= 0)));
    _graphLevels = levels;
    _options.chunkRadius = levels == StreamGraph::NearBand ? bandM : -1.0;
    updateCost();
}

void CityStream::holdProcessUnder(uint64_t bytes) {
    VISTA_CHECK(_options.budgetBytes > 0 && _options.budgetBytes <= bytes);
    _processBudget = bytes;
    _overhead = _overheadFloor = bytes - _options.budgetBytes;
}

std::vector<uint8_t> CityStream::held() const {
    return _pager ? _pager->held() : std::vector<uint8_t>(_manifest->regions.size(), 0);
}

RegionPagerStats CityStream::stats() const {
    RegionPagerStats s = _pager ? _pager->stats() : RegionPagerStats();
    s.processOverhead = _processBudget ? _overhead : 0;
    return s;
}

namespace {

// A group's key: CityStream::GroupKey.
using GroupKey = std::tuple<bool, int, bool>;

// Inserts `group` as `key`'s group under `root`, before the next group in merge order.
void insertInMergeOrder(osg::Group* root, std::map<GroupKey, osg::ref_ptr<osg::Group>>& groups, GroupKey key,
                        osg::Group* group) {
    auto it = groups.emplace(key, group).first;
    auto next = std::next(it);
    const unsigned at = next == groups.end() ? root->getNumChildren() : root->getChildIndex(next->second.get());
    root->insertChild(at, group);
}

// Removes `key`'s group from `root`; false when there is none.
bool removeGroup(osg::Group* root, std::map<GroupKey, osg::ref_ptr<osg::Group>>& groups, GroupKey key) {
    auto it = groups.find(key);
    if (it == groups.end()) return false;
    root->removeChild(it->second.get());
    groups.erase(it);
    return true;
}

// A region's manifest bounds (its full and coarse levels' graphs), a metre wider on every side
// for the ray scene's own copy of the geometry.
std::pair<glm::dvec3, glm::dvec3> changedBox(const PagedManifest& m, int region) {
    const PagedRegionEntry& e = m.regions[size_t(region)];
    return {e.lo - glm::dvec3(1.0), e.hi + glm::dvec3(1.0)};
}

}  // namespace

Result<CityStreamFrame> CityStream::advance(const glm::dvec3& eye, const glm::dvec3& velocity, bool wait) {
    _advanced = true;
    if (!_pager) _pager = std::make_unique<RegionPager>(*_manifest, _options);
    if (_processBudget > 0 && _pager->idle()) {
        // Measured while no load is under way (a load being prepared is the pager's reserve;
        // the worker hands free pages back after each load) and, after drops, once what they
        // freed is handed back too: else the freed pages would count as the process's own,
        // shrink the budget, and the next drops would shrink it further.
        if (_dropsSinceMeasure) releaseFreeMemory();
        _dropsSinceMeasure = false;
        const uint64_t rss = residentSetBytes(), held = _pager->stats().heldCost;
        _overhead = std::max(_overheadFloor, rss > held ? rss - held : 0);
        _pager->setBudget(_processBudget > _overhead ? _processBudget - _overhead : 1);
    }
    _pager->update(eye, velocity);
    CityStreamFrame f;
    if (const RegionShortfall sf = _pager->cameraShortfall(); sf.starved) {
        // Even the coarse levels of the regions at the camera do not fit: frames would draw nothing.
        const uint64_t own = _processBudget > 0 ? _overhead : 0;
        const uint64_t budget = _processBudget > 0 ? _processBudget : _options.budgetBytes;
        // GB with two decimals; what is needed rounds up, so that the figure given is enough.
        auto gb = [](uint64_t b, bool up = true) {
            const double v = double(b) / double(1ull << 30) * 100.0;
            char buf[32];
            std::snprintf(buf, sizeof buf, "%.2f", (up ? std::ceil(v) : std::round(v)) / 100.0);
            return std::string(buf);
        };
        std::string names;
        for (size_t k = 0; k < sf.regions.size(); ++k) {
            const PagedRegionEntry& r = _manifest->regions[size_t(sf.regions[k])];
            names += (k ? ", " : "") + r.file;
        }
        f.shortfall = "a budget of " + gb(budget, false) + " GB cannot hold the regions at the camera (" + names +
                      ") even at their coarse level; it needs at least " + gb(own + sf.needCoarse) + " GB (" +
                      gb(own + sf.needFull) + " GB for their full detail; " + gb(own, false) +
                      " GB of it the process's own memory beside the regions)";
        return f;
    }
    RegionPagerDelta d = _pager->collect(wait);
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
        const GroupKey key{x.coarse, x.region, x.chunks};
        if (_labelRoot) removeGroup(_labelRoot.get(), _labelGroups, key);
        if (!removeGroup(_root.get(), _groups, key)) continue;
        if (_near) _near->remove(x.chunks ? chunkPartKey(x.region) : levelKey(x.region, x.coarse));
        if (!x.chunks) f.changed.push_back(changedBox(*_manifest, x.region));  // a chunk part is not traced
        ++f.dropped;
    }
    for (RegionArrival& a : d.arrived) {
        auto* chunks = static_cast<RegionChunks*>(a.prepared.get());
        if (!chunks) continue;
        const GroupKey key{a.coarse, a.region, a.chunks};
        if (!_root->getStateSet() && chunks->rootState) _root->setStateSet(chunks->rootState.get());
        insertInMergeOrder(_root.get(), _groups, key, chunks->group.get());
        if (_labelRoot && chunks->labels) {
            if (!_labelRoot->getStateSet() && chunks->labelRootState)
                _labelRoot->setStateSet(chunks->labelRootState.get());
            insertInMergeOrder(_labelRoot.get(), _labelGroups, key, chunks->labels.get());
        }
        if (_near && chunks->nearField)
            _near->add(a.chunks ? chunkPartKey(a.region) : levelKey(a.region, a.coarse), *chunks->nearField);
        if (!a.chunks) f.changed.push_back(changedBox(*_manifest, a.region));
        ++f.arrived;
    }
    if (f.arrived > 0 || f.dropped > 0) ++_generation;
    f.belowDetail = _pager->belowDetail();
    _dropsSinceMeasure = _dropsSinceMeasure || !d.dropped.empty();
    return f;
}

}  // namespace vista
