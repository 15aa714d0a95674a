// vista view: interactive OSG viewer of a city (a real window on a GPU, or
// under Xvfb). Drive / walk / fly manipulators, path playback, on-screen
// stats (osgViewer StatsHandler, key s), render-mode switch (key m: full,
// near, osgimpostor, hybrid = NearFarSplit + FarFieldNode; the HUD then shows
// the far field's pixel classes and stage times; impostor = the baked
// ViewCellSwitch of a file from `vista bake`, the HUD shows the current cell),
// screenshots (key p, or --screenshot with --frames for headless use).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <memory>
#include <string>

#include <osg/Camera>
#include <osg/Geode>
#include <osg/GL>
#include <osg/MatrixTransform>
#include <osgGA/AnimationPathManipulator>
#include <osgGA/DriveManipulator>
#include <osgGA/FirstPersonManipulator>
#include <osgGA/FlightManipulator>
#include <osgGA/KeySwitchMatrixManipulator>
#include <osgGA/StateSetManipulator>
#include <osgGA/TrackballManipulator>
#include <osgSim/Impostor>
#include <osgText/Text>
#include <osgViewer/Viewer>
#include <osgViewer/ViewerEventHandlers>

#include <glm/gtc/type_ptr.hpp>

#include "nodes/far_field_node.h"
#include "foundation/units.h"
#include "nodes/near_far_split.h"
#include "nodes/view_cell_switch.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/scene_graph.h"
#include "cmd/cli.h"
#include "cmd/commands.h"
#include "runtime/engine/image.h"
#include "runtime/scene/paths.h"
#include "runtime/engine/ray_scene.h"

namespace vista {

namespace {


// Reads the back buffer after the next frame and writes a PNG.
struct Capture : public osg::Camera::DrawCallback {
    mutable std::string pending;
    mutable std::string lastWritten;
    void operator()(osg::RenderInfo& ri) const override {
        if (pending.empty()) return;
        const osg::Viewport* vp = ri.getCurrentCamera()->getViewport();
        int w = int(vp->width()), h = int(vp->height());
        Image img(w, h);
        std::vector<uint8_t> buf(size_t(w) * size_t(h) * 4);
        glPixelStorei(GL_PACK_ALIGNMENT, 1);
        glReadBuffer(GL_BACK);
        glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, buf.data());
        for (int y = 0; y < h; ++y)
            std::copy_n(&buf[size_t(h - 1 - y) * size_t(w) * 4], size_t(w) * 4, &img.rgba[size_t(y) * size_t(w) * 4]);
        for (size_t i = 3; i < img.rgba.size(); i += 4) img.rgba[i] = 255;
        Status s = writePng(img, pending);
        if (s) std::fprintf(stderr, "vista view: screenshot -> %s\n", pending.c_str());
        else std::fprintf(stderr, "vista view: %s\n", s.message().c_str());
        lastWritten = s ? pending : std::string();
        pending.clear();
    }
};

struct ViewState {
    int mode = 0;  // index into kModeNames
    bool available[5] = {true, true, true, false, false};  // hybrid: ray scene built; impostor: baked file
    unsigned child[5] = {0, 0, 1, 0, 0};                   // switch child drawn by each mode
    ViewCellSwitch* baked = nullptr;                       // owned by the scene graph (impostor mode)
    double nearDistance = 100.0;
    int shots = 0;
    osg::ref_ptr<osg::Switch> modes;
    osg::ref_ptr<Capture> capture;
    osg::ref_ptr<osgText::Text> hud;
    FarFieldNode* far = nullptr;      // owned by the scene graph (hybrid mode)
    NearFarSplit* split = nullptr;
};
// full and near share the city scene (near differs only by the projection's
// far plane); a baked file's full mode draws its tiles without the switch.
const char* kModeNames[] = {"full", "near", "osgimpostor", "hybrid", "impostor"};
constexpr int kNumModes = 5;

class ViewKeys : public osgGA::GUIEventHandler {
public:
    explicit ViewKeys(ViewState& s) : _s(s) {}
    bool handle(const osgGA::GUIEventAdapter& ea, osgGA::GUIActionAdapter&) override {
        if (ea.getEventType() != osgGA::GUIEventAdapter::KEYDOWN) return false;
        if (ea.getKey() == 'm') {
            do _s.mode = (_s.mode + 1) % kNumModes;
            while (!_s.available[_s.mode]);
            _s.modes->setSingleChildOn(_s.child[_s.mode]);
            return true;
        }
        if (ea.getKey() == 'p') {
            _s.capture->pending = "vista_screenshot_" + std::to_string(_s.shots++) + ".png";
            return true;
        }
        return false;
    }
    void getUsage(osg::ApplicationUsage& u) const override {
        u.addKeyboardMouseBinding("m", "cycle render mode: full / near / osgimpostor / hybrid / impostor (baked file)");
        u.addKeyboardMouseBinding("p", "screenshot to vista_screenshot_N.png");
    }

private:
    ViewState& _s;
};

osg::ref_ptr<osg::Node> makeImpostorScene(osg::Node* scene, double nearD) {
    osg::ref_ptr<osg::Group> root = new osg::Group;
    osg::Group* g = scene ? scene->asGroup() : nullptr;
    if (!g) return scene;
    for (unsigned i = 0; i < g->getNumChildren(); ++i) {
        osg::Node* c = g->getChild(i);
        osg::ref_ptr<osgSim::Impostor> imp = new osgSim::Impostor;
        if (auto* mt = dynamic_cast<osg::MatrixTransform*>(c)) {
            osg::ref_ptr<osg::MatrixTransform> copy = new osg::MatrixTransform(mt->getMatrix());
            for (unsigned k = 0; k < mt->getNumChildren(); ++k) imp->addChild(mt->getChild(k), 0.0f, 1e30f);
            copy->addChild(imp.get());
            root->addChild(copy.get());
        } else {
            imp->addChild(c, 0.0f, 1e30f);
            root->addChild(imp.get());
        }
        imp->setImpostorThreshold(float(nearD + imp->getBound().radius()));
    }
    root->setStateSet(g->getStateSet());
    return root;
}

osg::Matrixd toOsg(const glm::dmat4& m) { return osg::Matrixd(glm::value_ptr(m)); }

}  // namespace

int runView(int argc, char** argv) {
    CLI::App app{"Interactive viewer: drive (1), walk (2), fly (3), orbit (4), path playback (5); s = stats, "
                 "m = render mode, p = screenshot, h = help.",
                 "vista view"};
    std::string city, pathFile, sizeStr = "1280x720", screenshot, kind = "car", modeStr = "full", budgetStr = "20000";
    int frames = 0;
    uint64_t seed = 0;
    double fovDeg = 60.0, nearD = 100.0;
    app.add_option("city", city, "city scene file (.osgb), or a baked file from 'vista bake' (adds the impostor mode)")->required();
    app.add_option("--path", pathFile, "play back this path CSV (key 5)");
    app.add_option("--seed", seed, "make a path from this seed and play it back");
    app.add_option("--kind", kind, "path kind for --seed: walk, car, fly");
    app.add_option("--size", sizeStr, "window size WIDTHxHEIGHT (default 1280x720)");
    app.add_option("--fov", fovDeg, "vertical field of view in degrees (default 60)");
    app.add_option("--near", nearD, "near-field distance of the `near` and `hybrid` modes in metres (default 100)");
    app.add_option("--mode", modeStr, "start in this render mode: full, near, osgimpostor, hybrid, impostor (default full)");
    app.add_option("--budget", budgetStr,
                   "hybrid: far-field rays per frame through the panoramic cache, 0 .. 1000000000, or "
                   "'unlimited' / -1 (default 20000)");
    app.add_option("--frames", frames, "quit after N frames (0 = run until Esc)");
    app.add_option("--screenshot", screenshot, "write a PNG of the last frame (use with --frames)");
    int rc = parseOrExit(app, argc, argv);
    if (rc >= 0) return rc;
    const std::string cmd = "vista view";
    int w = 0, h = 0;
    char x = 0, extra = 0;
    if (std::sscanf(sizeStr.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || x != 'x' || w < 1 || h < 1 || w > 8192 || h > 8192)
        return reportBadInput(cmd, Status::error("--size '" + sizeStr + "': expected WIDTHxHEIGHT within 1x1 .. 8192x8192"));
    if (frames < 0) return reportBadInput(cmd, Status::error("--frames " + std::to_string(frames) + " must be >= 0"));
    if (!(fovDeg > 1 && fovDeg < 179)) return reportBadInput(cmd, Status::error("--fov out of range (1, 179) degrees"));
    if (!(nearD > 0)) return reportBadInput(cmd, Status::error("--near must be > 0 metres"));
    int startMode = -1;
    for (int i = 0; i < kNumModes; ++i)
        if (modeStr == kModeNames[i]) startMode = i;
    if (startMode < 0)
        return reportBadInput(cmd, Status::error("--mode '" + modeStr + "': expected full, near, osgimpostor, hybrid or impostor"));
    int64_t budget = -1;
    if (budgetStr != "unlimited" && budgetStr != "-1") {
        char* end = nullptr;
        long long v = std::strtoll(budgetStr.c_str(), &end, 10);
        if (budgetStr.empty() || *end || v < 0 || v > 1000000000LL)
            return reportBadInput(cmd, Status::error("--budget '" + budgetStr +
                                                     "' out of range 0 .. 1000000000 rays per frame, or 'unlimited' / -1"));
        budget = v;
    }
    if (!screenshot.empty())
        if (Status s = checkWritablePath("--screenshot", screenshot); !s) return reportBadInput(cmd, s);
    auto c = loadCityFile(city);
    if (!c) return reportBadInput(cmd, c.status());
    Path path;
    bool havePath = false;
    if (!pathFile.empty()) {
        auto p = loadPathCsv(pathFile);
        if (!p) return reportBadInput(cmd, p.status());
        path = std::move(p.value());
        havePath = true;
    }
    {
        auto k = parsePathKind(kind);
        if (!k) return reportBadInput(cmd, Status::error("--kind: " + k.status().message()));
        PathOptions po;
        po.seed = seed ? seed : 1;
        po.kind = k.value();
        if (!havePath && !c->streets.edges.empty()) {
            auto p = generatePath(c->streets, c->params, po);
            if (p) {
                path = std::move(p.value());
                havePath = seed != 0;  // playback only when asked; otherwise just the start position
                if (!havePath && !path.samples.empty()) path.samples.resize(1);
            }
        }
    }
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display) {
        std::fprintf(stderr, "vista view: no X display (DISPLAY is not set); run under `xvfb-run -a` without a screen\n");
        return 1;
    }

    std::unique_ptr<RayScene> rays;  // declared before the scene graph that references them
    HeightGrid grid;
    ViewState st;
    st.nearDistance = nearD;
    st.modes = new osg::Switch;
    // A baked file: its root is the view-cell switch; the plain modes draw its
    // city tiles (the children before the impostors) without it.
    osg::ref_ptr<osg::Node> plain = sceneRoot(*c);
    st.baked = dynamic_cast<ViewCellSwitch*>(sceneRoot(*c));
    if (st.baked) {
        osg::ref_ptr<osg::Group> tiles = new osg::Group;
        tiles->setStateSet(st.baked->getStateSet());
        for (unsigned i = 0; i < st.baked->getTileCount() && i < st.baked->getNumChildren(); ++i) tiles->addChild(st.baked->getChild(i));
        plain = tiles;
    } else if (startMode == 4) {
        return reportBadInput(cmd, Status::error("--mode impostor: '" + city + "' is not baked (run 'vista bake' and view its output)"));
    }
    st.modes->addChild(plain.get(), true);
    st.modes->addChild(makeImpostorScene(plain.get(), nearD).get(), false);
    // Hybrid: near field under a NearFarSplit + the far-field drawable. The
    // ray scene and the height grid outlive the viewer (declared before it).
    {
        auto r = RayScene::build(*c);
        if (r) {
            rays = std::move(r.value());
            grid = HeightGrid::build(*c, rays->frameOrigin(), 512);
            HybridSceneOptions ho;
            ho.nearDistance = nearD;
            ho.far.nearDistance = nearD;
            ho.far.pixelBudget = budget;
            st.child[3] = st.modes->getNumChildren();
            st.modes->addChild(buildHybridScene(*c, *rays, grid, ho, &st.split, &st.far).get(), false);
            st.available[3] = true;
        } else {
            std::fprintf(stderr, "vista view: hybrid mode unavailable: %s\n", r.status().message().c_str());
            if (startMode == 3) return reportBadInput(cmd, Status::error("--mode hybrid: " + r.status().message()));
        }
    }
    if (st.baked) {
        st.child[4] = st.modes->getNumChildren();
        st.modes->addChild(st.baked, false);
        st.available[4] = true;
    }
    st.mode = startMode;
    st.modes->setSingleChildOn(st.child[st.mode]);
    osg::ref_ptr<osg::Group> root = new osg::Group;
    root->addChild(st.modes.get());

    // HUD: mode and frame time.
    osg::ref_ptr<osg::Camera> hudCam = new osg::Camera;
    hudCam->setReferenceFrame(osg::Transform::ABSOLUTE_RF);
    hudCam->setProjectionMatrixAsOrtho2D(0, w, 0, h);
    hudCam->setViewMatrix(osg::Matrix::identity());
    hudCam->setClearMask(GL_DEPTH_BUFFER_BIT);
    hudCam->setRenderOrder(osg::Camera::POST_RENDER);
    hudCam->setAllowEventFocus(false);
    st.hud = new osgText::Text;
    st.hud->setCharacterSize(16.0f);
    st.hud->setPosition(osg::Vec3(10.0f, float(h) - 24.0f, 0.0f));
    st.hud->setColor(osg::Vec4(1, 1, 1, 1));
    st.hud->setDataVariance(osg::Object::DYNAMIC);
    osg::ref_ptr<osg::Geode> hudGeode = new osg::Geode;
    hudGeode->addDrawable(st.hud.get());
    hudGeode->getOrCreateStateSet()->setMode(GL_LIGHTING, osg::StateAttribute::OFF);
    hudCam->addChild(hudGeode.get());
    root->addChild(hudCam.get());

    osgViewer::Viewer viewer;
    viewer.setThreadingModel(osgViewer::ViewerBase::SingleThreaded);
    viewer.setUpViewInWindow(0, 0, w, h);
    viewer.setSceneData(root.get());
    osg::Camera* cam = viewer.getCamera();
    cam->setComputeNearFarMode(osg::CullSettings::DO_NOT_COMPUTE_NEAR_FAR);
    cam->setClearColor(osg::Vec4(0.62f, 0.75f, 0.9f, 1.0f));
    st.capture = new Capture;
    cam->setFinalDrawCallback(st.capture.get());

    // Manipulators.
    osg::ref_ptr<osgGA::KeySwitchMatrixManipulator> ks = new osgGA::KeySwitchMatrixManipulator;
    osg::Vec3d start(0, 0, 0), dir(0, 1, 0);
    if (!path.samples.empty()) {
        const auto& s0 = path.samples.front();
        start = osg::Vec3d(s0.position.x, s0.position.y, s0.position.z);
        dir = osg::Vec3d(std::sin(s0.heading), std::cos(s0.heading), 0.0);
    } else {
        start = osg::Vec3d(c->params.origin_x, c->params.origin_y, 1.7);
    }
    auto drive = new osgGA::DriveManipulator;
    auto walk = new osgGA::FirstPersonManipulator;
    auto fly = new osgGA::FlightManipulator;
    auto orbit = new osgGA::TrackballManipulator;
    for (osgGA::CameraManipulator* m : std::initializer_list<osgGA::CameraManipulator*>{drive, walk, fly})
        m->setHomePosition(start, start + dir * 10.0, osg::Vec3d(0, 0, 1));
    drive->setModelScale(1.0);
    ks->addMatrixManipulator('1', "Drive", drive);
    ks->addMatrixManipulator('2', "Walk", walk);
    ks->addMatrixManipulator('3', "Fly", fly);
    ks->addMatrixManipulator('4', "Orbit", orbit);
    // The key switch auto-computes every child's home from the scene bounds
    // by default (OSG), which would override the street start position set
    // above: only the orbit manipulator computes its home.
    ks->setAutoComputeHomePosition(false);
    ks->setHomePosition(start, start + dir * 10.0, osg::Vec3d(0, 0, 1));  // the switch pushes its home to the children
    orbit->setAutoComputeHomePosition(true);
    if (havePath && path.samples.size() > 1) {
        osg::ref_ptr<osg::AnimationPath> ap = new osg::AnimationPath;
        ap->setLoopMode(osg::AnimationPath::LOOP);
        for (const auto& s : path.samples) {
            Camera cc;
            cc.eye = s.position;
            cc.heading = s.heading;
            cc.pitch = s.pitch;
            osg::Matrixd inv = osg::Matrixd::inverse(toOsg(cc.view()));
            ap->insert(s.t, osg::AnimationPath::ControlPoint(inv.getTrans(), inv.getRotate()));
        }
        ks->addMatrixManipulator('5', "Path", new osgGA::AnimationPathManipulator(ap.get()));
        ks->selectMatrixManipulator(4);
    }
    viewer.setCameraManipulator(ks.get());
    viewer.addEventHandler(new osgViewer::StatsHandler);
    viewer.addEventHandler(new osgViewer::HelpHandler(new osg::ApplicationUsage));
    viewer.addEventHandler(new osgViewer::WindowSizeHandler);
    viewer.addEventHandler(new osgGA::StateSetManipulator(cam->getOrCreateStateSet()));
    viewer.addEventHandler(new ViewKeys(st));
    viewer.realize();
    if (!viewer.isRealized()) {
        std::fprintf(stderr, "vista view: cannot open a window on display '%s'\n", display);
        return 1;
    }

    int n = 0;
    double lastMs = 0;
    osg::Timer_t t0 = osg::Timer::instance()->tick();
    while (!viewer.done()) {
        Camera pc;
        const osg::Viewport* vp = cam->getViewport();
        pc.width = vp ? int(vp->width()) : w;
        pc.height = vp ? int(vp->height()) : h;
        pc.fovY = fovDeg * kPi / 180.0;
        cam->setProjectionMatrix(toOsg(pc.projection(st.mode == 1 ? st.nearDistance : 0.0)));  // hybrid: infinite far plane
        // HUD: short lines (they must fit a 640-pixel-wide window at 16 px).
        std::string text;
        char buf[256];
        std::snprintf(buf, sizeof(buf), "mode %s (m)   %.1f ms/frame", kModeNames[st.mode], lastMs);
        text += buf;
        std::snprintf(buf, sizeof(buf), "\nkeys: 1 drive 2 walk 3 fly 4 orbit%s s stats p shot", havePath ? " 5 path" : "");
        text += buf;
        if (st.mode == 4 && st.baked) {
            const int cell = st.baked->lastCell();
            if (cell >= 0)
                std::snprintf(buf, sizeof(buf), "\nview cell %d: %zu impostors", cell, st.baked->impostorsOf(uint32_t(cell)).size());
            else
                std::snprintf(buf, sizeof(buf), "\noutside the view cells: plain city");
            text += buf;
        }
        if (st.mode == 3 && st.far) {
            // Last drawn frame's pixel classes (thesis Table 4.1) and far-field stage times.
            FrameStats fs = st.far->lastStats();
            const PixelCounts& p = fs.pixels;
            const double n = std::max<double>(1.0, double(p.covered + p.horizonCulled + p.cache + p.rayHit + p.rayMiss));
            std::snprintf(buf, sizeof(buf), "\npixels %%: covered %.1f horizon %.1f cache %.1f\n          ray hit %.1f ray miss %.1f",
                          100.0 * double(p.covered) / n, 100.0 * double(p.horizonCulled) / n, 100.0 * double(p.cache) / n,
                          100.0 * double(p.rayHit) / n, 100.0 * double(p.rayMiss) / n);
            text += buf;
            std::snprintf(buf, sizeof(buf), "\nnear chunks drawn %u   stages ms:", st.split ? st.split->lastNearCount() : 0u);
            text += buf;
            int k = 0;
            fs.stages.forEach([&](Stage stage, double ms) {
                std::snprintf(buf, sizeof(buf), "%s%s %.1f", k % 4 == 0 ? "\n  " : "  ", stageName(stage), ms);
                text += buf;
                ++k;
            });
        }
        st.hud->setText(text);
        bool last = frames > 0 && n + 1 >= frames;
        if (last && !screenshot.empty()) st.capture->pending = screenshot;
        viewer.frame();
        osg::Timer_t t1 = osg::Timer::instance()->tick();
        lastMs = osg::Timer::instance()->delta_m(t0, t1);
        t0 = t1;
        if (last) break;
        ++n;
    }
    if (!screenshot.empty() && st.capture->lastWritten != screenshot) return 1;
    return 0;
}

}  // namespace vista
