// The osgdb_vista plugin: stock OpenSceneGraph tools (osgconv, a separate
// process that knows nothing about vista) read a scene holding vista::ViewCellSwitch
// and vista::PointImpostor nodes only through the plugin, and write them back with
// the plugin's serializers. Without the plugin on OSG_LIBRARY_PATH the stock tool
// drops the unknown nodes (or fails), which is what makes the first check meaningful.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>

#include <osg/Geode>
#include <osg/MatrixTransform>
#include <osg/ShapeDrawable>
#include <osgDB/FileUtils>
#include <osgDB/ReadFile>
#include <osgDB/Registry>
#include <osgDB/WriteFile>

#include "nodes/point_impostor.h"
#include "nodes/textured_depth_mesh.h"
#include "nodes/view_cell_switch.h"

namespace {

namespace fs = std::filesystem;

class TempDir {
public:
    TempDir() {
        std::string tmpl = (fs::temp_directory_path() / "vista_plugin_test_XXXXXX").string();
        const char* d = ::mkdtemp(tmpl.data());
        _path = d ? std::string(d) : fs::temp_directory_path().string();
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(_path, ec);
    }
    std::string file(const std::string& name) const { return (fs::path(_path) / name).string(); }
    const std::string& path() const { return _path; }

private:
    std::string _path;
};

std::string readText(const std::string& path) {
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

bool onPath(const std::string& tool) {
    const char* path = std::getenv("PATH");
    if (!path) return false;
    std::stringstream ss(path);
    std::string dir;
    while (std::getline(ss, dir, ':'))
        if (!dir.empty() && ::access((fs::path(dir) / tool).c_str(), X_OK) == 0) return true;
    return false;
}

// Runs stock osgconv in a child process with OSG_LIBRARY_PATH = libPath (the
// optimizer off so the node types reach the writer as they are). Returns the exit code.
// Under the sanitizer build (.ci/sanitize.sh) VISTA_TEST_PRELOAD names the
// ASan runtime: stock osgconv is not sanitized but loads our sanitized plugin.
int runOsgconv(const std::string& libPath, const std::string& in, const std::string& out, const std::string& log) {
    const char* preload = std::getenv("VISTA_TEST_PRELOAD");
    const std::string pre = preload && *preload ? " LD_PRELOAD='" + std::string(preload) + "'" : std::string();
    const std::string cmd = "env OSG_LIBRARY_PATH='" + libPath + "'" + pre + " OSG_OPTIMIZER=OFF osgconv '" + in +
                            "' '" + out + "' > '" + log + "' 2>&1";
    const int rc = std::system(cmd.c_str());
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

// A baked-scene-like graph: ViewCellSwitch root, one tile, one point impostor.
osg::ref_ptr<osg::Node> makeScene(vista::PointImpostorData& data) {
    data.planeOrigin = glm::vec3(10.0f, 20.0f, 0.0f);
    data.planeU = glm::vec3(4.0f, 0.0f, 0.0f);
    data.planeV = glm::vec3(0.0f, 0.0f, 3.0f);
    data.texelsX = 4;
    data.texelsY = 2;
    data.positions = {{10.5f, 20.0f, 0.5f}, {12.0f, 20.0f, 1.0f}, {13.5f, 20.0f, 2.5f}};
    data.colors = {{200, 10, 10, 255}, {10, 200, 10, 255}, {10, 10, 200, 255}};
    data.block = {-1, 0, -1};
    data.texels.assign(size_t(data.texelsX * data.texelsY), glm::u8vec4(128, 64, 32, 255));
    osg::ref_ptr<vista::PointImpostor> imp = new vista::PointImpostor;
    imp->setData(data);

    osg::ref_ptr<osg::MatrixTransform> tile = new osg::MatrixTransform;
    tile->setName("tile_0_0");
    osg::ref_ptr<osg::Geode> geode = new osg::Geode;
    geode->addDrawable(new osg::ShapeDrawable(new osg::Box(osg::Vec3(0, 0, 0), 1.0f)));
    tile->addChild(geode.get());

    osg::ref_ptr<vista::ViewCellSwitch> root = new vista::ViewCellSwitch;
    vista::ViewCellBox cell;
    cell.center = glm::dvec3(0.0, 0.0, 2.0);
    cell.halfLength = 5.0;
    cell.halfWidth = 2.0;
    cell.halfHeight = 2.0;
    root->setCells({cell});
    root->addChild(tile.get());
    root->addChild(imp.get());
    root->setTileCount(1);
    root->setCellChildren(0, {0}, {1});
    return root;
}

// An installed copy of the plugin (OSG's default library paths) would make the
// "without the plugin" run find it anyway.
bool pluginInstalledSystemWide() {
    const std::string lib = osgDB::Registry::instance()->createLibraryNameForExtension("vista");
    return !osgDB::findLibraryFile(lib).empty();
}

TEST(Plugin, ModuleHasOsgNameAndPlace) {
    const fs::path file(VISTA_PLUGIN_FILE);
    EXPECT_TRUE(fs::exists(file)) << file;
    // What osgDB asks for after "serializers_vista": <osgPlugins-ver>/osgdb_vista.so.
    const fs::path wanted = osgDB::Registry::instance()->createLibraryNameForExtension("vista");
    EXPECT_EQ(file.filename(), wanted.filename());
    EXPECT_EQ(file.parent_path().filename(), wanted.parent_path().filename());
    EXPECT_EQ(file.parent_path().parent_path(), fs::path(VISTA_OSG_LIBRARY_PATH));
}

TEST(Plugin, StockOsgconvRoundTripsVistaNodes) {
    if (!onPath("osgconv")) GTEST_SKIP() << "stock osgconv not on PATH";
    TempDir dir;
    vista::PointImpostorData data;
    osg::ref_ptr<osg::Node> scene = makeScene(data);
    const std::string in = dir.file("scene.osgb");
    ASSERT_TRUE(osgDB::writeNodeFile(*scene, in)) << in;

    // With the plugin: exit 0, both classes written back by the plugin's serializers.
    const std::string out = dir.file("with.osgt"), log = dir.file("with.log");
    ASSERT_EQ(runOsgconv(VISTA_OSG_LIBRARY_PATH, in, out, log), 0) << readText(log);
    const std::string text = readText(out);
    EXPECT_NE(text.find("vista::PointImpostor"), std::string::npos) << readText(log);
    EXPECT_NE(text.find("vista::ViewCellSwitch"), std::string::npos) << readText(log);
    EXPECT_NE(text.find("TexelsX"), std::string::npos);
    EXPECT_EQ(readText(log).find("Unsupported wrapper class"), std::string::npos) << readText(log);

    // The text file written by the stock tool reads back (in this process) to the
    // same node types and properties.
    osg::ref_ptr<osg::Node> back = osgDB::readNodeFile(out);
    ASSERT_TRUE(back.valid());
    auto* root = dynamic_cast<vista::ViewCellSwitch*>(back.get());
    ASSERT_NE(root, nullptr) << back->className();
    EXPECT_EQ(root->getTileCount(), 1u);
    EXPECT_TRUE(root->validate().empty()) << root->validate();
    ASSERT_EQ(root->getNumChildren(), 2u);
    auto* imp = dynamic_cast<vista::PointImpostor*>(root->getChild(1));
    ASSERT_NE(imp, nullptr) << root->getChild(1)->className();
    EXPECT_EQ(imp->pointCount(), data.positions.size());
    EXPECT_EQ(imp->getTexelsX(), data.texelsX);
    EXPECT_EQ(imp->getTexelsY(), data.texelsY);
    EXPECT_EQ(imp->getTexturedCount(), 1u);
    EXPECT_EQ(imp->getPlaneU(), osg::Vec3f(data.planeU.x, data.planeU.y, data.planeU.z));

    // Without the plugin (library path = an empty directory) the stock tool cannot
    // keep the vista nodes.
    if (pluginInstalledSystemWide()) GTEST_SKIP() << "osgdb_vista is installed system-wide; negative check skipped";
    const std::string empty = dir.file("no_plugins");
    fs::create_directories(empty);
    const std::string out2 = dir.file("without.osgt"), log2 = dir.file("without.log");
    const int rc2 = runOsgconv(empty, in, out2, log2);
    const std::string text2 = readText(out2);
    EXPECT_TRUE(rc2 != 0 || text2.find("vista::PointImpostor") == std::string::npos)
        << "osgconv kept vista::PointImpostor without the plugin (rc " << rc2 << ")";
}

// A textured depth mesh (vista bake --representation mesh) through stock
// osgconv and back: class, properties, arrays and the inline texture survive,
// and the read-back mesh validates.
TEST(Plugin, StockOsgconvRoundTripsTexturedDepthMesh) {
    if (!onPath("osgconv")) GTEST_SKIP() << "stock osgconv not on PATH";
    TempDir dir;
    vista::TexturedDepthMeshData d;
    d.eye = glm::vec3(-50.0f, 0.0f, 1.6f);
    d.width = 4;
    d.height = 2;
    for (int k = 0; k < 8; ++k) d.image.push_back(glm::u8vec4(uint8_t(30 * k), 100, 200, k == 7 ? 0 : 255));
    d.positions = {{100, 10, 0}, {100, -10, 0}, {100, -10, 20}, {100, 10, 20}};
    for (int k = 0; k < 4; ++k) d.texcoords.push_back(glm::vec4(0.25f * 150, 0.5f * 150, 0, 150));
    d.indices = {0, 1, 2, 0, 2, 3};
    osg::ref_ptr<vista::TexturedDepthMesh> mesh = new vista::TexturedDepthMesh;
    mesh->setData(d);
    mesh->setCellId(7);
    mesh->setEnd(1);
    ASSERT_EQ(mesh->validate(), "");
    osg::ref_ptr<osg::Geode> geode = new osg::Geode;
    geode->addDrawable(mesh.get());
    const std::string in = dir.file("mesh.osgb");
    ASSERT_TRUE(osgDB::writeNodeFile(*geode, in)) << in;
    const std::string out = dir.file("mesh.osgt"), log = dir.file("mesh.log");
    ASSERT_EQ(runOsgconv(VISTA_OSG_LIBRARY_PATH, in, out, log), 0) << readText(log);
    const std::string text = readText(out);
    EXPECT_NE(text.find("vista::TexturedDepthMesh"), std::string::npos) << readText(log);
    EXPECT_NE(text.find("CellId 7"), std::string::npos);
    osg::ref_ptr<osg::Node> back = osgDB::readNodeFile(out);
    ASSERT_TRUE(back.valid());
    osg::Geode* g = back->asGeode();
    ASSERT_NE(g, nullptr);
    ASSERT_EQ(g->getNumDrawables(), 1u);
    auto* m = dynamic_cast<vista::TexturedDepthMesh*>(g->getDrawable(0));
    ASSERT_NE(m, nullptr) << g->getDrawable(0)->className();
    EXPECT_EQ(m->validate(), "");
    EXPECT_EQ(m->getCellId(), 7u);
    EXPECT_EQ(m->getEnd(), 1);
    EXPECT_EQ(m->getEye(), osg::Vec3f(-50.0f, 0.0f, 1.6f));
    EXPECT_EQ(m->triangleCount(), 2u);
    EXPECT_EQ(m->vertexCount(), 4u);
    // An index out of range in an untrusted file is reported.
    static_cast<osg::DrawElementsUInt*>(m->getPrimitiveSet(0))->at(2) = 99;
    EXPECT_NE(m->validate(), "");
}

}  // namespace
