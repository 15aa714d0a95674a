// NearFarSplit: an osg::Group whose cull traversal visits only the near field
// (thesis §4.3.1); every other traversal (update, bounds, intersection,
// serialisation) sees all children.
//
// Near field, by distance (default, 100 m): every child whose world-space
// bounding box comes within nearDistance of the eye. Straddling children are
// drawn whole (no popping). By triangle budget (setTriangleBudget > 0): the
// nearest children (box distance) until the budget would be exceeded (the
// nearest child is always drawn). Children's boxes and triangle counts are
// computed lazily on the first cull after a child changes (ComputeBoundsVisitor;
// instanced primitive sets count instances). The eye is the cull visitor's eye
// point in this node's coordinate frame; put the node where the local frame is
// the world frame (no transform above it), or the boxes are local too.
//
// A streamed near field (setSource): the chunks to choose from are not the
// node's children but a NearFieldScene and its SplitIndex that follow the
// resident regions (StreamedNearField), read at each cull: the chosen chunks
// (non-null slots) are traversed in the index's order. The node then culls
// nothing itself (its children's bounds are not the source's).
//
// Near detail (setNearDetail, the hybrid's viewer face): the chosen chunks
// are traversed nearest first (box distance), and a chunk of the given
// NearFieldScene with a flat twin is traversed as its twin where the twin's
// deviation projects to at most detailPx pixels (screenDeviationPx with the
// cull visitor's projection and viewport) — the bench face's choice.
//
// Thread safety: OSG's single-threaded or CullDrawThreadPerContext models (one
// cull at a time); lastNearCount()/lastNearTriangles() report the last cull.
// A source changes only between frames.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include <osg/Group>
#include <osg/NodeVisitor>

#include "nodes/near_field_chunks.h"
#include "runtime/engine/adaptive_split.h"

namespace vista {

class NearFarSplit : public osg::Group {
public:
    NearFarSplit();
    NearFarSplit(const NearFarSplit& o, const osg::CopyOp& copyop = osg::CopyOp::SHALLOW_COPY);
    META_Node(vista, NearFarSplit);

    void setNearDistance(double metres) { _nearDistance = metres; }
    double getNearDistance() const { return _nearDistance; }
    // > 0: near field = nearest children up to this many triangles (distance ignored).
    void setTriangleBudget(uint64_t triangles) { _triangleBudget = triangles; }
    uint64_t getTriangleBudget() const { return _triangleBudget; }

    // Chooses among `scene`'s chunks by `index` (both outlive the node), or among the children (null).
    void setSource(const std::vector<osg::ref_ptr<osg::Node>>* chunks, const std::vector<SplitObject>* objects,
                   const SplitIndex* index);

    // scene: whose chunks the split chooses among (children or source), for its twins; null = none.
    void setNearDetail(const NearFieldScene* scene, bool frontToBack, double detailPx) {
        _detailScene = scene;
        _frontToBack = frontToBack;
        _detailPx = detailPx;
    }

    void traverse(osg::NodeVisitor& nv) override;

    unsigned lastNearCount() const { return _lastCount; }
    uint64_t lastNearTriangles() const { return _lastTriangles; }
    // The per-child boxes (world frame) used for the split; refreshed on demand.
    const std::vector<SplitObject>& objects();

protected:
    ~NearFarSplit() override = default;
    bool insertChild(unsigned int index, osg::Node* child) override;
    bool removeChildren(unsigned int pos, unsigned int numChildrenToRemove) override;
    bool setChild(unsigned int i, osg::Node* node) override;

private:
    void refresh();
    double _nearDistance = 100.0;
    uint64_t _triangleBudget = 0;
    std::vector<SplitObject> _objects;
    std::unique_ptr<SplitIndex> _index;                                // over _objects, rebuilt with them
    const std::vector<osg::ref_ptr<osg::Node>>* _srcChunks = nullptr;  // setSource
    const std::vector<SplitObject>* _srcObjects = nullptr;
    const SplitIndex* _srcIndex = nullptr;
    const NearFieldScene* _detailScene = nullptr;  // setNearDetail
    bool _frontToBack = false;
    double _detailPx = 0;
    bool _dirty = true;
    unsigned _lastCount = 0;
    uint64_t _lastTriangles = 0;
};

// Triangles drawn by a subgraph (DrawElements/DrawArrays of triangle modes,
// instanced sets multiplied by their instance count).
uint64_t countTriangles(osg::Node* node);

}  // namespace vista
