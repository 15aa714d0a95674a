// Near-field chunker: the city re-chunked into small square chunks for a fine
// near/far split (near_field_chunks.h).
#include "nodes/near_field_chunks.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <tuple>

#include <osg/Geode>
#include <osg/Geometry>
#include <osg/MatrixTransform>

#include "runtime/scene/scene_graph.h"

namespace vista {

namespace {

struct TreeBatch {
    osg::Geometry* source = nullptr;
    std::vector<osg::Vec4> cols[4];
};

struct ChunkBuild {
    glm::dvec3 origin{0.0};
    osg::ref_ptr<osg::Vec3Array> verts = new osg::Vec3Array;
    osg::ref_ptr<osg::Vec4ubArray> colors = new osg::Vec4ubArray;
    std::vector<GLuint> indices;
    std::map<osg::Geometry*, TreeBatch> trees;
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

}  // namespace

NearFieldScene buildNearFieldScene(osg::Node* cityScene, double chunk) {
    NearFieldScene out;
    if (!cityScene) return out;
    chunk = chunk > 0 ? chunk : kNearChunkSize;
    osg::Group* root = cityScene->asGroup();
    out.rootState = cityScene->getStateSet();
    std::map<ChunkKey, ChunkBuild> chunks;
    auto chunkFor = [&](const ChunkKey& key, const glm::dvec3& origin) -> ChunkBuild& {
        auto it = chunks.find(key);
        if (it == chunks.end()) {
            it = chunks.emplace(key, ChunkBuild()).first;
            it->second.origin = origin;
        }
        return it->second;
    };
    auto keep = [&](osg::Node* n) {  // unknown layout: a single chunk with OSG's bound
        const osg::BoundingSphere& bs = n->getBound();
        if (!bs.valid()) return;
        SplitObject o;
        o.lo = glm::dvec3(bs.center().x(), bs.center().y(), bs.center().z()) - glm::dvec3(bs.radius());
        o.hi = glm::dvec3(bs.center().x(), bs.center().y(), bs.center().z()) + glm::dvec3(bs.radius());
        out.objects.push_back(o);
        out.chunks.push_back(n);
    };
    if (!root) {
        keep(cityScene);
        return out;
    }
    int64_t tileId = 0;
    for (unsigned ci = 0; ci < root->getNumChildren(); ++ci) {
        osg::Node* child = root->getChild(ci);
        osg::MatrixTransform* xf = asCityTile(child);
        if (!xf) {
            keep(child);
            continue;
        }
        ++tileId;
        const osg::Vec3d tt = xf->getMatrix().getTrans();
        const glm::dvec3 tileOrigin(tt.x(), tt.y(), tt.z());
        for (osg::Geometry* g : tileGeometries(*xf)) {
            auto* verts = dynamic_cast<osg::Vec3Array*>(g->getVertexArray());
            auto* colors = dynamic_cast<osg::Vec4ubArray*>(g->getColorArray());
            auto* de = dynamic_cast<osg::DrawElements*>(g->getPrimitiveSet(0));
            if (!verts || !de || de->getMode() != GL_TRIANGLES) continue;
            if (g->getName().rfind(kTreeGeometryPrefix, 0) == 0) {
                osg::Vec4Array* cols[4];
                bool ok = true;
                for (unsigned c = 0; c < 4; ++c) {
                    cols[c] = dynamic_cast<osg::Vec4Array*>(g->getVertexAttribArray(kInstanceAttrib0 + c));
                    ok = ok && cols[c];
                }
                if (!ok) continue;
                osg::BoundingBox pb;
                for (const auto& v : *verts) pb.expandBy(v);
                size_t n = std::min<size_t>(cols[0]->size(), size_t(std::max(0, de->getNumInstances())));
                uint64_t protoTris = de->getNumIndices() / 3;
                for (size_t k = 0; k < n; ++k) {
                    glm::mat4 m;
                    for (int c = 0; c < 4; ++c) {
                        const osg::Vec4& v = (*cols[c])[unsigned(k)];
                        m[c] = glm::vec4(v.x(), v.y(), v.z(), v.w());
                    }
                    glm::dvec3 world = tileOrigin + glm::dvec3(m[3]);
                    int64_t cx = int64_t(std::floor(world.x / chunk)), cy = int64_t(std::floor(world.y / chunk));
                    ChunkBuild& cb = chunkFor({tileId, 0, cx, cy}, tileOrigin);
                    TreeBatch& tb = cb.trees[g];
                    tb.source = g;
                    for (int c = 0; c < 4; ++c) tb.cols[c].push_back((*cols[c])[unsigned(k)]);
                    for (int corner = 0; corner < 8; ++corner) {
                        osg::Vec3 v = pb.corner(unsigned(corner));
                        glm::dvec4 w = glm::dmat4(m) * glm::dvec4(v.x(), v.y(), v.z(), 1.0);
                        cb.expand(tileOrigin + glm::dvec3(w));
                    }
                    cb.triangles += protoTris;
                }
                continue;
            }
            // Plain mesh: triangles to chunks by centroid (large ones to the tile's own chunk).
            const unsigned ni = de->getNumIndices();
            std::vector<std::pair<ChunkKey, unsigned>> tris;
            tris.reserve(ni / 3);
            for (unsigned t = 0; t + 2 < ni; t += 3) {
                osg::Vec3 a = (*verts)[de->index(t)], b = (*verts)[de->index(t + 1)], c = (*verts)[de->index(t + 2)];
                osg::BoundingBox bb;
                bb.expandBy(a);
                bb.expandBy(b);
                bb.expandBy(c);
                glm::dvec3 cen = tileOrigin + glm::dvec3((a.x() + b.x() + c.x()) / 3.0, (a.y() + b.y() + c.y()) / 3.0, 0.0);
                bool large = std::max(bb.xMax() - bb.xMin(), bb.yMax() - bb.yMin()) > chunk;
                int64_t cx = int64_t(std::floor(cen.x / chunk)), cy = int64_t(std::floor(cen.y / chunk));
                tris.push_back({large ? ChunkKey{tileId, 1, 0, 0} : ChunkKey{tileId, 0, cx, cy}, t});
            }
            std::stable_sort(tris.begin(), tris.end(),
                             [](const auto& x, const auto& y) { return x.first < y.first; });
            std::vector<int64_t> remap(verts->size(), -1);
            std::vector<unsigned> touched;
            for (size_t s = 0; s < tris.size();) {
                const ChunkKey key = tris[s].first;
                ChunkBuild& cb = chunkFor(key, tileOrigin);
                for (; s < tris.size() && tris[s].first == key; ++s) {
                    for (unsigned k = 0; k < 3; ++k) {
                        unsigned vi = de->index(tris[s].second + k);
                        if (remap[vi] < 0) {
                            remap[vi] = int64_t(cb.verts->size());
                            touched.push_back(vi);
                            const osg::Vec3& p = (*verts)[vi];
                            cb.verts->push_back(p);
                            cb.colors->push_back(colors && vi < colors->size() ? (*colors)[vi] : osg::Vec4ub(255, 255, 255, 255));
                            cb.expand(cb.origin + glm::dvec3(p.x(), p.y(), p.z()));
                        }
                        cb.indices.push_back(GLuint(remap[vi]));
                    }
                    ++cb.triangles;
                }
                for (unsigned vi : touched) remap[vi] = -1;
                touched.clear();
            }
        }
    }
    // Draw order: unknown nodes, then per tile its large triangles, then its squares.
    std::vector<std::tuple<int64_t, int, uint32_t>> drawKeys;
    for (uint32_t i = 0; i < out.chunks.size(); ++i) drawKeys.push_back({-1, 0, i});
    osg::ref_ptr<InstancesBound> instancesBound = new InstancesBound;
    // Materialise the chunks as nodes.
    for (auto& [key, cb] : chunks) {
        if (cb.triangles == 0) continue;
        osg::ref_ptr<osg::Geode> geode = new osg::Geode;
        if (!cb.indices.empty()) {
            osg::ref_ptr<osg::Geometry> g = new osg::Geometry;
            g->setUseDisplayList(false);
            g->setUseVertexBufferObjects(true);
            cb.colors->setNormalize(true);
            g->setVertexArray(cb.verts.get());
            g->setColorArray(cb.colors.get(), osg::Array::BIND_PER_VERTEX);
            g->addPrimitiveSet(new osg::DrawElementsUInt(GL_TRIANGLES, cb.indices.begin(), cb.indices.end()));
            geode->addDrawable(g.get());
        }
        for (auto& [src, tb] : cb.trees) {
            osg::ref_ptr<osg::Geometry> g = new osg::Geometry;
            g->setName(src->getName());
            g->setUseDisplayList(false);
            g->setUseVertexBufferObjects(true);
            g->setVertexArray(src->getVertexArray());
            if (src->getNormalArray()) g->setNormalArray(src->getNormalArray(), osg::Array::BIND_PER_VERTEX);
            g->setColorArray(src->getColorArray(), osg::Array::BIND_PER_VERTEX);
            osg::ref_ptr<osg::PrimitiveSet> ps =
                static_cast<osg::PrimitiveSet*>(src->getPrimitiveSet(0)->clone(osg::CopyOp::SHALLOW_COPY));
            ps->setNumInstances(int(tb.cols[0].size()));
            g->addPrimitiveSet(ps.get());
            osg::BoundingBox bb;
            osg::BoundingBox pb;
            for (const auto& v : *static_cast<osg::Vec3Array*>(src->getVertexArray())) pb.expandBy(v);
            for (unsigned c = 0; c < 4; ++c) {
                osg::ref_ptr<osg::Vec4Array> a = new osg::Vec4Array(tb.cols[c].begin(), tb.cols[c].end());
                g->setVertexAttribArray(kInstanceAttrib0 + c, a.get(), osg::Array::BIND_PER_VERTEX);
            }
            for (size_t k = 0; k < tb.cols[0].size(); ++k) {
                osg::Matrixf m(tb.cols[0][k].x(), tb.cols[0][k].y(), tb.cols[0][k].z(), tb.cols[0][k].w(),
                               tb.cols[1][k].x(), tb.cols[1][k].y(), tb.cols[1][k].z(), tb.cols[1][k].w(),
                               tb.cols[2][k].x(), tb.cols[2][k].y(), tb.cols[2][k].z(), tb.cols[2][k].w(),
                               tb.cols[3][k].x(), tb.cols[3][k].y(), tb.cols[3][k].z(), tb.cols[3][k].w());
                for (unsigned corner = 0; corner < 8; ++corner) bb.expandBy(pb.corner(corner) * m);
            }
            g->setInitialBound(bb);
            g->setComputeBoundingBoxCallback(instancesBound.get());
            g->setStateSet(src->getStateSet());
            geode->addDrawable(g.get());
        }
        osg::ref_ptr<osg::MatrixTransform> xf = new osg::MatrixTransform;
        xf->setDataVariance(osg::Object::DYNAMIC);
        xf->setMatrix(osg::Matrixd::translate(cb.origin.x, cb.origin.y, cb.origin.z));
        xf->addChild(geode.get());
        SplitObject o;
        o.lo = cb.lo;
        o.hi = cb.hi;
        o.triangles = cb.triangles;
        out.triangles += cb.triangles;
        out.objects.push_back(o);
        drawKeys.push_back({std::get<0>(key), std::get<1>(key) == 1 ? 0 : 1, uint32_t(out.chunks.size())});
        out.chunks.push_back(xf);
    }
    std::stable_sort(drawKeys.begin(), drawKeys.end());
    for (const auto& k : drawKeys) out.drawOrder.push_back(std::get<2>(k));
    return out;
}

}  // namespace vista
