// The near field of a streamed paged city. See streamed_near_field.h.
#include "nodes/render/streamed_near_field.h"

#include <algorithm>
#include <limits>

#include "foundation/status.h"

namespace vista {

HeightGrid pagedHeightLattice(const PagedManifest& m, const glm::dvec3& frameOrigin, int cells) {
    glm::dvec2 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
    for (const PagedRegionEntry& r : m.regions) {
        if (r.empty) continue;
        lo = glm::min(lo, glm::dvec2(r.lo));
        hi = glm::max(hi, glm::dvec2(r.hi));
    }
    if (!(lo.x <= hi.x) || !(lo.y <= hi.y)) lo = hi = glm::dvec2(frameOrigin);  // no region: one point
    return HeightGrid::lattice(lo, hi, frameOrigin, cells);
}

StreamedNearField::StreamedNearField(double blockCell, HeightGrid grid)
    : _index(_scene.objects, blockCell, nullptr), _grid(std::move(grid)) {}

std::shared_ptr<NearFieldRegion> StreamedNearField::prepare(osg::Node* root, const SceneModel& model, bool chunks,
                                                            bool heights) const {
    auto out = std::make_shared<NearFieldRegion>();
    if (chunks) out->scene = buildNearFieldScene(root, kNearChunkSize, false);
    out->block = SplitIndex::makeBlock(out->scene.objects.data(), out->scene.objects.size());
    if (heights && _grid.cells() > 0) out->heights = std::make_shared<const HeightPatch>(_grid.patch(model));
    return out;
}

uint32_t StreamedNearField::allocate(uint32_t count) {
    if (count == 0) return uint32_t(_scene.objects.size());
    for (auto it = _free.begin(); it != _free.end(); ++it) {
        if (it->second < count) continue;
        const uint32_t first = it->first, left = it->second - count;
        _free.erase(it);
        if (left > 0) _free[first + count] = left;
        return first;
    }
    const uint32_t first = uint32_t(_scene.objects.size());
    _scene.objects.resize(size_t(first) + count);
    _scene.chunks.resize(size_t(first) + count);
    _scene.chunkTile.resize(size_t(first) + count, -1);
    return first;
}

void StreamedNearField::release(uint32_t first, uint32_t count) {
    if (count == 0) return;
    SplitObject none;
    none.lo = none.hi = glm::dvec3(std::numeric_limits<double>::infinity());
    for (uint32_t i = first; i < first + count; ++i) {
        _scene.objects[i] = none;
        _scene.chunks[i] = nullptr;
    }
    // Merge with the free runs on either side.
    auto next = _free.lower_bound(first);
    if (next != _free.end() && next->first == first + count) {
        count += next->second;
        next = _free.erase(next);
    }
    if (next != _free.begin()) {
        auto prev = std::prev(next);
        if (prev->first + prev->second == first) {
            first = prev->first;
            count += prev->second;
            _free.erase(prev);
        }
    }
    if (size_t(first) + count == _scene.objects.size()) {  // the tail: the lists shrink
        _scene.objects.resize(first);
        _scene.chunks.resize(first);
        _scene.chunkTile.resize(first);
    } else {
        _free[first] = count;
    }
}

void StreamedNearField::add(uint64_t key, const NearFieldRegion& region) {
    VISTA_CHECK(_levels.count(key) == 0 && region.block);
    const NearFieldScene& nf = region.scene;
    VISTA_CHECK(region.block->count == nf.objects.size() && nf.chunks.size() == nf.objects.size());
    Level level;
    level.count = uint32_t(nf.objects.size());
    level.first = allocate(level.count);
    for (uint32_t i = 0; i < level.count; ++i) {
        _scene.objects[level.first + i] = nf.objects[i];
        _scene.chunks[level.first + i] = nf.chunks[i];
        _scene.chunkTile[level.first + i] = -1;
    }
    level.drawOrder = nf.drawOrder;
    if (!_scene.rootState && nf.rootState) _scene.rootState = nf.rootState;
    _scene.triangles += nf.triangles;
    _index.addBlock(key, level.first, region.block);
    if (region.heights && _grid.cells() > 0) _grid.addPatch(key, region.heights);
    _levels[key] = std::move(level);
    rebuildDrawOrder();
}

void StreamedNearField::remove(uint64_t key) {
    auto it = _levels.find(key);
    if (it == _levels.end()) return;
    const Level& level = it->second;
    _index.removeBlock(key);
    _grid.removePatch(key);
    for (uint32_t i = level.first; i < level.first + level.count; ++i) _scene.triangles -= _scene.objects[i].triangles;
    release(level.first, level.count);
    _levels.erase(it);
    rebuildDrawOrder();
}

void StreamedNearField::rebuildDrawOrder() {
    _scene.drawOrder.clear();
    for (const auto& [key, level] : _levels)
        for (uint32_t i : level.drawOrder) _scene.drawOrder.push_back(level.first + i);
}

}  // namespace vista
