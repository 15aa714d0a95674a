// `osglod`: osg::LOD per chunk with Simplifier far versions (mode_osglod.h).
#include "nodes/render/mode_osglod.h"

#include <limits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <map>
#include <tuple>

#include <osg/Camera>
#include <osg/Geode>
#include <osg/LOD>
#include <osg/MatrixTransform>
#include <osgUtil/Simplifier>
#include <tbb/parallel_for.h>

#include "foundation/timing.h"
#include "runtime/scene/scene_graph.h"
#include "runtime/scene/tree_impostor_graph.h"

namespace vista {
namespace {

// Vertices at the same position (to 1 mm) merged, colours and normals
// averaged, triangles kept. The city's faces are flat-shaded (no vertex is
// shared between two faces) and osgUtil::Simplifier never collapses an edge
// that touches a mesh boundary, so without this it would remove nothing.
// Other layouts (not a Vec3Array with indexed triangles) are returned as is.
osg::ref_ptr<osg::Geometry> welded(const osg::Geometry& g) {
    const auto* v = dynamic_cast<const osg::Vec3Array*>(g.getVertexArray());
    const auto* de =
        g.getNumPrimitiveSets() == 1 ? dynamic_cast<const osg::DrawElements*>(g.getPrimitiveSet(0)) : nullptr;
    if (!v || !de || de->getMode() != GL_TRIANGLES)
        return new osg::Geometry(g, osg::CopyOp::DEEP_COPY_ARRAYS | osg::CopyOp::DEEP_COPY_PRIMITIVES);
    const auto* c = dynamic_cast<const osg::Vec4ubArray*>(g.getColorArray());
    const auto* n = dynamic_cast<const osg::Vec3Array*>(g.getNormalArray());
    std::map<std::tuple<int64_t, int64_t, int64_t>, GLuint> index;
    std::vector<GLuint> remap(v->size());
    std::vector<osg::Vec4d> colour;
    osg::ref_ptr<osg::Vec3Array> nv = new osg::Vec3Array;
    osg::ref_ptr<osg::Vec3Array> nn = new osg::Vec3Array;
    for (size_t i = 0; i < v->size(); ++i) {
        const osg::Vec3& p = (*v)[i];
        auto key =
            std::make_tuple(std::llround(p.x() * 1000.0), std::llround(p.y() * 1000.0), std::llround(p.z() * 1000.0));
        auto [it, fresh] = index.emplace(key, GLuint(nv->size()));
        if (fresh) {
            nv->push_back(p);
            colour.push_back(osg::Vec4d());
            nn->push_back(osg::Vec3());
        }
        remap[i] = it->second;
        if (c && i < c->size()) {
            const osg::Vec4ub& cc = (*c)[i];
            colour[it->second] += osg::Vec4d(cc.r(), cc.g(), cc.b(), cc.a());
        }
        if (n && i < n->size()) (*nn)[it->second] += (*n)[i];
    }
    osg::ref_ptr<osg::Geometry> w = new osg::Geometry;
    w->setStateSet(const_cast<osg::StateSet*>(g.getStateSet()));
    w->setName(g.getName());
    w->setVertexArray(nv.get());
    if (c) {
        std::vector<int> count(nv->size(), 0);
        for (size_t i = 0; i < v->size() && i < c->size(); ++i) ++count[remap[i]];
        osg::ref_ptr<osg::Vec4ubArray> nc = new osg::Vec4ubArray;
        for (size_t k = 0; k < nv->size(); ++k) {
            const osg::Vec4d a = colour[k] / double(std::max(1, count[k]));
            nc->push_back(osg::Vec4ub(uint8_t(std::lround(a.x())), uint8_t(std::lround(a.y())),
                                      uint8_t(std::lround(a.z())), uint8_t(std::lround(a.w()))));
        }
        nc->setNormalize(c->getNormalize());
        w->setColorArray(nc.get(), osg::Array::BIND_PER_VERTEX);
    }
    if (n) {
        for (auto& x : *nn) x.normalize();
        w->setNormalArray(nn.get(), osg::Array::BIND_PER_VERTEX);
    }
    osg::ref_ptr<osg::DrawElementsUInt> tris = new osg::DrawElementsUInt(GL_TRIANGLES);
    for (unsigned i = 0; i < de->getNumIndices(); ++i) tris->push_back(remap[de->index(i)]);
    w->addPrimitiveSet(tris.get());
    return w;
}

// A simplified copy of a plain (non-instanced) triangle geometry.
osg::ref_ptr<osg::Geometry> simplifiedCopy(const osg::Geometry& g, double ratio) {
    osg::ref_ptr<osg::Geometry> c = welded(g);
    osgUtil::Simplifier s(ratio);
    s.setDoTriStrip(false);
    s.setSmoothing(false);
    s.simplify(*c);
    c->setUseDisplayList(false);
    c->setUseVertexBufferObjects(true);
    return c;
}

bool isTree(const osg::Drawable* d) { return d->getName().rfind(kTreeGeometryPrefix, 0) == 0; }

// Tree prototypes simplified once per level (key: the prototype's vertex array).
class PrototypeCache {
public:
    explicit PrototypeCache(double ratio) : _ratio(ratio) {}
    void add(const osg::Geometry& tree) {
        const osg::Array* key = tree.getVertexArray();
        if (_protos.count(key) || tree.getNumPrimitiveSets() == 0) return;
        osg::ref_ptr<osg::Geometry> plain = new osg::Geometry;
        plain->setVertexArray(const_cast<osg::Array*>(tree.getVertexArray()));
        if (tree.getNormalArray())
            plain->setNormalArray(const_cast<osg::Array*>(tree.getNormalArray()), osg::Array::BIND_PER_VERTEX);
        if (tree.getColorArray())
            plain->setColorArray(const_cast<osg::Array*>(tree.getColorArray()), osg::Array::BIND_PER_VERTEX);
        osg::ref_ptr<osg::PrimitiveSet> ps =
            static_cast<osg::PrimitiveSet*>(tree.getPrimitiveSet(0)->clone(osg::CopyOp::DEEP_COPY_ALL));
        ps->setNumInstances(0);
        plain->addPrimitiveSet(ps.get());
        _protos[key] = simplifiedCopy(*plain, _ratio);
    }
    // The chunk's instanced tree drawn with the simplified prototype (null: nothing left).
    osg::ref_ptr<osg::Geometry> instance(const osg::Geometry& tree) const {
        auto it = _protos.find(tree.getVertexArray());
        if (it == _protos.end() || it->second->getNumPrimitiveSets() == 0) return nullptr;
        const osg::Geometry& p = *it->second;
        osg::ref_ptr<osg::Geometry> g = new osg::Geometry;
        g->setName(tree.getName());
        g->setUseDisplayList(false);
        g->setUseVertexBufferObjects(true);
        g->setVertexArray(const_cast<osg::Array*>(p.getVertexArray()));
        if (p.getNormalArray())
            g->setNormalArray(const_cast<osg::Array*>(p.getNormalArray()), osg::Array::BIND_PER_VERTEX);
        if (p.getColorArray())
            g->setColorArray(const_cast<osg::Array*>(p.getColorArray()), osg::Array::BIND_PER_VERTEX);
        osg::ref_ptr<osg::PrimitiveSet> ps =
            static_cast<osg::PrimitiveSet*>(p.getPrimitiveSet(0)->clone(osg::CopyOp::SHALLOW_COPY));
        ps->setNumInstances(tree.getPrimitiveSet(0)->getNumInstances());
        g->addPrimitiveSet(ps.get());
        for (unsigned c = 0; c < 4; ++c)
            g->setVertexAttribArray(kInstanceAttrib0 + c,
                                    const_cast<osg::Array*>(tree.getVertexAttribArray(kInstanceAttrib0 + c)),
                                    osg::Array::BIND_PER_VERTEX);
        g->setInitialBound(tree.getInitialBound());
        g->setComputeBoundingBoxCallback(
            const_cast<osg::Drawable::ComputeBoundingBoxCallback*>(tree.getComputeBoundingBoxCallback()));
        g->setStateSet(const_cast<osg::StateSet*>(tree.getStateSet()));
        return g;
    }

private:
    double _ratio;
    std::map<const osg::Array*, osg::ref_ptr<osg::Geometry>> _protos;
};

// Tree prototypes as impostors (citygen/tree_impostor.h), baked once per
// prototype (key: the prototype's vertex array), for the far levels.
class ImpostorCache {
public:
    void add(const osg::Geometry& tree) {
        const osg::Array* key = tree.getVertexArray();
        if (_impostors.count(key) || tree.getNumPrimitiveSets() == 0) return;
        const auto* v = dynamic_cast<const osg::Vec3Array*>(tree.getVertexArray());
        const auto* c = dynamic_cast<const osg::Vec4ubArray*>(tree.getColorArray());
        const auto* de = dynamic_cast<const osg::DrawElements*>(tree.getPrimitiveSet(0));
        if (!v || !de || de->getMode() != GL_TRIANGLES) return;
        std::vector<glm::vec3> positions(v->size());
        std::vector<glm::u8vec4> colors(v->size(), glm::u8vec4(255));
        for (size_t i = 0; i < v->size(); ++i) positions[i] = glm::vec3((*v)[i].x(), (*v)[i].y(), (*v)[i].z());
        if (c)
            for (size_t i = 0; i < c->size() && i < v->size(); ++i)
                colors[i] = glm::u8vec4((*c)[i].r(), (*c)[i].g(), (*c)[i].b(), (*c)[i].a());
        std::vector<uint32_t> indices;
        for (unsigned i = 0; i + 2 < de->getNumIndices(); i += 3)
            if (de->index(i) < v->size() && de->index(i + 1) < v->size() && de->index(i + 2) < v->size())
                for (unsigned k = 0; k < 3; ++k) indices.push_back(de->index(i + k));
        _impostors[key] = makeTreeImpostorArrays(makeTreeImpostor(positions, colors, indices));
    }
    // The chunk's instanced tree drawn as impostors (null: nothing to draw).
    osg::ref_ptr<osg::Geometry> instance(const osg::Geometry& tree) const {
        auto it = _impostors.find(tree.getVertexArray());
        if (it == _impostors.end()) return nullptr;
        osg::Array* cols[4];
        for (unsigned c = 0; c < 4; ++c)
            if (!(cols[c] = const_cast<osg::Array*>(tree.getVertexAttribArray(kInstanceAttrib0 + c)))) return nullptr;
        long pi = std::strtol(tree.getName().c_str() + std::strlen(kTreeGeometryPrefix), nullptr, 10);
        osg::ref_ptr<osg::Geometry> g = instancedTreeImpostor(
            it->second, unsigned(std::max(0L, pi)), cols,
            unsigned(std::max(0, tree.getPrimitiveSet(0)->getNumInstances())), tree.getInitialBound());
        if (g)
            g->setComputeBoundingBoxCallback(
                const_cast<osg::Drawable::ComputeBoundingBoxCallback*>(tree.getComputeBoundingBoxCallback()));
        return g;
    }

private:
    std::map<const osg::Array*, TreeImpostorArrays> _impostors;
};

// The geode of a chunk (transform -> geode), or null for another layout.
osg::Geode* chunkGeode(osg::Node* chunk) {
    auto* xf = dynamic_cast<osg::MatrixTransform*>(chunk);
    return xf && xf->getNumChildren() == 1 ? xf->getChild(0)->asGeode() : nullptr;
}

// Trees: simplified prototypes (`impostors` null) or impostors.
osg::ref_ptr<osg::Geode> simplifiedGeode(const osg::Geode& src, double ratio, const PrototypeCache& trees,
                                         const ImpostorCache* impostors) {
    osg::ref_ptr<osg::Geode> out = new osg::Geode;
    for (unsigned i = 0; i < src.getNumDrawables(); ++i) {
        const osg::Geometry* g = src.getDrawable(i)->asGeometry();
        if (!g) continue;
        osg::ref_ptr<osg::Geometry> s = !isTree(g)  ? simplifiedCopy(*g, ratio)
                                        : impostors ? impostors->instance(*g)
                                                    : trees.instance(*g);
        if (s) out->addDrawable(s.get());
    }
    return out;
}

class OsgLodMode : public GraphMode {
public:
    explicit OsgLodMode(ModeContext& ctx) : GraphMode(ctx) {
        const NearFieldScene& nf = ctx.nearField();
        _setup.push_back({"chunking", ctx.chunkingMs()});
        Stopwatch sw;
        const double ratios[2] = {kOsgLodRatio1, kOsgLodRatio2};
        PrototypeCache trees[2] = {PrototypeCache(ratios[0]), PrototypeCache(ratios[1])};
        ImpostorCache impostors;
        for (const auto& c : nf.chunks)
            if (osg::Geode* geode = chunkGeode(c.get()))
                for (unsigned i = 0; i < geode->getNumDrawables(); ++i)
                    if (const osg::Geometry* g = geode->getDrawable(i)->asGeometry(); g && isTree(g)) {
                        for (int l = 0; l < 2; ++l)
                            if (l + 1 < kOsgLodTreeImpostorLevel) trees[l].add(*g);
                        impostors.add(*g);
                    }
        std::vector<osg::ref_ptr<osg::Geode>> far[2];
        for (auto& f : far) f.resize(nf.chunks.size());
        tbb::parallel_for(size_t(0), nf.chunks.size(), [&](size_t i) {
            if (osg::Geode* geode = chunkGeode(nf.chunks[i].get()))
                for (int l = 0; l < 2; ++l)
                    far[l][i] = simplifiedGeode(*geode, ratios[l], trees[l],
                                                l + 1 >= kOsgLodTreeImpostorLevel ? &impostors : nullptr);
        });
        _setup.push_back({"simplify", sw.ms()});
        _root = smallFeatureCulling();
        if (nf.rootState) _root->setStateSet(nf.rootState.get());
        const double nearD = ctx.options.fixedNearDistance();
        for (uint32_t i : nf.drawOrder) {  // full's order: level 0 draws as full does
            osg::Geode* geode = chunkGeode(nf.chunks[i].get());
            if (!geode) {
                _root->addChild(nf.chunks[i].get());
                continue;
            }
            const osg::BoundingSphere bs = geode->getBound();
            const float r = bs.radius(), d1 = float(nearD) + r, d2 = float(kOsgLodFarFactor * nearD) + r;
            osg::ref_ptr<osg::LOD> lod = new osg::LOD;
            lod->setCenterMode(osg::LOD::USER_DEFINED_CENTER);
            lod->setCenter(bs.center());
            lod->setRadius(r);
            lod->addChild(geode, 0.0f, d1);
            lod->addChild(far[0][i].get(), d1, d2);
            lod->addChild(far[1][i].get(), d2, std::numeric_limits<float>::max());
            auto* xf = static_cast<osg::MatrixTransform*>(nf.chunks[i].get());
            osg::ref_ptr<osg::MatrixTransform> t = new osg::MatrixTransform(xf->getMatrix());
            t->addChild(lod.get());
            _root->addChild(t.get());
        }
        _graph = _root;
    }
    std::string name() const override { return "osglod"; }

private:
    // A nested camera that only changes the culling: small features culled.
    static osg::ref_ptr<osg::Camera> smallFeatureCulling() {
        osg::ref_ptr<osg::Camera> c = new osg::Camera;
        c->setName("vista.osglod");
        c->setRenderOrder(osg::Camera::NESTED_RENDER);
        c->setReferenceFrame(osg::Transform::RELATIVE_RF);
        c->setViewMatrix(osg::Matrixd::identity());
        c->setProjectionMatrix(osg::Matrixd::identity());
        c->setClearMask(0);
        c->setInheritanceMask(osg::CullSettings::ALL_VARIABLES &
                              ~(osg::CullSettings::CULLING_MODE | osg::CullSettings::SMALL_FEATURE_CULLING_PIXEL_SIZE));
        c->setCullingMode(osg::CullSettings::VIEW_FRUSTUM_CULLING | osg::CullSettings::SMALL_FEATURE_CULLING);
        c->setSmallFeatureCullingPixelSize(kOsgLodSmallFeaturePixels);
        return c;
    }
    osg::ref_ptr<osg::Camera> _root;
};

}  // namespace

Result<std::unique_ptr<RenderMode>> makeOsgLodMode(ModeContext& ctx) {
    return std::unique_ptr<RenderMode>(new OsgLodMode(ctx));
}

}  // namespace vista
