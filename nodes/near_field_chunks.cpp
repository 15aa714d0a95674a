// Near-field chunker: the city re-chunked into small square chunks for a fine
// near/far split (near_field_chunks.h).
#include "nodes/near_field_chunks.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <tuple>

#include <osg/Geode>
#include <osg/Geometry>
#include <osg/MatrixTransform>

#include "citygen/labels.h"
#include "citygen/recess_flatten.h"
#include "nodes/label_pass.h"
#include "runtime/scene/scene_graph.h"
#include "runtime/scene/tree_impostor_graph.h"

namespace vista {

namespace {

struct TreeBatch {
    osg::Geometry* source = nullptr;
    std::vector<osg::Vec4> cols[4];
    std::vector<GLuint> ids;  // labels: per-instance tree id
};

struct ChunkBuild {
    glm::dvec3 origin{0.0};
    osg::ref_ptr<osg::Vec3Array> verts = new osg::Vec3Array;
    osg::ref_ptr<osg::Vec4ubArray> colors = new osg::Vec4ubArray;
    osg::ref_ptr<osg::UIntArray> labelIds, labelClasses;  // labels only: per vertex
    std::vector<GLuint> indices;
    std::vector<Material> triMaterial;  // per triangle of `indices`
    std::map<osg::Geometry*, TreeBatch> trees;
    uint64_t treeTriangles = 0;
    glm::dvec3 lo{1e300}, hi{-1e300};
    uint64_t triangles = 0;
    void expand(const glm::dvec3& p) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
};

// (tile, 0 = a square chunk / 1 = the tile's large triangles, cx, cy): a
// chunk never mixes tiles and keeps its tile's origin, so its vertices are
// the loaded floats, bit for bit. Materials stay merged (one draw call per
// chunk). Index order puts a tile's large triangles last, draw order first
// (NearFieldScene::drawOrder).
using ChunkKey = std::tuple<int64_t, int, int64_t, int64_t>;

// The bound of an instanced tree geometry is its instances' box alone (OSG
// would add the prototype's box around the tile origin, far from the chunk,
// and cull almost nothing).
struct InstancesBound : public osg::Drawable::ComputeBoundingBoxCallback {
    osg::BoundingBox computeBound(const osg::Drawable& d) const override { return d.getInitialBound(); }
};

// Builds the chunks of one scene: tiles are added one geometry at a time,
// then materialised as nodes.
class Chunker {
public:
    Chunker(double chunk, bool labels, bool coarse) : _chunk(chunk), _labels(labels), _coarse(coarse) {
        if (labels) _treeLabelState = labelTreeState();
    }

    // Instanced trees: each instance to the square of its trunk position.
    void addTrees(osg::Geometry* g, int64_t tileId, const glm::dvec3& tileOrigin) {
        auto* verts = dynamic_cast<osg::Vec3Array*>(g->getVertexArray());
        auto* de = dynamic_cast<osg::DrawElements*>(g->getPrimitiveSet(0));
        osg::Vec4Array* cols[4];
        for (unsigned c = 0; c < 4; ++c)
            if (!(cols[c] = dynamic_cast<osg::Vec4Array*>(g->getVertexAttribArray(kInstanceAttrib0 + c)))) return;
        osg::BoundingBox pb;
        for (const auto& v : *verts) pb.expandBy(v);
        const size_t n = std::min<size_t>(cols[0]->size(), size_t(std::max(0, de->getNumInstances())));
        auto* treeIds = _labels ? dynamic_cast<osg::UIntArray*>(g->getVertexAttribArray(kTreeIdAttrib)) : nullptr;
        const uint64_t protoTris = de->getNumIndices() / 3;
        for (size_t k = 0; k < n; ++k) {
            glm::mat4 m;
            for (int c = 0; c < 4; ++c) {
                const osg::Vec4& v = (*cols[c])[unsigned(k)];
                m[c] = glm::vec4(v.x(), v.y(), v.z(), v.w());
            }
            const glm::dvec3 world = tileOrigin + glm::dvec3(m[3]);
            ChunkBuild& cb = chunkFor({tileId, 0, cell(world.x), cell(world.y)}, tileOrigin);
            TreeBatch& tb = cb.trees[g];
            tb.source = g;
            for (int c = 0; c < 4; ++c) tb.cols[c].push_back((*cols[c])[unsigned(k)]);
            if (_labels) tb.ids.push_back(treeIds && k < treeIds->size() ? (*treeIds)[unsigned(k)] : 0u);
            for (int corner = 0; corner < 8; ++corner) {
                const osg::Vec3 v = pb.corner(unsigned(corner));
                cb.expand(tileOrigin + glm::dvec3(glm::dmat4(m) * glm::dvec4(v.x(), v.y(), v.z(), 1.0)));
            }
            cb.triangles += protoTris;
            cb.treeTriangles += protoTris;
        }
    }

    // A plain mesh: triangles to squares by centroid, large ones to the tile's own chunk.
    void addMesh(osg::Geometry* g, int64_t tileId, const glm::dvec3& tileOrigin) {
        auto* verts = dynamic_cast<osg::Vec3Array*>(g->getVertexArray());
        auto* colors = dynamic_cast<osg::Vec4ubArray*>(g->getColorArray());
        auto* de = dynamic_cast<osg::DrawElements*>(g->getPrimitiveSet(0));
        auto* ids = _labels ? dynamic_cast<osg::UIntArray*>(g->getVertexAttribArray(kLabelAttrib)) : nullptr;
        const Material material = materialFromName(g->getName().c_str());
        const GLuint cls = GLuint(semanticClass(material));
        const unsigned ni = de->getNumIndices();
        std::vector<std::pair<ChunkKey, unsigned>> tris;
        tris.reserve(ni / 3);
        for (unsigned t = 0; t + 2 < ni; t += 3) {
            const osg::Vec3 a = (*verts)[de->index(t)], b = (*verts)[de->index(t + 1)], c = (*verts)[de->index(t + 2)];
            osg::BoundingBox bb;
            bb.expandBy(a);
            bb.expandBy(b);
            bb.expandBy(c);
            const glm::dvec3 cen =
                tileOrigin + glm::dvec3((a.x() + b.x() + c.x()) / 3.0, (a.y() + b.y() + c.y()) / 3.0, 0.0);
            const bool large = std::max(bb.xMax() - bb.xMin(), bb.yMax() - bb.yMin()) > _chunk;
            tris.push_back({large ? ChunkKey{tileId, 1, 0, 0} : ChunkKey{tileId, 0, cell(cen.x), cell(cen.y)}, t});
        }
        std::stable_sort(tris.begin(), tris.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
        std::vector<int64_t> remap(verts->size(), -1);
        std::vector<unsigned> touched;
        for (size_t s = 0; s < tris.size();) {
            const ChunkKey key = tris[s].first;
            ChunkBuild& cb = chunkFor(key, tileOrigin);
            for (; s < tris.size() && tris[s].first == key; ++s) {
                for (unsigned k = 0; k < 3; ++k) {
                    const unsigned vi = de->index(tris[s].second + k);
                    if (remap[vi] < 0) {
                        remap[vi] = int64_t(cb.verts->size());
                        touched.push_back(vi);
                        const osg::Vec3& p = (*verts)[vi];
                        cb.verts->push_back(p);
                        cb.colors->push_back(colors && vi < colors->size() ? (*colors)[vi]
                                                                           : osg::Vec4ub(255, 255, 255, 255));
                        if (_labels) {
                            if (!cb.labelIds) {
                                cb.labelIds = new osg::UIntArray;
                                cb.labelClasses = new osg::UIntArray;
                            }
                            cb.labelIds->push_back(ids && vi < ids->size() ? (*ids)[vi] : 0u);
                            cb.labelClasses->push_back(cls);
                        }
                        cb.expand(cb.origin + glm::dvec3(p.x(), p.y(), p.z()));
                    }
                    cb.indices.push_back(GLuint(remap[vi]));
                }
                cb.triMaterial.push_back(material);
                ++cb.triangles;
            }
            for (unsigned vi : touched) remap[vi] = -1;
            touched.clear();
        }
    }

    // Appends the chunks to `out` (index order: the map's) and sets its draw
    // order: unknown nodes already in `out`, then per tile its large
    // triangles, then its squares.
    void materialise(NearFieldScene& out) {
        std::vector<std::tuple<int64_t, int, uint32_t>> drawKeys;
        for (uint32_t i = 0; i < out.chunks.size(); ++i) drawKeys.push_back({-1, 0, i});
        for (auto& [key, cb] : _chunks) {
            if (cb.triangles == 0) continue;
            osg::ref_ptr<osg::Geode> geode = new osg::Geode, labelGeode = _labels ? new osg::Geode : nullptr;
            const RecessFlattening flat = flatten(cb);
            NearKindCounts kinds = meshKinds(cb);
            kinds[size_t(NearKind::Facade)] -= flat.jambTriangles;
            kinds[size_t(NearKind::Recess)] += flat.jambTriangles;
            kinds[size_t(NearKind::Tree)] += cb.treeTriangles;
            out.chunkKinds.push_back(kinds);
            if (!cb.indices.empty()) {
                auto g = meshGeometry(cb);
                geode->addDrawable(g.get());
                if (_labels) labelGeode->addDrawable(labelMeshGeometry(*g, cb).get());
            }
            for (auto& [src, tb] : cb.trees) {
                auto g = treeGeometry(*src, tb);
                geode->addDrawable(g.get());
                if (_labels) labelGeode->addDrawable(labelTreeGeometry(*g, *src, tb).get());
            }
            osg::ref_ptr<osg::MatrixTransform> xf = new osg::MatrixTransform;
            xf->setDataVariance(osg::Object::DYNAMIC);
            xf->setMatrix(osg::Matrixd::translate(cb.origin.x, cb.origin.y, cb.origin.z));
            xf->addChild(geode.get());
            if (_coarse) {
                out.coarseChunks.push_back(flat.jambTriangles ? coarseNode(cb, flat, *geode) : nullptr);
                out.coarseTriangles.push_back(cb.triangles - flat.jambTriangles);
                out.coarseError.push_back(float(flat.maxRecessDepth));
            }
            if (_labels) {
                osg::ref_ptr<osg::MatrixTransform> lx = new osg::MatrixTransform;
                lx->setDataVariance(osg::Object::DYNAMIC);
                lx->setMatrix(xf->getMatrix());
                lx->addChild(labelGeode.get());
                out.labelChunks.push_back(lx);
            }
            SplitObject o;
            o.lo = cb.lo;
            o.hi = cb.hi;
            o.triangles = cb.triangles;
            out.triangles += cb.triangles;
            out.objects.push_back(o);
            drawKeys.push_back({std::get<0>(key), std::get<1>(key) == 1 ? 0 : 1, uint32_t(out.chunks.size())});
            const int64_t tid = std::get<0>(key);
            out.chunkTile.push_back(tid >= 0 && size_t(tid) < _tileChild.size() ? _tileChild[size_t(tid)] : -1);
            out.chunks.push_back(xf);
        }
        std::stable_sort(drawKeys.begin(), drawKeys.end());
        for (const auto& k : drawKeys) out.drawOrder.push_back(std::get<2>(k));
    }

private:
    static NearKind kindOf(Material m) {
        switch (m) {
            case Material::Ground:
            case Material::Road:
            case Material::Marking:
            case Material::Sidewalk:
            case Material::Grass: return NearKind::Ground;
            case Material::Wall:
            case Material::Roof: return NearKind::Facade;
            case Material::Window: return NearKind::Window;
            case Material::Car: return NearKind::Car;
            case Material::Trunk:
            case Material::Leaves: return NearKind::Tree;
            default: return NearKind::Other;
        }
    }
    static NearKindCounts meshKinds(const ChunkBuild& cb) {
        NearKindCounts k{};
        for (Material m : cb.triMaterial) ++k[size_t(kindOf(m))];
        return k;
    }
    static RecessFlattening flatten(const ChunkBuild& cb) {
        std::vector<glm::vec3> pos(cb.verts->size());
        for (size_t i = 0; i < pos.size(); ++i) {
            const osg::Vec3& p = (*cb.verts)[unsigned(i)];
            pos[i] = glm::vec3(p.x(), p.y(), p.z());
        }
        return flattenRecesses(pos, std::vector<uint32_t>(cb.indices.begin(), cb.indices.end()), cb.triMaterial);
    }
    // The chunk's flattened twin: moved glass, no jambs, the same colours and
    // the fine geode's trees (its drawables after the mesh, shared).
    static osg::ref_ptr<osg::Node> coarseNode(const ChunkBuild& cb, const RecessFlattening& flat, osg::Geode& fine) {
        osg::ref_ptr<osg::Geometry> g = new osg::Geometry;
        g->setUseDisplayList(false);
        g->setUseVertexBufferObjects(true);
        osg::ref_ptr<osg::Vec3Array> verts = new osg::Vec3Array(unsigned(flat.moved.size()));
        for (size_t i = 0; i < flat.moved.size(); ++i)
            (*verts)[unsigned(i)] = osg::Vec3(flat.moved[i].x, flat.moved[i].y, flat.moved[i].z);
        g->setVertexArray(verts.get());
        g->setColorArray(cb.colors.get(), osg::Array::BIND_PER_VERTEX);  // the chunk's own colours, shared
        std::vector<GLuint> idx;
        idx.reserve(cb.indices.size());
        for (size_t t = 0; t < flat.jamb.size(); ++t)
            if (!flat.jamb[t])
                idx.insert(idx.end(), cb.indices.begin() + long(3 * t), cb.indices.begin() + long(3 * t + 3));
        g->addPrimitiveSet(new osg::DrawElementsUInt(GL_TRIANGLES, idx.begin(), idx.end()));
        osg::ref_ptr<osg::Geode> geode = new osg::Geode;
        geode->addDrawable(g.get());
        for (unsigned d = 1; d < fine.getNumDrawables(); ++d) geode->addDrawable(fine.getDrawable(d));
        osg::ref_ptr<osg::MatrixTransform> xf = new osg::MatrixTransform;
        xf->setDataVariance(osg::Object::DYNAMIC);
        xf->setMatrix(osg::Matrixd::translate(cb.origin.x, cb.origin.y, cb.origin.z));
        xf->addChild(geode.get());
        return xf;
    }
    int64_t cell(double worldCoordinate) const { return int64_t(std::floor(worldCoordinate / _chunk)); }
    ChunkBuild& chunkFor(const ChunkKey& key, const glm::dvec3& origin) {
        auto it = _chunks.find(key);
        if (it == _chunks.end()) {
            it = _chunks.emplace(key, ChunkBuild()).first;
            it->second.origin = origin;
        }
        return it->second;
    }
    static osg::ref_ptr<osg::Geometry> meshGeometry(ChunkBuild& cb) {
        osg::ref_ptr<osg::Geometry> g = new osg::Geometry;
        g->setUseDisplayList(false);
        g->setUseVertexBufferObjects(true);
        cb.colors->setNormalize(true);
        g->setVertexArray(cb.verts.get());
        g->setColorArray(cb.colors.get(), osg::Array::BIND_PER_VERTEX);
        g->addPrimitiveSet(new osg::DrawElementsUInt(GL_TRIANGLES, cb.indices.begin(), cb.indices.end()));
        return g;
    }
    osg::ref_ptr<osg::Geometry> treeGeometry(osg::Geometry& src, const TreeBatch& tb) const {
        osg::ref_ptr<osg::Geometry> g = new osg::Geometry;
        g->setName(src.getName());
        g->setUseDisplayList(false);
        g->setUseVertexBufferObjects(true);
        g->setVertexArray(src.getVertexArray());
        if (src.getNormalArray()) g->setNormalArray(src.getNormalArray(), osg::Array::BIND_PER_VERTEX);
        g->setColorArray(src.getColorArray(), osg::Array::BIND_PER_VERTEX);
        if (src.getTexCoordArray(0))
            g->setTexCoordArray(0, src.getTexCoordArray(0), osg::Array::BIND_PER_VERTEX);  // tree impostors
        osg::ref_ptr<osg::PrimitiveSet> ps =
            static_cast<osg::PrimitiveSet*>(src.getPrimitiveSet(0)->clone(osg::CopyOp::SHALLOW_COPY));
        ps->setNumInstances(int(tb.cols[0].size()));
        g->addPrimitiveSet(ps.get());
        osg::BoundingBox bb, pb;
        for (const auto& v : *static_cast<osg::Vec3Array*>(src.getVertexArray())) pb.expandBy(v);
        for (unsigned c = 0; c < 4; ++c)
            g->setVertexAttribArray(kInstanceAttrib0 + c, new osg::Vec4Array(tb.cols[c].begin(), tb.cols[c].end()),
                                    osg::Array::BIND_PER_VERTEX);
        for (size_t k = 0; k < tb.cols[0].size(); ++k) {
            osg::Matrixf m;
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r) m(c, r) = tb.cols[size_t(c)][k][r];
            for (unsigned corner = 0; corner < 8; ++corner) bb.expandBy(pb.corner(corner) * m);
        }
        g->setInitialBound(bb);
        g->setComputeBoundingBoxCallback(_instancesBound.get());
        g->setStateSet(src.getStateSet());
        return g;
    }

    // The label twin of a chunk's mesh geometry: the same vertex array and
    // primitive set, plus the per-vertex ids and classes (label_pass.h).
    static osg::ref_ptr<osg::Geometry> labelMeshGeometry(osg::Geometry& colour, ChunkBuild& cb) {
        osg::ref_ptr<osg::Geometry> g = new osg::Geometry;
        g->setUseDisplayList(false);
        g->setUseVertexBufferObjects(true);
        g->setVertexArray(colour.getVertexArray());
        g->addPrimitiveSet(colour.getPrimitiveSet(0));
        if (!cb.labelIds) {
            cb.labelIds = new osg::UIntArray(unsigned(cb.verts->size()));
            cb.labelClasses = new osg::UIntArray(unsigned(cb.verts->size()));
        }
        for (osg::UIntArray* a : {cb.labelIds.get(), cb.labelClasses.get()}) {
            a->setPreserveDataType(true);
            a->setBinding(osg::Array::BIND_PER_VERTEX);
        }
        g->setVertexAttribArray(kLabelAttrib, cb.labelIds.get(), osg::Array::BIND_PER_VERTEX);
        g->setVertexAttribArray(kLabelClassAttrib, cb.labelClasses.get(), osg::Array::BIND_PER_VERTEX);
        g->setInitialBound(colour.getInitialBound());
        return g;
    }
    // The label twin of an instanced tree geometry: the same vertices and
    // instance matrices, per-vertex classes from the prototype's parts and
    // the per-instance tree ids.
    osg::ref_ptr<osg::Geometry> labelTreeGeometry(osg::Geometry& colour, osg::Geometry& src,
                                                  const TreeBatch& tb) const {
        osg::ref_ptr<osg::Geometry> g = new osg::Geometry;
        g->setName(colour.getName());
        g->setUseDisplayList(false);
        g->setUseVertexBufferObjects(true);
        g->setVertexArray(colour.getVertexArray());
        g->addPrimitiveSet(colour.getPrimitiveSet(0));
        for (unsigned c = 0; c < 4; ++c)
            g->setVertexAttribArray(kInstanceAttrib0 + c, colour.getVertexAttribArray(kInstanceAttrib0 + c),
                                    osg::Array::BIND_PER_VERTEX);
        const unsigned nv = colour.getVertexArray()->getNumElements();
        osg::ref_ptr<osg::UIntArray> classes = new osg::UIntArray(nv);
        auto* parts = dynamic_cast<osg::UIntArray*>(src.getVertexAttribArray(kLabelAttrib));
        for (unsigned i = 0; i < nv; ++i) {
            const uint32_t part = parts && i < parts->size() ? (*parts)[i] : uint32_t(Material::Leaves);
            const SemanticClass c =
                part < uint32_t(kMaterialCount) ? semanticClass(Material(part)) : SemanticClass::TreeLeaves;
            (*classes)[i] = GLuint(c);
        }
        osg::ref_ptr<osg::UIntArray> ids = new osg::UIntArray(tb.ids.begin(), tb.ids.end());
        for (osg::UIntArray* a : {classes.get(), ids.get()}) a->setPreserveDataType(true);
        g->setVertexAttribArray(kLabelClassAttrib, classes.get(), osg::Array::BIND_PER_VERTEX);
        g->setVertexAttribArray(kTreeIdAttrib, ids.get(), osg::Array::BIND_PER_VERTEX);
        g->setInitialBound(colour.getInitialBound());
        g->setComputeBoundingBoxCallback(_instancesBound.get());
        g->setStateSet(_treeLabelState.get());
        return g;
    }

public:
    // tileId (as passed to addMesh/addTrees) -> the tile's child index in the city root.
    void setTileChild(int64_t tileId, int32_t child) {
        if (tileId < 0) return;
        if (_tileChild.size() <= size_t(tileId)) _tileChild.resize(size_t(tileId) + 1, -1);
        _tileChild[size_t(tileId)] = child;
    }

private:
    std::vector<int32_t> _tileChild;
    double _chunk;
    bool _labels = false;
    bool _coarse = false;
    osg::ref_ptr<osg::StateSet> _treeLabelState;
    std::map<ChunkKey, ChunkBuild> _chunks;
    osg::ref_ptr<InstancesBound> _instancesBound = new InstancesBound;
};

// An unknown layout: one chunk with OSG's bound.
void keepWhole(osg::Node* n, NearFieldScene& out, int32_t child, bool coarse) {
    const osg::BoundingSphere& bs = n->getBound();
    if (!bs.valid()) return;
    SplitObject o;
    o.lo = glm::dvec3(bs.center().x(), bs.center().y(), bs.center().z()) - glm::dvec3(bs.radius());
    o.hi = glm::dvec3(bs.center().x(), bs.center().y(), bs.center().z()) + glm::dvec3(bs.radius());
    out.objects.push_back(o);
    out.chunks.push_back(n);
    out.chunkTile.push_back(child);
    out.chunkKinds.push_back(NearKindCounts{});
    if (coarse) {
        out.coarseChunks.push_back(nullptr);
        out.coarseTriangles.push_back(0);
        out.coarseError.push_back(0.0f);
    }
    if (out.labelRootState) out.labelChunks.push_back(new osg::Group);  // unknown layout: no labels
}

}  // namespace

const char* nearKindName(NearKind kind) {
    static const char* const names[kNearKindCount] = {"ground", "facade", "recess", "window", "car", "tree", "other"};
    return size_t(kind) < kNearKindCount ? names[size_t(kind)] : "?";
}

double screenDeviationPx(double deviation, double distance, double fovY, int width, int height) {
    if (!(distance > 0)) return std::numeric_limits<double>::infinity();
    const double t = std::tan(0.5 * fovY);
    const double f = 0.5 * double(height) / t;  // focal length in pixels
    const double aspect = double(width) / double(height);
    const double tanCorner2 = t * t * (1.0 + aspect * aspect);  // tan^2 of the corner's angle
    return deviation * f * (1.0 + tanCorner2) / distance;       // 1 / cos^2 = 1 + tan^2
}

NearFieldScene buildNearFieldScene(osg::Node* cityScene, double chunk, bool labels, bool coarse) {
    NearFieldScene out;
    if (!cityScene) return out;
    out.rootState = cityScene->getStateSet();
    if (labels) out.labelRootState = labelRootState();
    osg::Group* root = cityScene->asGroup();
    if (!root) {
        keepWhole(cityScene, out, -1, coarse);
        out.drawOrder.assign(out.chunks.size(), 0);
        return out;
    }
    Chunker chunker(chunk > 0 ? chunk : kNearChunkSize, labels, coarse);
    int64_t tileId = 0;
    for (unsigned ci = 0; ci < root->getNumChildren(); ++ci) {
        osg::MatrixTransform* xf = asCityTile(root->getChild(ci));
        if (!xf) {
            keepWhole(root->getChild(ci), out, int32_t(ci), coarse);
            continue;
        }
        ++tileId;
        chunker.setTileChild(tileId, int32_t(ci));
        const osg::Vec3d tt = xf->getMatrix().getTrans();
        const glm::dvec3 tileOrigin(tt.x(), tt.y(), tt.z());
        for (osg::Geometry* g : tileGeometries(*xf)) {
            auto* verts = dynamic_cast<osg::Vec3Array*>(g->getVertexArray());
            auto* de = dynamic_cast<osg::DrawElements*>(g->getPrimitiveSet(0));
            if (!verts || !de || de->getMode() != GL_TRIANGLES) continue;
            if (g->getName().rfind(kTreeGeometryPrefix, 0) == 0 || isTreeImpostorName(g->getName()))
                chunker.addTrees(g, tileId, tileOrigin);
            else chunker.addMesh(g, tileId, tileOrigin);
        }
    }
    chunker.materialise(out);
    return out;
}

}  // namespace vista
