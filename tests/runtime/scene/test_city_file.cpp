// City scene file (.osgb), integrity trailer, atomic writes and glTF export.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <chrono>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include <sys/stat.h>
#include <unistd.h>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>
#include <osg/Geode>
#include <osg/Geometry>
#include <osg/Group>
#include <osg/MatrixTransform>

#include "citygen/generate.h"
#include "foundation/atomic_file.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/scene_graph.h"
#include "runtime/scene/scene_file.h"

#include "tests/common/temp_dir.h"

namespace vista {
namespace {

bool fileExists(const std::string& path) {
    struct stat st;
    return ::stat(path.c_str(), &st) == 0;
}

using test::readBytes;

class TempDir : public test::TempDir {
public:
    TempDir() : test::TempDir("vista_city_file") {}
};

// A box mesh (8 corners, 12 triangles) with a colour derived from `tag`.
Mesh boxMesh(glm::vec3 lo, glm::vec3 hi, uint8_t tag) {
    Mesh m;
    for (int i = 0; i < 8; ++i) {
        m.positions.push_back({(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z});
        m.normals.push_back(glm::normalize(glm::vec3((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1)));
        m.colors.push_back({uint8_t(tag + i), uint8_t(100 + tag), uint8_t(200 - i), 255});
    }
    const uint32_t f[] = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                          2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
    m.indices.assign(std::begin(f), std::end(f));
    return m;
}

// A hand-built city: 3 tiles (one empty), meshes in several materials,
// 2 tree prototypes (one unused in tile 1), 5 instances, a small street graph.
City makeCity(double originX = 0, double originY = 0) {
    City c;
    c.params.origin_x = originX;
    c.params.origin_y = originY;
    c.params.size_m = 500;
    c.params.tile_size_m = 250;
    c.params.seed = 7;
    c.streets.nodes = {{-100, 0}, {100, 0}, {0, 120}};
    c.streets.edges = {{0, 1, RoadClass::Arterial, 12.0f, 3}, {1, 2, RoadClass::Local, 7.0f, 2}};
    TreePrototype p0, p1;
    p0.species = 0;
    p0.height = 8;
    p0.mesh = boxMesh({-0.3f, -0.3f, 0}, {0.3f, 0.3f, 8}, 30);
    p1.species = 1;
    p1.height = 12;
    p1.mesh = boxMesh({-2, -2, 2}, {2, 2, 12}, 60);
    p1.mesh.append(boxMesh({-0.2f, -0.2f, 0}, {0.2f, 0.2f, 2}, 90));
    c.treePrototypes = {p0, p1};
    const double half = 125;
    for (int iy = 0; iy < 2; ++iy)
        for (int ix = 0; ix < 2; ++ix) {
            if (ix == 1 && iy == 1) continue;  // a missing tile
            Tile t;
            t.ix = ix;
            t.iy = iy;
            t.origin = {-250 + half + 250 * ix, -250 + half + 250 * iy, 1.5 * ix};
            t.meshes[size_t(Material::Ground)] = boxMesh({-125, -125, -1}, {125, 125, 0}, uint8_t(10 * ix + iy));
            if (ix == 0) t.meshes[size_t(Material::Wall)] = boxMesh({-20, -10, 0}, {20, 10, 30}, 5);
            if (iy == 0) t.meshes[size_t(Material::Roof)] = boxMesh({-20, -10, 30}, {20, 10, 31}, 7);
            c.tiles.push_back(t);
        }
    auto addTree = [&](size_t tile, glm::dvec2 local, float yaw, float scale, uint16_t proto) {
        TreeInstance ti;
        ti.position = c.tiles[tile].origin + glm::dvec3(local, 0.0);
        ti.yaw = yaw;
        ti.scale = scale;
        ti.prototype = proto;
        c.tiles[tile].trees.push_back(uint32_t(c.trees.size()));
        c.trees.push_back(ti);
    };
    addTree(0, {10, 20}, 0.3f, 1.0f, 0);
    addTree(0, {-40, 5}, 1.3f, 1.2f, 1);
    addTree(0, {60, -70}, 2.0f, 0.8f, 0);
    addTree(1, {0, 0}, 0.0f, 1.0f, 0);
    addTree(2, {-30, 30}, -0.5f, 1.1f, 1);
    return c;
}

TEST(CityFile, SceneLayout) {
    City c = makeCity(1000, 2000);
    osg::ref_ptr<osg::Node> n = buildCityScene(c);
    ASSERT_TRUE(n.valid());
    osg::Group* root = n->asGroup();
    ASSERT_NE(root, nullptr);
    EXPECT_EQ(root->getName(), "vista.city");
    int fmt = 0;
    double ox = 0, ts = 0;
    std::string pj;
    EXPECT_TRUE(root->getUserValue("vista.format", fmt));
    EXPECT_EQ(fmt, 1);
    EXPECT_TRUE(root->getUserValue("vista.origin_x", ox));
    EXPECT_EQ(ox, 1000.0);
    EXPECT_TRUE(root->getUserValue("vista.tile_size_m", ts));
    EXPECT_EQ(ts, 250.0);
    EXPECT_TRUE(root->getUserValue("vista.params", pj));
    EXPECT_EQ(pj, paramsToJson(c.params));
    ASSERT_EQ(root->getNumChildren(), 3u);
    auto* xf = dynamic_cast<osg::MatrixTransform*>(root->getChild(0));
    ASSERT_NE(xf, nullptr);
    EXPECT_EQ(xf->getName(), "tile_0_0");
    EXPECT_DOUBLE_EQ(xf->getMatrix().getTrans().x(), 1000 + c.tiles[0].origin.x);
    EXPECT_DOUBLE_EQ(xf->getMatrix().getTrans().y(), 2000 + c.tiles[0].origin.y);
    osg::Geode* g = xf->getChild(0)->asGeode();
    ASSERT_NE(g, nullptr);
    // ground, wall, roof + 2 prototypes.
    ASSERT_EQ(g->getNumDrawables(), 5u);
    EXPECT_EQ(g->getDrawable(0)->getName(), "ground");
    EXPECT_EQ(g->getDrawable(1)->getName(), "wall");
    EXPECT_EQ(g->getDrawable(2)->getName(), "roof");
    // Instanced geometries share the prototype arrays across tiles.
    osg::Geometry* t0 = g->getDrawable(3)->asGeometry();
    osg::Geometry* t1 = root->getChild(1)->asGroup()->getChild(0)->asGeode()->getDrawable(2)->asGeometry();
    ASSERT_TRUE(t0 && t1);
    EXPECT_EQ(t0->getName(), t1->getName());
    EXPECT_EQ(t0->getVertexArray(), t1->getVertexArray());
    EXPECT_EQ(t0->getPrimitiveSet(0)->getNumInstances(), 2);
    // The initial bound covers every instance (OSG cannot compute it).
    const osg::BoundingBox& bb = t0->getBoundingBox();
    EXPECT_LE(bb.xMin(), 10 - 0.3 - 1e-3);
    EXPECT_GE(bb.xMax(), 60 + 0.2);
    EXPECT_LE(bb.yMin(), -70 - 0.2);
    // Lighting is off at the root (prelit colours).
    ASSERT_NE(root->getStateSet(), nullptr);
    EXPECT_EQ(root->getStateSet()->getMode(GL_LIGHTING) & osg::StateAttribute::ON, 0u);
}

TEST(CityFile, RoundTrip) {
    TempDir dir;
    City c = makeCity(5000, -3000);
    const std::string path = dir.file("city.osgb");
    Status s = writeCityFile(c, path);
    ASSERT_TRUE(s.isOk()) << s.message();
    auto r = loadCityFile(path);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    const SceneModel& lc = *r;
    EXPECT_EQ(paramsToJson(lc.params), paramsToJson(c.params));
    // Meshes: one per tile and non-empty material, in tile/material order.
    std::vector<std::pair<const Tile*, const Mesh*>> expected;
    for (const Tile& t : c.tiles)
        for (const Mesh& m : t.meshes)
            if (!m.empty()) expected.push_back({&t, &m});
    ASSERT_EQ(lc.meshes.size(), expected.size());
    for (size_t i = 0; i < expected.size(); ++i) {
        const Mesh& m = *expected[i].second;
        const SceneMesh& l = lc.meshes[i];
        EXPECT_EQ(l.origin, glm::dvec3(5000 + expected[i].first->origin.x, -3000 + expected[i].first->origin.y,
                                       expected[i].first->origin.z));
        EXPECT_EQ(l.positions, m.positions);
        EXPECT_EQ(l.colors, m.colors);
        EXPECT_EQ(l.indices, m.indices);
    }
    ASSERT_EQ(lc.prototypes.size(), c.treePrototypes.size());
    for (size_t i = 0; i < lc.prototypes.size(); ++i) {
        EXPECT_EQ(lc.prototypes[i].positions, c.treePrototypes[i].mesh.positions);
        EXPECT_EQ(lc.prototypes[i].indices, c.treePrototypes[i].mesh.indices);
        EXPECT_EQ(lc.prototypes[i].colors, c.treePrototypes[i].mesh.colors);
    }
    // Instances: world transform of the prototype origin = world tree base.
    ASSERT_EQ(lc.instances.size(), c.trees.size());
    std::vector<bool> matched(c.trees.size(), false);
    for (const SceneInstance& li : lc.instances) {
        glm::dvec3 base = glm::dvec3(li.transform * glm::dvec4(0, 0, 0, 1));
        glm::dvec3 top = glm::dvec3(li.transform * glm::dvec4(0, 0, 1, 1)) - base;
        bool found = false;
        for (size_t k = 0; k < c.trees.size(); ++k) {
            const TreeInstance& t = c.trees[k];
            glm::dvec3 w = t.position + glm::dvec3(5000, -3000, 0);
            if (!matched[k] && t.prototype == li.prototype && glm::length(base - w) < 1e-3 &&
                std::abs(glm::length(top) - t.scale) < 1e-5) {
                // Yaw: the prototype x axis turns by t.yaw.
                glm::dvec3 xa = glm::dvec3(li.transform * glm::dvec4(1, 0, 0, 0)) / double(t.scale);
                EXPECT_NEAR(xa.x, std::cos(t.yaw), 1e-5);
                EXPECT_NEAR(xa.y, std::sin(t.yaw), 1e-5);
                matched[k] = found = true;
                break;
            }
        }
        EXPECT_TRUE(found) << "instance at " << base.x << "," << base.y;
    }
    CityCounts counts = countCity(c);
    size_t tris = 0;
    for (const auto& [t, m] : expected) tris += m->triangleCount();
    for (const TreeInstance& t : c.trees) tris += c.treePrototypes[t.prototype].mesh.triangleCount();
    EXPECT_EQ(lc.triangles, tris);
    if (counts.triangles != 0) { EXPECT_EQ(lc.triangles, counts.triangles); }
    // Street graph: compared only once the serialiser is implemented.
    if (streetGraphToJson(c.streets) != "{}") {
        EXPECT_EQ(lc.streets.nodes.size(), c.streets.nodes.size());
        EXPECT_EQ(lc.streets.edges.size(), c.streets.edges.size());
    }
    ASSERT_NE(sceneRoot(lc), nullptr);
}

TEST(CityFile, DeterministicBytes) {
    TempDir dir;
    City c = makeCity(123456.5, 7.25);
    ASSERT_TRUE(writeCityFile(c, dir.file("a.osgb")).isOk());
    City c2 = makeCity(123456.5, 7.25);  // rebuilt: different allocation addresses
    ASSERT_TRUE(writeCityFile(c2, dir.file("b.osgb")).isOk());
    std::string a = readBytes(dir.file("a.osgb")), b = readBytes(dir.file("b.osgb"));
    EXPECT_GT(a.size(), 1000u);
    EXPECT_TRUE(a == b) << "sizes " << a.size() << " vs " << b.size();
    // A different city gives different bytes (the comparison can fail).
    c2.trees[0].yaw += 0.1f;
    ASSERT_TRUE(writeCityFile(c2, dir.file("c.osgb")).isOk());
    EXPECT_NE(a, readBytes(dir.file("c.osgb")));
}

TEST(CityFile, FarFromOriginKeepsMillimetres) {
    TempDir dir;
    const double ox = 1.0e6 + 0.123, oy = -1.0e6 + 0.456;
    City c = makeCity(ox, oy);
    ASSERT_TRUE(writeCityFile(c, dir.file("far.osgb")).isOk());
    auto r = loadCityFile(dir.file("far.osgb"));
    ASSERT_TRUE(r.isOk()) << r.status().message();
    size_t mi = 0;
    double worst = 0;
    for (const Tile& t : c.tiles)
        for (const Mesh& m : t.meshes) {
            if (m.empty()) continue;
            ASSERT_LT(mi, r->meshes.size());
            const SceneMesh& l = r->meshes[mi++];
            for (size_t i = 0; i < m.positions.size(); ++i) {
                glm::dvec3 expect = glm::dvec3(ox, oy, 0) + t.origin + glm::dvec3(m.positions[i]);
                glm::dvec3 got = l.origin + glm::dvec3(l.positions[i]);
                worst = std::max(worst, glm::length(got - expect));
            }
        }
    EXPECT_LT(worst, 1e-3);
    for (const SceneInstance& li : r->instances) {
        glm::dvec3 base = glm::dvec3(li.transform * glm::dvec4(0, 0, 0, 1));
        double best = 1e30;
        for (const TreeInstance& t : c.trees)
            best = std::min(best, glm::length(base - (t.position + glm::dvec3(ox, oy, 0))));
        EXPECT_LT(best, 1e-3);
    }
}

TEST(CityFile, AtomicWriteFailures) {
    TempDir dir;
    City c = makeCity();
    // Parent "directory" is a regular file: error naming the path, nothing created.
    const std::string notDir = dir.file("plainfile");
    ASSERT_TRUE(writeFileAtomic(notDir, "x").isOk());
    Status s0 = writeCityFile(c, notDir + "/city.osgb");
    EXPECT_FALSE(s0.isOk());
    EXPECT_NE(s0.message().find(notDir + "/city.osgb"), std::string::npos) << s0.message();
    EXPECT_EQ(readBytes(notDir), "x");
    // Missing directory.
    Status s1 = writeFileAtomic(dir.file("nodir/x.json"), "{}");
    EXPECT_FALSE(s1.isOk());
    EXPECT_NE(s1.message().find("nodir/x.json"), std::string::npos);
    // Unwritable directory (not enforced for root): error naming the path, nothing created.
    const std::string ro = dir.file("ro");
    ASSERT_EQ(::mkdir(ro.c_str(), 0555), 0);
    if (::access(ro.c_str(), W_OK) != 0) {
        Status s = writeCityFile(c, ro + "/city.osgb");
        EXPECT_FALSE(s.isOk());
        EXPECT_NE(s.message().find(ro + "/city.osgb"), std::string::npos) << s.message();
        EXPECT_FALSE(fileExists(ro + "/city.osgb"));
    }
}

TEST(CityFile, FailedWriteLeavesExistingFileUntouched) {
    TempDir dir;
    City c = makeCity();
    const std::string path = dir.file("city.osgb");
    ASSERT_TRUE(writeFileAtomic(path, "old contents").isOk());
    EXPECT_EQ(readBytes(path), "old contents");
    // The temp file name is taken by a directory: the write fails before rename.
    const std::string tmp = path + ".tmp." + std::to_string(::getpid());
    ASSERT_EQ(::mkdir(tmp.c_str(), 0755), 0);
    EXPECT_FALSE(writeCityFile(c, path).isOk());
    EXPECT_FALSE(writeFileAtomic(path, "new").isOk());
    EXPECT_EQ(readBytes(path), "old contents");
    ::rmdir(tmp.c_str());
    ASSERT_TRUE(writeFileAtomic(path, "new").isOk());
    EXPECT_EQ(readBytes(path), "new");
    EXPECT_FALSE(fileExists(tmp));
}

TEST(CityFile, BadFilesAreErrorsNotCrashes) {
    TempDir dir;
    City c = makeCity(10, 20);
    const std::string good = dir.file("good.osgb");
    ASSERT_TRUE(writeCityFile(c, good).isOk());
    const std::string bytes = readBytes(good);
    auto expectError = [&](const std::string& path, const char* what) {
        auto r = loadCityFile(path);
        EXPECT_FALSE(r.isOk()) << what;
        if (!r.isOk()) {
            EXPECT_NE(r.status().message().find(path), std::string::npos) << what << ": " << r.status().message();
        }
    };
    expectError(dir.file("missing.osgb"), "missing");
    expectError(dir.path(), "directory");
    ASSERT_TRUE(writeFileAtomic(dir.file("empty.osgb"), "").isOk());
    expectError(dir.file("empty.osgb"), "empty");
    ASSERT_TRUE(writeFileAtomic(dir.file("text.osgb"), "#Ascii Scene\nosg::Group {}\n").isOk());
    expectError(dir.file("text.osgb"), "not osgb");
    for (double f : {0.1, 0.5, 0.99}) {
        const std::string p = dir.file("cut" + std::to_string(int(f * 100)) + ".osgb");
        ASSERT_TRUE(writeFileAtomic(p, bytes.substr(0, size_t(double(bytes.size()) * f))).isOk());
        expectError(p, "truncated");
    }
    std::mt19937 rng(12345);
    for (int trial = 0; trial < 20; ++trial) {
        std::string b = bytes;
        size_t pos = std::uniform_int_distribution<size_t>(0, b.size() - 1)(rng);
        b[pos] = char(b[pos] ^ (1 + trial % 255));
        const std::string p = dir.file("corrupt.osgb");
        ASSERT_TRUE(writeFileAtomic(p, b).isOk());
        expectError(p, "corrupt byte");
    }
    // A valid osgb that is not a vista city (written through the same writer).
    osg::ref_ptr<osg::Group> other = new osg::Group;
    other->setName("something else");
    ASSERT_TRUE(writeSceneFile(*other, dir.file("other.osgb")).isOk());
    expectError(dir.file("other.osgb"), "not vista");
    // Unreadable file.
    const std::string noread = dir.file("noread.osgb");
    ASSERT_TRUE(writeFileAtomic(noread, bytes).isOk());
    ::chmod(noread.c_str(), 0);
    if (::access(noread.c_str(), R_OK) != 0) expectError(noread, "unreadable");
}

TEST(CityFile, HashIsStableAcrossSplits) {
    std::string s(1000, 'x');
    for (size_t i = 0; i < s.size(); ++i) s[i] = char(i * 7 + 3);
    uint64_t h = hashBytes64(s.data(), s.size());
    EXPECT_NE(h, hashBytes64(s.data(), s.size() - 1));
    std::string t = s;
    t[500] ^= 1;
    EXPECT_NE(h, hashBytes64(t.data(), t.size()));
    EXPECT_EQ(h, hashBytes64(s.data(), s.size()));
}

TEST(CityFile, OsgconvOpensTheFile) {
    if (std::system("command -v osgconv > /dev/null 2>&1") != 0) GTEST_SKIP() << "osgconv not on PATH";
    TempDir dir;
    ASSERT_TRUE(writeCityFile(makeCity(1e6, 1e6), dir.file("city.osgb")).isOk());
    std::string cmd = "osgconv '" + dir.file("city.osgb") + "' '" + dir.file("city.osgt") + "' > /dev/null 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0);
    std::string text = readBytes(dir.file("city.osgt"));
    EXPECT_NE(text.find("vista.city"), std::string::npos);
    EXPECT_NE(text.find("tile_0_1"), std::string::npos);
    EXPECT_NE(text.find("vista_instance0"), std::string::npos);
}

TEST(CityFile, GeneratedCityRoundTrip) {
    CityParams p;
    p.size_m = 400;
    p.seed = 11;
    p.origin_x = 250000.5;
    p.origin_y = -4000000.25;
    auto city = generateCity(p);
    ASSERT_TRUE(city.isOk()) << city.status().message();
    TempDir dir;
    ASSERT_TRUE(writeCityFile(*city, dir.file("gen.osgb")).isOk());
    auto r = loadCityFile(dir.file("gen.osgb"));
    ASSERT_TRUE(r.isOk()) << r.status().message();
    CityCounts n = countCity(*city);
    EXPECT_EQ(r->triangles, n.triangles);
    EXPECT_EQ(r->instances.size(), city->trees.size());
    EXPECT_EQ(r->streets.nodes.size(), city->streets.nodes.size());
    EXPECT_EQ(r->streets.edges.size(), city->streets.edges.size());
    EXPECT_EQ(paramsToJson(r->params), paramsToJson(city->params));
    size_t stored = 0;
    for (const SceneMesh& m : r->meshes) stored += m.indices.size() / 3;
    for (const SceneMesh& m : r->prototypes) stored += m.indices.size() / 3;
    // Prototypes that no tile uses are not in the file.
    size_t unused = 0;
    std::vector<bool> used(city->treePrototypes.size(), false);
    for (const TreeInstance& t : city->trees) used[t.prototype] = true;
    for (size_t i = 0; i < used.size(); ++i) unused += used[i] ? 0 : city->treePrototypes[i].mesh.triangleCount();
    EXPECT_EQ(stored + unused, n.storedTriangles);
}

TEST(CityFile, ConvertedFileWithoutTrailerIsRejected) {
    if (std::system("command -v osgconv > /dev/null 2>&1") != 0) GTEST_SKIP() << "osgconv not on PATH";
    TempDir dir;
    ASSERT_TRUE(writeCityFile(makeCity(), dir.file("city.osgb")).isOk());
    std::string cmd = "osgconv '" + dir.file("city.osgb") + "' '" + dir.file("conv.osgb") + "' > /dev/null 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    auto r = loadCityFile(dir.file("conv.osgb"));
    EXPECT_FALSE(r.isOk());
}

// ---- glTF ------------------------------------------------------------------

struct Glb {
    nlohmann::json json;
    std::string bin;
};

uint32_t u32(const std::string& s, size_t off) {
    uint32_t v;
    std::memcpy(&v, s.data() + off, 4);
    return v;
}

::testing::AssertionResult parseGlb(const std::string& b, Glb& out) {
    if (b.size() < 20) return ::testing::AssertionFailure() << "too small";
    if (b.compare(0, 4, "glTF") != 0) return ::testing::AssertionFailure() << "magic";
    if (u32(b, 4) != 2) return ::testing::AssertionFailure() << "version";
    if (u32(b, 8) != b.size()) return ::testing::AssertionFailure() << "length " << u32(b, 8) << " vs " << b.size();
    uint32_t jl = u32(b, 12);
    if (u32(b, 16) != 0x4E4F534Au) return ::testing::AssertionFailure() << "JSON chunk type";
    if (jl % 4 != 0 || 20 + size_t(jl) > b.size()) return ::testing::AssertionFailure() << "JSON chunk length";
    out.json = nlohmann::json::parse(b.substr(20, jl), nullptr, false);
    if (out.json.is_discarded()) return ::testing::AssertionFailure() << "JSON parse";
    size_t off = 20 + jl;
    if (off < b.size()) {
        uint32_t bl = u32(b, off);
        if (u32(b, off + 4) != 0x004E4942u) return ::testing::AssertionFailure() << "BIN chunk type";
        if (bl % 4 != 0 || off + 8 + bl != b.size()) return ::testing::AssertionFailure() << "BIN chunk length";
        out.bin = b.substr(off + 8, bl);
    }
    return ::testing::AssertionSuccess();
}

TEST(Gltf, StructureIsValid) {
    TempDir dir;
    City c = makeCity(1e6, 2e6);
    const std::string path = dir.file("city.glb");
    Status s = writeGltf(c, path);
    ASSERT_TRUE(s.isOk()) << s.message();
    std::string bytes = readBytes(path);
    Glb g;
    ASSERT_TRUE(parseGlb(bytes, g));
    const auto& j = g.json;
    EXPECT_EQ(j["asset"]["version"], "2.0");
    EXPECT_DOUBLE_EQ(j["asset"]["extras"]["vista"]["origin_x"].get<double>(), 1e6);
    ASSERT_EQ(j["buffers"].size(), 1u);
    EXPECT_EQ(j["buffers"][0]["byteLength"].get<size_t>(), g.bin.size());
    for (const auto& bv : j["bufferViews"]) {
        size_t o = bv.value("byteOffset", size_t(0)), l = bv["byteLength"].get<size_t>();
        EXPECT_EQ(o % 4, 0u);
        EXPECT_LE(o + l, g.bin.size());
    }
    auto compSize = [](int ct) { return ct == 5126 || ct == 5125 ? 4 : ct == 5123 ? 2 : 1; };
    auto ncomp = [](const std::string& t) {
        return t == "SCALAR" ? 1 : t == "VEC3" ? 3 : t == "VEC4" ? 4 : t == "MAT4" ? 16 : 0;
    };
    for (const auto& a : j["accessors"]) {
        const auto& bv = j["bufferViews"][a["bufferView"].get<size_t>()];
        size_t need = a.value("byteOffset", size_t(0)) +
                      a["count"].get<size_t>() * compSize(a["componentType"]) * ncomp(a["type"]);
        EXPECT_LE(need, bv["byteLength"].get<size_t>());
        EXPECT_GT(a["count"].get<size_t>(), 0u);
    }
    // Meshes: tile meshes (one per tile and material) + prototypes.
    size_t tileMeshes = 0;
    for (const Tile& t : c.tiles)
        for (const Mesh& m : t.meshes) tileMeshes += m.empty() ? 0 : 1;
    size_t prims = 0;
    for (const auto& m : j["meshes"]) prims += m["primitives"].size();
    EXPECT_EQ(prims, tileMeshes + c.treePrototypes.size());
    // Check POSITION min/max and index range of every primitive from the data.
    for (const auto& m : j["meshes"])
        for (const auto& p : m["primitives"]) {
            const auto& pa = j["accessors"][p["attributes"]["POSITION"].get<size_t>()];
            const auto& bv = j["bufferViews"][pa["bufferView"].get<size_t>()];
            size_t n = pa["count"], off = bv.value("byteOffset", size_t(0)) + pa.value("byteOffset", size_t(0));
            glm::vec3 lo(1e30f), hi(-1e30f);
            for (size_t i = 0; i < n; ++i) {
                glm::vec3 v;
                std::memcpy(&v, g.bin.data() + off + 12 * i, 12);
                lo = glm::min(lo, v);
                hi = glm::max(hi, v);
            }
            for (int k = 0; k < 3; ++k) {
                EXPECT_FLOAT_EQ(pa["min"][k].get<float>(), lo[k]);
                EXPECT_FLOAT_EQ(pa["max"][k].get<float>(), hi[k]);
            }
            EXPECT_EQ(j["accessors"][p["attributes"]["COLOR_0"].get<size_t>()]["normalized"], true);
            EXPECT_EQ(j["accessors"][p["attributes"]["NORMAL"].get<size_t>()]["count"], n);
            const auto& ia = j["accessors"][p["indices"].get<size_t>()];
            const auto& ibv = j["bufferViews"][ia["bufferView"].get<size_t>()];
            size_t ioff = ibv.value("byteOffset", size_t(0)) + ia.value("byteOffset", size_t(0));
            EXPECT_EQ(ia["count"].get<size_t>() % 3, 0u);
            for (size_t i = 0; i < ia["count"].get<size_t>(); ++i) EXPECT_LT(u32(g.bin, ioff + 4 * i), n);
        }
    // Nodes: one per tile + one per tree instance, all under the scene roots.
    size_t meshNodes = 0;
    for (const auto& n : j["nodes"]) meshNodes += n.contains("mesh") ? 1 : 0;
    EXPECT_GE(meshNodes, c.trees.size() + c.tiles.size());
    EXPECT_EQ(j["scenes"][j["scene"].get<size_t>()]["nodes"].size() > 0, true);
    // Deterministic bytes.
    ASSERT_TRUE(writeGltf(c, dir.file("again.glb")).isOk());
    EXPECT_TRUE(bytes == readBytes(dir.file("again.glb")));
}

TEST(Gltf, UnwritablePathIsAnError) {
    TempDir dir;
    Status s = writeGltf(makeCity(), dir.file("no/such/dir/city.glb"));
    EXPECT_FALSE(s.isOk());
    EXPECT_NE(s.message().find("city.glb"), std::string::npos);
}

// Trust model (docs/measurements/reliability.md): a payload with a matching trailer (as
// another tool could write) that is not a valid osgb graph is refused; with
// VISTA_UNTRUSTED_FILES=1 it is decoded in a child process first, and a good
// file still loads.
TEST(CityFile, MalformedPayloadWithAValidTrailerIsRefused) {
    TempDir dir;
    std::mt19937 rng(7);
    for (int k = 0; k < 20; ++k) {
        std::string payload(size_t(64 + k * 37), '\0');
        for (auto& c : payload) c = char(rng());
        std::memcpy(payload.data(), "\x10\x2c\x3a\x1a\x00\x00\x00\x00", 8);  // an osgb-like header start
        const std::string f = dir.file("crafted.osgb");
        std::ofstream(f, std::ios::binary) << payload << sceneFileTrailer(payload);
        ::setenv("VISTA_UNTRUSTED_FILES", k % 2 ? "1" : "0", 1);
        EXPECT_FALSE(loadCityFile(f).isOk()) << k;
    }
    ::setenv("VISTA_UNTRUSTED_FILES", "1", 1);
    CityParams p;
    p.size_m = 300;
    auto city = generateCity(p);
    ASSERT_TRUE(city.isOk());
    const std::string good = dir.file("good.osgb");
    ASSERT_TRUE(writeCityFile(*city, good));
    auto m = loadCityFile(good);
    EXPECT_TRUE(m.isOk()) << m.status().message();
    ::unsetenv("VISTA_UNTRUSTED_FILES");
}

// Found by fuzz_scene_file (its trailer forged by libFuzzer's comparison
// tracing): a 3.8 KB payload that keeps OSG's osgb reader busy for seconds.
// Untrusted mode refuses it when the child's time limit runs out.
TEST(CityFile, PayloadThatKeepsTheReaderBusyIsRefusedInUntrustedMode) {
    const std::string f = std::string(VISTA_SOURCE_DIR) + "/tests/data/fuzz_findings/scene_slow_reader.osgb";
    ::setenv("VISTA_UNTRUSTED_FILES", "1", 1);
    ::setenv("VISTA_UNTRUSTED_DECODE_SECONDS", "0.3", 1);
    const auto start = std::chrono::steady_clock::now();
    auto m = loadCityFile(f);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ::unsetenv("VISTA_UNTRUSTED_DECODE_SECONDS");
    ::unsetenv("VISTA_UNTRUSTED_FILES");
    ASSERT_FALSE(m.isOk());
    // Refused by the time limit (the reader alone takes seconds on it).
    EXPECT_NE(m.status().message().find("busy"), std::string::npos) << m.status().message();
    EXPECT_LT(s, 5.0);
}

}  // namespace
}  // namespace vista
