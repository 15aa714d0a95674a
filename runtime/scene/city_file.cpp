// The city scene file (.osgb): building the scene graph from a City, writing
// it atomically and loading it back for the runtime. See city_file.h and
// docs/formats.md for the layout.
#include "runtime/scene/city_file.h"
#include "runtime/scene/scene_graph.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>

#include <glm/gtc/matrix_transform.hpp>
#include <string>

#include <osg/BlendFunc>
#include <osg/CullFace>
#include <osg/NodeVisitor>
#include <osg/Program>
#include <set>
#include <osg/Geode>
#include <osg/Geometry>
#include <osg/Group>
#include <osg/MatrixTransform>
#include <osg/Program>
#include <osg/Shader>
#include <osg/StateSet>
#include <osg/UserDataContainer>
#include <osg/VertexAttribDivisor>

#include "citygen/labels.h"
#include "runtime/scene/scene_file.h"
#include "runtime/scene/tree_impostor_graph.h"

namespace vista {

// The fragment's eye-plane depth is its clip w, which the rasteriser
// interpolates anyway (gl_FragCoord.w = 1 / w): cheaper per fragment than a
// depth varying. exp(-k d) as exp2(-k log2(e) d), the form the GPU computes.
const char* const kHazeGlsl = R"(#version 120
uniform float vista_haze_density;
uniform vec3 vista_haze_color;
vec4 vistaHaze(vec4 c) {
    float t = exp2(vista_haze_density * -1.4426950 / gl_FragCoord.w);
    return vec4(mix(vista_haze_color, c.rgb, t), c.a);
}
)";
const char* const kInstancedVertexHead = R"(#version 120
attribute vec4 vista_instance0;
attribute vec4 vista_instance1;
attribute vec4 vista_instance2;
attribute vec4 vista_instance3;
void main() {
    mat4 instance = mat4(vista_instance0, vista_instance1, vista_instance2, vista_instance3);
    gl_Position = gl_ModelViewProjectionMatrix * (instance * gl_Vertex);
)";

namespace {

constexpr int kFormatVersion = 1;
// Generic vertex attribute locations of the four columns of the per-instance
// matrix (texture-coordinate aliases 4..7 on drivers that alias).

// Vertex shader of instanced tree drawing (compatibility profile; works with
// GLSL 1.20 since the per-instance data are plain attributes with divisor 1).
// No gl_BackColor: two-sided colour is never enabled, and an unused vertex
// output still costs the rasteriser (about 0.3 ms a whole-city frame on llvmpipe).
const std::string kInstanceVertexShader = std::string(kInstancedVertexHead) + R"(    gl_FrontColor = gl_Color;
}
)";
const char* const kInstanceFragmentShader = R"(#version 120
void main() {
    gl_FragColor = gl_Color;
}
)";

// Gives every instanced-tree program under `root` the haze uniforms.
void addHazeToTreePrograms(osg::Node* root) {
    struct Visitor : osg::NodeVisitor {
        Visitor() : osg::NodeVisitor(TRAVERSE_ALL_CHILDREN) {}
        std::set<osg::Program*> seen;
        void fix(osg::StateSet* ss) {
            if (!ss) return;
            auto* prog = dynamic_cast<osg::Program*>(ss->getAttribute(osg::StateAttribute::PROGRAM));
            if (!prog || prog->getName() != "vista.instanced_trees" || !seen.insert(prog).second) return;
            while (prog->getNumShaders() > 0) prog->removeShader(prog->getShader(0));
            prog->addShader(new osg::Shader(osg::Shader::VERTEX, kInstanceVertexShader));
            prog->addShader(
                new osg::Shader(osg::Shader::FRAGMENT,
                                std::string(kHazeGlsl) + "void main() { gl_FragColor = vistaHaze(gl_Color); }\n"));
        }
        void apply(osg::Node& n) override {
            fix(n.getStateSet());
            traverse(n);
        }
        void apply(osg::Geode& g) override {
            fix(g.getStateSet());
            for (unsigned i = 0; i < g.getNumDrawables(); ++i) fix(g.getDrawable(i)->getStateSet());
            traverse(g);
        }
    } v;
    if (root) root->accept(v);
}

osg::ref_ptr<osg::Vec3Array> toVec3Array(const std::vector<glm::vec3>& v) {
    osg::ref_ptr<osg::Vec3Array> a = new osg::Vec3Array(unsigned(v.size()));
    for (size_t i = 0; i < v.size(); ++i) (*a)[i].set(v[i].x, v[i].y, v[i].z);
    return a;
}
osg::ref_ptr<osg::Vec4ubArray> toColorArray(const std::vector<glm::u8vec4>& v) {
    osg::ref_ptr<osg::Vec4ubArray> a = new osg::Vec4ubArray(unsigned(v.size()));
    for (size_t i = 0; i < v.size(); ++i) (*a)[i].set(v[i].x, v[i].y, v[i].z, v[i].w);
    a->setNormalize(true);
    return a;
}
osg::ref_ptr<osg::Vec3Array> normalsFor(const Mesh& m) {
    if (m.normals.size() == m.positions.size()) return toVec3Array(m.normals);
    // Missing normals (should not happen): up vectors keep the arrays consistent.
    osg::ref_ptr<osg::Vec3Array> a = new osg::Vec3Array(unsigned(m.positions.size()));
    std::fill(a->begin(), a->end(), osg::Vec3(0, 0, 1));
    return a;
}

// Per-vertex label ids as an integer vertex attribute (empty ids: all 0).
osg::ref_ptr<osg::UIntArray> labelArray(const Mesh& m) {
    osg::ref_ptr<osg::UIntArray> a = new osg::UIntArray(unsigned(m.positions.size()));
    if (m.ids.size() == m.positions.size()) std::copy(m.ids.begin(), m.ids.end(), a->begin());
    a->setPreserveDataType(true);
    a->setBinding(osg::Array::BIND_PER_VERTEX);
    return a;
}

osg::BoundingBox boundsOf(const std::vector<glm::vec3>& p) {
    osg::BoundingBox b;
    for (const auto& v : p) b.expandBy(v.x, v.y, v.z);
    return b;
}

void checkMesh(const Mesh& m) {
    VISTA_CHECK(m.indices.size() % 3 == 0);
    VISTA_CHECK(m.colors.size() == m.positions.size());
    for (uint32_t i : m.indices) VISTA_CHECK(i < m.positions.size());
}

osg::ref_ptr<osg::Geometry> makeGeometry(const std::string& name, osg::Vec3Array* verts, osg::Vec3Array* normals,
                                         osg::Vec4ubArray* colors, const std::vector<uint32_t>& indices) {
    osg::ref_ptr<osg::Geometry> g = new osg::Geometry;
    g->setName(name);
    g->setUseDisplayList(false);
    g->setUseVertexBufferObjects(true);
    g->setVertexArray(verts);
    g->setNormalArray(normals, osg::Array::BIND_PER_VERTEX);
    g->setColorArray(colors, osg::Array::BIND_PER_VERTEX);
    osg::ref_ptr<osg::DrawElementsUInt> de = new osg::DrawElementsUInt(GL_TRIANGLES, indices.begin(), indices.end());
    g->addPrimitiveSet(de.get());
    return g;
}

struct ProtoArrays {
    osg::ref_ptr<osg::Vec3Array> verts, normals;
    osg::ref_ptr<osg::Vec4ubArray> colors;
    osg::ref_ptr<osg::UIntArray> labels;
    osg::BoundingBox bounds;
};

// Float matrix placing a tree (prototype frame) in its tile's frame.
glm::mat4 instanceMatrix(const TreeInstance& t, const glm::dvec3& tileOrigin) {
    glm::dvec3 local = t.position - tileOrigin;
    glm::dmat4 m = glm::translate(glm::dmat4(1.0), local);
    m = glm::rotate(m, double(t.yaw), glm::dvec3(0, 0, 1));
    m = glm::scale(m, glm::dvec3(double(t.scale)));
    return glm::mat4(m);
}

// The instance matrices of the trees `list` (tile-local) as four column arrays, and the
// tile-local box of the prototype box `pb` under every matrix.
void instanceColumns(const City& city, const std::vector<uint32_t>& list, const glm::dvec3& tileOrigin,
                     const osg::BoundingBox& pb, osg::ref_ptr<osg::Vec4Array> (&cols)[4], osg::BoundingBox& bb) {
    for (auto& c : cols) c = new osg::Vec4Array(unsigned(list.size()));
    for (size_t k = 0; k < list.size(); ++k) {
        const glm::mat4 m = instanceMatrix(city.trees[list[k]], tileOrigin);
        for (int c = 0; c < 4; ++c) (*cols[c])[unsigned(k)].set(m[c][0], m[c][1], m[c][2], m[c][3]);
        for (int corner = 0; corner < 8; ++corner) {
            const osg::Vec3 v = pb.corner(unsigned(corner));
            const glm::vec4 w = m * glm::vec4(v.x(), v.y(), v.z(), 1.0f);
            bb.expandBy(w.x, w.y, w.z);
        }
    }
}

osg::ref_ptr<osg::StateSet> instancedStateSet() {
    osg::ref_ptr<osg::StateSet> ss = new osg::StateSet;
    osg::ref_ptr<osg::Program> prog = new osg::Program;
    prog->setName("vista.instanced_trees");
    prog->addShader(new osg::Shader(osg::Shader::VERTEX, kInstanceVertexShader));
    prog->addShader(new osg::Shader(osg::Shader::FRAGMENT, kInstanceFragmentShader));
    for (unsigned c = 0; c < 4; ++c)
        prog->addBindAttribLocation("vista_instance" + std::to_string(c), kInstanceAttrib0 + c);
    ss->setAttributeAndModes(prog.get(), osg::StateAttribute::ON);
    for (unsigned c = 0; c < 4; ++c) ss->setAttribute(new osg::VertexAttribDivisor(kInstanceAttrib0 + c, 1));
    ss->setAttribute(new osg::VertexAttribDivisor(kTreeIdAttrib, 1));
    return ss;
}

std::string tileName(const Tile& t) { return "tile_" + std::to_string(t.ix) + "_" + std::to_string(t.iy); }

bool tileEmpty(const Tile& t) {
    if (!t.trees.empty()) return false;
    for (const Mesh& m : t.meshes)
        if (!m.empty()) return false;
    return true;
}

template <class T>
bool getUser(const osg::Object& o, const std::string& key, T& out) {
    return o.getUserValue(key, out);
}

}  // namespace

osg::ref_ptr<osg::Node> buildCityScene(const City& city) {
    const CityParams& p = city.params;
    osg::ref_ptr<osg::Group> root = new osg::Group;
    root->setName("vista.city");
    root->setUserValue("vista.format", kFormatVersion);
    root->setUserValue("vista.params", paramsToJson(p));
    root->setUserValue("vista.streets", streetGraphToJson(city.streets));
    root->setUserValue("vista.origin_x", p.origin_x);
    root->setUserValue("vista.origin_y", p.origin_y);
    root->setUserValue("vista.tile_size_m", p.tile_size_m);
    root->setUserValue("vista.tree_prototypes", int(city.treePrototypes.size()));
    root->setUserValue("vista.labels", 1);
    if (city.treeImpostors) root->setUserValue("vista.tree_impostors", 1);
    osg::StateSet* rs = root->getOrCreateStateSet();
    rs->setMode(GL_LIGHTING, osg::StateAttribute::OFF);
    rs->setAttributeAndModes(new osg::CullFace(osg::CullFace::BACK), osg::StateAttribute::ON);

    // Tree prototypes: arrays shared by every tile that uses them (osgb stores them once).
    std::vector<ProtoArrays> protos(city.treePrototypes.size());
    std::vector<TreeImpostorArrays> impostors(city.treeImpostors ? city.treePrototypes.size() : 0);
    for (size_t i = 0; i < city.treePrototypes.size(); ++i) {
        const Mesh& m = city.treePrototypes[i].mesh;
        checkMesh(m);
        if (city.treeImpostors)
            impostors[i] =
                makeTreeImpostorArrays(makeTreeImpostor(m.positions, m.colors, m.indices, kCoarseImpostorCellPixels));
        protos[i].verts = toVec3Array(m.positions);
        protos[i].normals = normalsFor(m);
        protos[i].colors = toColorArray(m.colors);
        protos[i].labels = labelArray(m);
        protos[i].bounds = boundsOf(m.positions);
    }
    osg::ref_ptr<osg::StateSet> instSS;  // shared by all instanced geometries

    for (const Tile& tile : city.tiles) {
        if (tileEmpty(tile)) continue;
        osg::ref_ptr<osg::MatrixTransform> xf = new osg::MatrixTransform;
        xf->setName(tileName(tile));
        // DYNAMIC keeps osgUtil::Optimizer (run by osgviewer) from flattening
        // the tile transform into the float vertices.
        xf->setDataVariance(osg::Object::DYNAMIC);
        xf->setMatrix(osg::Matrixd::translate(p.origin_x + tile.origin.x, p.origin_y + tile.origin.y, tile.origin.z));
        osg::ref_ptr<osg::Geode> geode = new osg::Geode;
        geode->setName(tileName(tile));
        for (int mi = 0; mi < kMaterialCount; ++mi) {
            const Mesh& m = tile.meshes[size_t(mi)];
            if (m.empty()) continue;
            checkMesh(m);
            auto g = makeGeometry(materialName(Material(mi)), toVec3Array(m.positions).get(), normalsFor(m).get(),
                                  toColorArray(m.colors).get(), m.indices);
            g->setVertexAttribArray(kLabelAttrib, labelArray(m).get(), osg::Array::BIND_PER_VERTEX);
            g->setInitialBound(boundsOf(m.positions));
            geode->addDrawable(g.get());
        }
        // Trees: one instanced draw per prototype used in this tile.
        std::map<uint32_t, std::vector<uint32_t>> byProto;
        for (uint32_t ti : tile.trees) {
            VISTA_CHECK(ti < city.trees.size());
            VISTA_CHECK(city.trees[ti].prototype < city.treePrototypes.size());
            byProto[city.trees[ti].prototype].push_back(ti);
        }
        for (const auto& [pi, list] : byProto) {
            const Mesh& pm = city.treePrototypes[pi].mesh;
            if (pm.empty()) continue;
            if (city.treeImpostors) {
                if (impostors[pi].empty()) continue;
                osg::ref_ptr<osg::Vec4Array> cols[4];
                osg::BoundingBox bb;
                instanceColumns(city, list, tile.origin, impostors[pi].bounds, cols, bb);
                osg::Array* const arrays[4] = {cols[0].get(), cols[1].get(), cols[2].get(), cols[3].get()};
                if (auto g = instancedTreeImpostor(impostors[pi], pi, arrays, unsigned(list.size()), bb))
                    geode->addDrawable(g.get());
                continue;
            }
            if (!instSS) instSS = instancedStateSet();
            auto g = makeGeometry(kTreeGeometryPrefix + std::to_string(pi), protos[pi].verts.get(),
                                  protos[pi].normals.get(), protos[pi].colors.get(), pm.indices);
            g->getPrimitiveSet(0)->setNumInstances(int(list.size()));
            osg::ref_ptr<osg::Vec4Array> cols[4];
            osg::ref_ptr<osg::UIntArray> treeIds = new osg::UIntArray(unsigned(list.size()));
            treeIds->setPreserveDataType(true);
            for (size_t k = 0; k < list.size(); ++k)
                (*treeIds)[unsigned(k)] = makeInstanceId(InstanceKind::Tree, list[k]);
            osg::BoundingBox bb;
            instanceColumns(city, list, tile.origin, protos[pi].bounds, cols, bb);
            for (unsigned c = 0; c < 4; ++c)
                g->setVertexAttribArray(kInstanceAttrib0 + c, cols[c].get(), osg::Array::BIND_PER_VERTEX);
            g->setVertexAttribArray(kLabelAttrib, protos[pi].labels.get(), osg::Array::BIND_PER_VERTEX);
            g->setVertexAttribArray(kTreeIdAttrib, treeIds.get(), osg::Array::BIND_PER_VERTEX);
            g->setInitialBound(bb);
            g->setStateSet(instSS.get());
            geode->addDrawable(g.get());
        }
        if (geode->getNumDrawables() == 0) continue;
        xf->addChild(geode.get());
        root->addChild(xf.get());
    }
    return root;
}

Status writeCityFile(const City& city, const std::string& path) {
    osg::ref_ptr<osg::Node> scene = buildCityScene(city);
    return writeSceneFile(*scene, path, false);
}

Result<SceneModel> loadCityFile(const std::string& path) {
    auto rn = readSceneFile(path);
    if (!rn) return rn.status();
    return decodeCityScene(rn->get(), path);
}

osg::Node* sceneRoot(const SceneModel& model) { return model.graph ? model.graph->root.get() : nullptr; }

void setSceneRoot(SceneModel& model, osg::Node* root) {
    model.graph = std::make_shared<SceneGraph>();
    model.graph->root = root;
}

void expandBounds(const SceneMesh& m, glm::dvec2& lo, glm::dvec2& hi) {
    for (const auto& p : m.positions) {
        const glm::dvec2 w = glm::dvec2(m.origin) + glm::dvec2(p);
        lo = glm::min(lo, w);
        hi = glm::max(hi, w);
    }
}

void expandBounds(const SceneModel& city, const SceneInstance& in, glm::dvec2& lo, glm::dvec2& hi) {
    if (in.prototype >= city.prototypes.size()) return;
    for (const auto& p : city.prototypes[in.prototype].positions) {
        const glm::dvec2 w(in.transform * glm::dvec4(glm::dvec3(p), 1.0));
        lo = glm::min(lo, w);
        hi = glm::max(hi, w);
    }
}

namespace {

Status notCityFile(const std::string& path, const std::string& why) {
    return Status::error("'" + path + "' is not a vista city file: " + why);
}

// Reads the city's parameters, street graph, label flag and tree prototype
// count from the root's user values.
Status decodeCityValues(const osg::Group& root, const std::string& path, SceneModel& out, int& protoCount) {
    std::string paramsJson, streetsJson;
    if (!getUser(root, "vista.params", paramsJson)) return notCityFile(path, "missing user value vista.params");
    auto params = parseParamsJson(paramsJson, path + " (vista.params)");
    if (!params) return params.status();
    out.params = *params;
    if (getUser(root, "vista.streets", streetsJson) && !streetsJson.empty() && streetsJson != "{}") {
        auto g = streetGraphFromJson(streetsJson);
        if (!g) return Status::error("city file '" + path + "': vista.streets: " + g.status().message());
        out.streets = std::move(*g);
    }
    int labels = 0;
    out.labelled = getUser(root, "vista.labels", labels) && labels == 1;
    getUser(root, "vista.tree_prototypes", protoCount);
    if (protoCount < 0 || protoCount > 1000000)
        return notCityFile(path, "vista.tree_prototypes = " + std::to_string(protoCount) + " out of range");
    return Status::ok();
}

// Copies one geometry's triangles (positions, colours, indices) into mesh,
// checking that its arrays agree.
Status decodeMesh(osg::Geometry& g, const osg::MatrixTransform& xf, const std::string& path, SceneMesh& mesh) {
    auto* verts = dynamic_cast<osg::Vec3Array*>(g.getVertexArray());
    auto* colors = dynamic_cast<osg::Vec4ubArray*>(g.getColorArray());
    auto* de = dynamic_cast<osg::DrawElements*>(g.getPrimitiveSet(0));
    if (!verts || !de || de->getMode() != GL_TRIANGLES)
        return notCityFile(path, "geometry '" + g.getName() + "' in " + xf.getName() + " is malformed");
    if (colors && colors->size() != verts->size())
        return notCityFile(path, "geometry '" + g.getName() + "': colour count != vertex count");
    mesh.positions.resize(verts->size());
    for (size_t i = 0; i < verts->size(); ++i)
        mesh.positions[i] = glm::vec3((*verts)[i].x(), (*verts)[i].y(), (*verts)[i].z());
    mesh.colors.assign(verts->size(), glm::u8vec4(255));
    if (colors)
        for (size_t i = 0; i < colors->size(); ++i)
            mesh.colors[i] = glm::u8vec4((*colors)[i].r(), (*colors)[i].g(), (*colors)[i].b(), (*colors)[i].a());
    mesh.indices.resize(de->getNumIndices());
    for (unsigned i = 0; i < de->getNumIndices(); ++i) {
        mesh.indices[i] = de->getElement(i);
        if (mesh.indices[i] >= verts->size())
            return notCityFile(path, "geometry '" + g.getName() + "': index out of range");
    }
    if (mesh.indices.size() % 3 != 0)
        return notCityFile(path, "geometry '" + g.getName() + "': index count not a multiple of 3");
    return Status::ok();
}

// Reads the instance matrices of an instanced geometry (`what`: "tree
// geometry" or "tree impostor geometry"): one column per vec4 attribute array.
Status decodeInstanceMatrices(osg::Geometry& g, const std::string& what, const std::string& path,
                              std::vector<glm::dmat4>& matrices) {
    const std::string& name = g.getName();
    osg::Vec4Array* cols[4];
    for (unsigned c = 0; c < 4; ++c) {
        cols[c] = dynamic_cast<osg::Vec4Array*>(g.getVertexAttribArray(kInstanceAttrib0 + c));
        if (!cols[c]) return notCityFile(path, what + " '" + name + "' has no instance matrices");
    }
    const size_t n = size_t(std::max(0, g.getPrimitiveSet(0)->getNumInstances()));
    for (auto* c : cols)
        if (c->size() != n) return notCityFile(path, what + " '" + name + "': instance count mismatch");
    matrices.resize(n);
    for (size_t k = 0; k < n; ++k) {
        glm::dmat4 m(1.0);
        for (int c = 0; c < 4; ++c) {
            const osg::Vec4& v = (*cols[c])[unsigned(k)];
            m[c] = glm::dvec4(v.x(), v.y(), v.z(), v.w());
        }
        matrices[k] = m;
    }
    return Status::ok();
}

// Decodes the tiles of a city file's root into out: meshes, tree instances
// and prototypes, tree impostors, and each tile's triangles and mesh bounds.
class TileDecoder {
public:
    TileDecoder(const std::string& path, int protoCount, SceneModel& out)
        : _path(path), _protoCount(protoCount), _out(out), _protoSeen(size_t(protoCount), false) {}

    // Decodes the tile xf (child ci of the root).
    Status decodeTile(osg::MatrixTransform& xf, unsigned ci) {
        const osg::Vec3d t = xf.getMatrix().getTrans();
        const glm::dvec3 tileOrigin(t.x(), t.y(), t.z());
        SceneTile tile;
        tile.child = ci;
        tile.origin = tileOrigin;
        for (osg::Geometry* g : tileGeometries(xf))
            if (Status s = decodeGeometry(*g, xf, tile); !s) return s;
        for (uint32_t mi : tile.meshes) expandBounds(_out.meshes[mi], tile.lo, tile.hi);
        _out.tiles.push_back(std::move(tile));
        return Status::ok();
    }

private:
    // Decodes one geometry of a tile: a tree impostor, a tree prototype with
    // its instances, or a mesh of the tile.
    Status decodeGeometry(osg::Geometry& g, osg::MatrixTransform& xf, SceneTile& tile) {
        SceneMesh mesh;
        if (Status s = decodeMesh(g, xf, _path, mesh); !s) return s;
        const glm::dmat4 tileM = glm::translate(glm::dmat4(1.0), tile.origin);
        const std::string& name = g.getName();
        if (long pi = -1; isTreeImpostorName(name, &pi)) {  // coarse levels: drawn by the graph only
            if (pi < 0 || pi >= _protoCount)
                return notCityFile(_path, "tree impostor geometry '" + name + "' names an unknown prototype");
            std::vector<glm::dmat4> matrices;
            if (Status s = decodeInstanceMatrices(g, "tree impostor geometry", _path, matrices); !s) return s;
            for (const glm::dmat4& m : matrices) _out.impostors.push_back({uint32_t(pi), tileM * m, 0u});
            const size_t n = matrices.size();
            _out.triangles += n * (mesh.indices.size() / 3);
            tile.triangles += n * (mesh.indices.size() / 3);
            return Status::ok();
        }
        mesh.material = materialFromName(name.c_str());
        if (_out.labelled) {
            auto* ids = dynamic_cast<osg::UIntArray*>(g.getVertexAttribArray(kLabelAttrib));
            if (!ids || ids->size() != mesh.positions.size())
                return notCityFile(_path, "geometry '" + name + "': label count != vertex count");
            ids->setPreserveDataType(true);
            mesh.ids.assign(ids->begin(), ids->end());
        }
        if (name.rfind(kTreeGeometryPrefix, 0) == 0) return decodeTrees(g, tileM, std::move(mesh), tile);
        mesh.origin = tile.origin;
        _out.triangles += mesh.indices.size() / 3;
        tile.triangles += mesh.indices.size() / 3;
        tile.meshes.push_back(uint32_t(_out.meshes.size()));
        _out.meshes.push_back(std::move(mesh));
        return Status::ok();
    }

    // Decodes a tree geometry: its instances (with their tree ids when
    // labelled) and, the first time its prototype appears, the prototype mesh.
    Status decodeTrees(osg::Geometry& g, const glm::dmat4& tileM, SceneMesh&& mesh, SceneTile& tile) {
        const std::string& name = g.getName();
        long pi = std::strtol(name.c_str() + std::strlen(kTreeGeometryPrefix), nullptr, 10);
        if (pi < 0 || pi >= _protoCount)
            return notCityFile(_path, "tree geometry '" + name + "' names an unknown prototype");
        std::vector<glm::dmat4> matrices;
        if (Status s = decodeInstanceMatrices(g, "tree geometry", _path, matrices); !s) return s;
        const size_t n = matrices.size();
        osg::UIntArray* treeIds = nullptr;
        if (_out.labelled) {
            treeIds = dynamic_cast<osg::UIntArray*>(g.getVertexAttribArray(kTreeIdAttrib));
            if (!treeIds || treeIds->size() != n)
                return notCityFile(_path, "tree geometry '" + name + "': tree id count != instance count");
            treeIds->setPreserveDataType(true);
        }
        for (size_t k = 0; k < n; ++k) {
            tile.instances.push_back(uint32_t(_out.instances.size()));
            _out.instances.push_back({uint32_t(pi), tileM * matrices[k], treeIds ? (*treeIds)[unsigned(k)] : 0u});
        }
        _out.triangles += n * (mesh.indices.size() / 3);
        tile.triangles += n * (mesh.indices.size() / 3);
        if (!_protoSeen[size_t(pi)]) {
            _protoSeen[size_t(pi)] = true;
            _out.prototypes[size_t(pi)] = std::move(mesh);
        }
        return Status::ok();
    }

    const std::string& _path;
    const int _protoCount;
    SceneModel& _out;
    std::vector<bool> _protoSeen;
};

}  // namespace

Result<SceneModel> decodeCityScene(osg::Node* node, const std::string& path) {
    osg::Group* root = node ? node->asGroup() : nullptr;
    if (!root || root->getName() != "vista.city") return notCityFile(path, "root node is not the group 'vista.city'");
    int format = 0;
    if (!getUser(*root, "vista.format", format)) return notCityFile(path, "missing user value vista.format");
    if (format != kFormatVersion)
        return Status::error("city file '" + path + "': vista.format = " + std::to_string(format) +
                             " is not supported (expected " + std::to_string(kFormatVersion) + ")");
    SceneModel out;
    addHazeToTreePrograms(node);
    setSceneRoot(out, node);
    int protoCount = 0;
    if (Status s = decodeCityValues(*root, path, out, protoCount); !s) return s;
    out.prototypes.resize(size_t(protoCount));

    TileDecoder tiles(path, protoCount, out);
    for (unsigned ci = 0; ci < root->getNumChildren(); ++ci) {
        osg::MatrixTransform* xf = asCityTile(root->getChild(ci));
        if (!xf) continue;
        if (Status s = tiles.decodeTile(*xf, ci); !s) return s;
    }
    // Instance bounds need the prototypes, which a later tile may define first.
    for (SceneTile& t : out.tiles)
        for (uint32_t ii : t.instances) expandBounds(out, out.instances[ii], t.lo, t.hi);
    return out;
}

osg::MatrixTransform* asCityTile(osg::Node* node) {
    auto* xf = dynamic_cast<osg::MatrixTransform*>(node);
    return xf && xf->getName().rfind("tile_", 0) == 0 ? xf : nullptr;
}

std::vector<osg::Geometry*> tileGeometries(osg::MatrixTransform& tile) {
    std::vector<osg::Geometry*> out;
    for (unsigned gi = 0; gi < tile.getNumChildren(); ++gi) {
        osg::Geode* geode = tile.getChild(gi)->asGeode();
        if (!geode) continue;
        for (unsigned di = 0; di < geode->getNumDrawables(); ++di) {
            osg::Geometry* g = geode->getDrawable(di)->asGeometry();
            if (g && g->getNumPrimitiveSets() > 0) out.push_back(g);
        }
    }
    return out;
}

}  // namespace vista
