// StreamedNearField: the near field of a streamed paged city (the hybrid
// mode under bench --paged-stream): the resident region levels' 40 m chunks
// in one NearFieldScene, their split index (SplitIndex blocks) and the
// horizon's height grid, each following the resident set region by region.
//
// A region level is cut on the pager's worker thread (prepare(): its chunks,
// its SplitIndex block, its HeightPatch on the grid's lattice); between
// frames add() and remove() only splice: a level's chunks and objects take
// a run of slots in scene() (the first free run that fits, else appended;
// a removed level's slots are freed: its chunks null, its objects empty
// boxes at infinity with no triangles, outside every block), its block joins
// or leaves index() and its patch the grid. Nothing is rebuilt and no
// per-frame query walks the resident levels: selection visits the blocks and
// cells near the eye (SplitIndex). scene().drawOrder lists the resident
// chunks in block order (full levels by region, then coarse levels by
// region, as loadPagedCity() merges them), each level's chunks in their own
// draw order; rebuilt on each change (a list of indices).
//
// Keys: levelKey(region, coarse) orders levels as a preloaded city merges
// them, so index().within() returns chunks in the order a preloaded run of
// the same regions draws them.
//
// Contract: add() of a key not present; remove() of an unknown key does
// nothing. Not thread-safe: add/remove between frames; prepare() is
// thread-safe (it reads the lattice only).
#pragma once
#include <cstdint>
#include <map>
#include <memory>
#include <vector>

#include <osg/Node>

#include "nodes/near_field_chunks.h"
#include "runtime/engine/adaptive_split.h"
#include "runtime/engine/horizon.h"
#include "runtime/scene/paged_load.h"
#include "runtime/scene/scene_model.h"

namespace vista {

// What a worker makes of one region level for the near field.
struct NearFieldRegion {
    NearFieldScene scene;                            // the level's chunks (buildNearFieldScene)
    std::shared_ptr<const SplitIndex::Block> block;  // its objects, bucketed
    std::shared_ptr<const HeightPatch> heights;      // its cells on the grid's lattice (null: no grid)
};

// (coarse, region) as one key, in the order loadPagedCity() merges levels.
inline uint64_t levelKey(int region, bool coarse) { return (uint64_t(coarse ? 1 : 0) << 32) | uint32_t(region); }
// A full region's chunk part (RegionArrival::chunks): after every level, by region.
inline uint64_t chunkPartKey(int region) { return (uint64_t(1) << 40) | uint32_t(region); }

// The paged city's horizon lattice: its regions' bounds (the manifest's, non-empty regions),
// cells as HeightGrid::build (0 = auto), in the frame of frameOrigin.
HeightGrid pagedHeightLattice(const PagedManifest& manifest, const glm::dvec3& frameOrigin, int cells);

class StreamedNearField {
public:
    // blockCell: the cells that find blocks (the paged city's region size, metres, > 0).
    // grid: the horizon's lattice (HeightGrid::lattice), or an empty grid for none.
    StreamedNearField(double blockCell, HeightGrid grid);
    StreamedNearField(const StreamedNearField&) = delete;
    StreamedNearField& operator=(const StreamedNearField&) = delete;

    // Worker side: the level's chunks, block and patch (`root`: the level's graph).
    // chunks = false: no chunks (an empty block): a level the near field never draws
    // (CityStream::setGraphLevels); heights = false: no height patch (a chunk part, whose level
    // brings it).
    std::shared_ptr<NearFieldRegion> prepare(osg::Node* root, const SceneModel& model, bool chunks = true,
                                             bool heights = true) const;
    void add(uint64_t key, const NearFieldRegion& region);
    void remove(uint64_t key);

    const NearFieldScene& scene() const { return _scene; }
    const SplitIndex& index() const { return _index; }
    const HeightGrid* grid() const { return _grid.cells() > 0 ? &_grid : nullptr; }
    size_t levels() const { return _levels.size(); }
    size_t slots() const { return _scene.objects.size(); }  // used and free

private:
    struct Level {
        uint32_t first = 0, count = 0;
        std::vector<uint32_t> drawOrder;  // local chunk indices
    };
    uint32_t allocate(uint32_t count);
    void release(uint32_t first, uint32_t count);
    void rebuildDrawOrder();

    NearFieldScene _scene;
    SplitIndex _index;
    HeightGrid _grid;
    std::map<uint64_t, Level> _levels;
    std::map<uint32_t, uint32_t> _free;  // free runs of slots: first -> count
};

}  // namespace vista
