// vista view: interactive OSG viewer of a city (a real window on a GPU, or
// under Xvfb). Drive / walk / fly / orbit manipulators, path playback,
// on-screen stats (osgViewer StatsHandler, key s), the render modes of the
// registry (key m cycles them; each mode's viewer face, created on first
// use; the HUD shows what the mode reports: pixel classes, stage times,
// notes), screenshots (key p, or --screenshot with --frames for headless
// use). --step shows exactly the bench's frames of the path (the camera of
// `vista bench --frames N`), so view and bench can be compared image to image.
//
// A paged city (DIR.paged) is streamed (the default; --paged-preload loads the
// regions around the path before the first frame instead, as does a start mode
// that does not stream): the viewer's graph and ray scene follow the
// camera through the same CityStream as `vista bench` and `vista render`
// (cmd/paged_stream.h). Between viewer frames, on the frame thread, the
// stream is advanced to the camera with its velocity (the path's at --step,
// else measured from the camera's motion), so regions ahead of the heading
// load first; the loads run on the pager's worker and a frame never waits
// for them (--paged-wait: every frame does), except the first, which waits
// for the regions around the start. A region keeps its coarse level until
// its full level has arrived (without a budget that forbids both). Started in
// a hybrid mode, the stream keeps the near field as the bench's does (chunks
// only for the regions around the camera; the split node chooses among them
// at each cull), and the modes that draw the whole graph are not offered;
// every mode made so far drops what it kept of the old resident set when the
// set changes (RenderMode::sceneChanged). At exit a
// line on stderr gives the stream's totals and the frames that drew a region
// below the detail its distance asks for (cmd/paged_stream.h StreamDetail). A
// stream that cannot stream (unreadable region files, a budget that cannot
// hold the regions at the camera) stops the viewer with exit 2. --pace with
// --step shows each frame at its path time: a drive at the path's own speed.
#include <filesystem>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include <osg/Camera>
#include <osg/Geode>
#include <osg/GL>
#include <osgGA/AnimationPathManipulator>
#include <osgGA/DriveManipulator>
#include <osgGA/FirstPersonManipulator>
#include <osgGA/FlightManipulator>
#include <osgGA/KeySwitchMatrixManipulator>
#include <osgGA/StateSetManipulator>
#include <osgGA/TrackballManipulator>
#include <osgText/Text>
#include <osgViewer/Viewer>
#include <osgViewer/ViewerEventHandlers>

#include <glm/gtc/type_ptr.hpp>

#include "cmd/cli.h"
#include "cmd/memory.h"
#include "cmd/commands.h"
#include "cmd/options.h"
#include "cmd/paged_stream.h"
#include "foundation/timing.h"
#include "foundation/units.h"
#include "nodes/far_field_node.h"
#include "nodes/gl_readback.h"
#include "nodes/render/city_stream.h"
#include "nodes/render/offscreen.h"
#include "nodes/render/traffic_scene.h"
#include "nodes/render/walkthrough.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/scene/paged_load.h"
#include "runtime/scene/scene_graph.h"

namespace vista {

namespace {

const char* const kCmd = "vista view";

osg::Matrixd toOsg(const glm::dmat4& m) { return osg::Matrixd(glm::value_ptr(m)); }

struct ViewArgs {
    std::string city, size = "1280x720", screenshot, mode = "full";
    std::optional<std::string> effects;  // unset: the scene's
    int frames = 0;
    bool step = false, noHud = false;
    bool repeats = false;  // --allow-repeated-frames (with --step)
    std::string sampling = samplingName(kDefaultSampleRuns);
    int sampleRuns = kDefaultSampleRuns;
    PathFlags path;
    ModeFlags modeFlags;
    ImageSize window;
    double fovDeg = 60.0, memoryBudgetGb = 0;
    PagedReach paged;
    PagedStreamFlags stream;
    bool streamed = false;  // a paged city that streams (choosePagedStream)
    bool pace = false;      // --pace
    CommandFiles files;     // checked by configure; holds the output's lock for the run
};

void declareFlags(CLI::App& app, ViewArgs& a) {
    a.path.seed = 0;  // no playback unless asked
    app.add_option("city", a.city,
                   "city scene file (.osgb), a paged city directory (DIR.paged: streamed around the camera), "
                   "or a baked file from 'vista bake' (adds the impostor mode; lodmesh for --representation mesh)")
        ->required();
    addPathFlags(app, a.path, true);
    addPagedFlags(app, a.paged);
    addPagedStreamFlags(app, a.stream);
    app.get_option("--seed")->description(
        "play back the path of this seed (key 5); default 0 = none, start where seed 1's path starts");
    app.add_option("--size", a.size, "window size WIDTHxHEIGHT, 1x1 .. 8192x8192 (default 1280x720)");
    addNumberOption(app, "--fov", a.fovDeg, kFovRange, "vertical field of view in degrees, (1, 179) (default 60)");
    app.add_option("--mode", a.mode, "start in this render mode: " + renderModeNames() + " (default full)");
    addModeFlags(app, a.modeFlags);
    addNumberOption(app, "--frames", a.frames, 0, 100000000, "quit after N frames, 0 .. 100000000 (0 = run until Esc)");
    app.add_flag(
        "--step", a.step,
        "with --frames N and a path: show the N frames `vista bench --frames N` renders (one path sample per frame)");
    app.add_option("--sampling", a.sampling,
                   "with --step: the path samples shown, as vista bench's --sampling: spread, consecutive or runs:K "
                   "(default " +
                       samplingName(kDefaultSampleRuns) + ")");
    addRepeatedFramesFlag(app, a.repeats);
    app.add_flag("--pace", a.pace,
                 "with --step and --sampling consecutive: show each frame no earlier than its path time after the "
                 "first frame's, a drive at the path's own speed");
    app.add_flag("--no-hud", a.noHud, "no text overlay (for screenshots compared with `vista bench`)");
    app.add_option("--screenshot", a.screenshot, "write a PNG of the last frame (use with --frames)");
    addNumberOption(
        app, "--memory-budget", a.memoryBudgetGb, kMemoryBudgetGbRange,
        "GB, (0, 65536]: refuse up front when the estimated peak memory (from the city file's size, with the ray scene "
        "every mode may need) exceeds it; a streamed paged city's regions are held within it, and a budget that "
        "cannot hold the regions at the camera is an error naming the budget they need (default: no budget)");
    app.add_option("--effects", a.effects,
                   "run-time effects instead of the scene's: 'none', names (haze, glass, night) or a JSON object; "
                   "keys y / g / n toggle haze, glass reflections and the night sky");
}

Status configure(ViewArgs& a, ModeOptions& options) {
    auto size = parseImageSize(a.size);
    if (!size) return size.status();
    a.window = size.value();
    VISTA_RETURN_IF_ERROR(checkFov(a.fovDeg));
    if (auto m = parseModeName(a.mode); !m) return m.status();
    auto sampling = parseSampling(a.sampling);
    if (!sampling) return sampling.status();
    a.sampleRuns = sampling.value();
    if (a.step && (a.frames < 1 || a.frames > 1000000 || (a.path.file.empty() && a.path.seed == 0)))
        return Status::error("--step needs --frames N in 1 .. 1000000 (as vista bench) and a path (--path or --seed)");
    if (a.repeats && !a.step)
        return Status::error(
            "option --allow-repeated-frames: only with --step (without it --frames counts frames "
            "drawn, not path samples)");
    VISTA_RETURN_IF_ERROR(checkRunFiles(a.files.output("--screenshot", a.screenshot), a.city, a.path, a.modeFlags));
    if (!a.screenshot.empty()) VISTA_RETURN_IF_ERROR(checkWritablePath("--screenshot", a.screenshot));
    VISTA_RETURN_IF_ERROR(validatePagedReach(a.paged));
    VISTA_RETURN_IF_ERROR(validatePagedStream(a.stream));
    if (a.pace && (!a.step || a.sampleRuns != 1))
        return Status::error("--pace: needs --step and --sampling consecutive (a drive at the path's own speed)");
    const Status modes = checkStreamingModes({a.mode});
    auto streamed = choosePagedStream(kCmd, a.stream, a.city, modes ? std::string() : modes.message(), false);
    if (!streamed) return streamed.status();
    a.streamed = *streamed;
    return parseModeFlags(a.modeFlags, options);
}

// The registry's modes in the viewer, each created on first use (its ray
// scene too, when the mode needs one).
class ViewModes {
public:
    // stream: a streamed paged city (its graph and ray scene are in ctx), or null.
    ViewModes(ModeContext& ctx, CityStream* stream) : _ctx(ctx), _stream(stream) {}
    Result<RenderMode*> get(const std::string& name) {
        auto it = _modes.find(name);
        if (it != _modes.end()) return it->second.get();
        const ModeInfo* info = findRenderMode(name);
        if (!info) return Status::error("unknown mode '" + name + "'");
        // A stream started in a hybrid mode keeps chunks only near the camera (CityStream::setGraphLevels).
        if (_stream && modeStreams(name) && streamGraphOf({name}) == StreamGraph::EveryLevel &&
            _stream->graphLevels() != StreamGraph::EveryLevel)
            return Status::error(
                "the streamed city keeps chunks only near the camera (started in a hybrid mode); "
                "start in full or near to draw the whole city");
        if (info->needsRays || _ctx.options.effects.glassMarked) VISTA_RETURN_IF_ERROR(buildRays());
        Stopwatch sw;
        auto m = createRenderMode(name, _ctx);
        if (!m) return m.status();
        std::fprintf(stderr, "%s: mode %s set up in %.0f ms\n", kCmd, name.c_str(), sw.ms());
        return (_modes[name] = std::move(m.value())).get();
    }
    // The streamed city's resident set changed: every mode made so far forgets what it kept of the
    // old one (RenderMode::sceneChanged).
    void sceneChanged(const SceneBoxes& changed) {
        for (auto& [name, m] : _modes) m->sceneChanged(changed);
    }
    // Moves the ray scene's frame next to the eye (RayScene::placeFrameNear),
    // between frames, when no ray is in flight.
    void placeFrameNear(const glm::dvec3& eye) {
        RayScene* rays = _stream ? _stream->rays() : _rays.get();
        if (!rays) return;
        if (Status st = rays->placeFrameNear(eye); !st) std::fprintf(stderr, "%s: %s\n", kCmd, st.message().c_str());
    }
    // The mode after `current` that can be created (stays on `current` if none).
    std::string next(const std::string& current) {
        const auto& all = renderModes();
        size_t i = 0;
        while (i < all.size() && current != all[i].name) ++i;
        for (size_t k = 1; k <= all.size(); ++k) {
            const std::string name = all[(i + k) % all.size()].name;
            if (auto m = get(name)) return name;
            else
                std::fprintf(stderr, "%s: mode %s unavailable: %s\n", kCmd, name.c_str(), m.status().message().c_str());
        }
        return current;
    }

private:
    Status buildRays() {
        if (_ctx.rays) return Status::ok();
        if (_stream) return Status::error("the streamed city has no ray scene (start in a mode that casts rays)");
        if (!_raysError.empty()) return Status::error(_raysError);
        if (!_ctx.city) return Status::error("no city for the ray scene");
        auto r = RayScene::build(*_ctx.city);
        if (!r) {
            _raysError = "the ray scene could not be built: " + r.status().message();
            return Status::error(_raysError);
        }
        _rays = std::move(r.value());
        _ctx.rays = _rays.get();
        if (_ctx.traffic) return _ctx.traffic->attachRays(_rays.get());  // agents beyond a split are ray-cast
        return Status::ok();
    }
    ModeContext& _ctx;
    CityStream* _stream = nullptr;
    std::unique_ptr<RayScene> _rays;  // before _modes: destroyed after them
    std::string _raysError;
    std::map<std::string, std::unique_ptr<RenderMode>> _modes;
};

// Reads the back buffer after the frame (HUD included) and writes a PNG.
struct Capture : public osg::Camera::DrawCallback {
    mutable std::string pending, lastWritten;
    void operator()(osg::RenderInfo& ri) const override {
        if (pending.empty()) return;
        const osg::Viewport* vp = ri.getCurrentCamera()->getViewport();
        const int w = int(vp->width()), h = int(vp->height());
        Image img(w, h);
        std::vector<uint32_t> buf;
        glReadBuffer(GL_BACK);
        readColorTopDown(0, 0, w, h, buf, img.rgba.data());
        for (size_t i = 3; i < img.rgba.size(); i += 4) img.rgba[i] = 255;
        Status s = writePng(img, pending);
        if (s) std::fprintf(stderr, "%s: screenshot -> %s\n", kCmd, pending.c_str());
        else std::fprintf(stderr, "%s: %s\n", kCmd, s.message().c_str());
        lastWritten = s ? pending : std::string();
        pending.clear();
    }
};

struct Hud {
    osg::ref_ptr<osg::Camera> camera;
    osg::ref_ptr<osgText::Text> text;
};

Hud makeHud(int w, int h) {
    Hud hud;
    hud.camera = new osg::Camera;
    hud.camera->setReferenceFrame(osg::Transform::ABSOLUTE_RF);
    hud.camera->setProjectionMatrixAsOrtho2D(0, w, 0, h);
    hud.camera->setViewMatrix(osg::Matrix::identity());
    hud.camera->setClearMask(GL_DEPTH_BUFFER_BIT);
    hud.camera->setRenderOrder(osg::Camera::POST_RENDER);
    hud.camera->setAllowEventFocus(false);
    hud.text = new osgText::Text;
    hud.text->setCharacterSize(16.0f);
    hud.text->setPosition(osg::Vec3(10.0f, float(h) - 24.0f, 0.0f));
    hud.text->setColor(osg::Vec4(1, 1, 1, 1));
    hud.text->setDataVariance(osg::Object::DYNAMIC);
    osg::ref_ptr<osg::Geode> geode = new osg::Geode;
    geode->addDrawable(hud.text.get());
    geode->getOrCreateStateSet()->setMode(GL_LIGHTING, osg::StateAttribute::OFF);
    hud.camera->addChild(geode.get());
    return hud;
}

// HUD lines (short: they must fit a 640-pixel-wide window at 16 px).
std::string hudText(const std::string& mode, double lastMs, const FrameStats& fs, bool havePath) {
    char buf[256];
    std::snprintf(buf, sizeof(buf), "mode %s (m)   %.1f ms/frame\nkeys: 1 drive 2 walk 3 fly 4 orbit%s s stats p shot",
                  mode.c_str(), lastMs, havePath ? " 5 path" : "");
    std::string text = buf;
    const PixelCounts& p = fs.pixels;
    if (p.total() > 0) {
        const double n = double(p.total());
        std::snprintf(
            buf, sizeof(buf),
            "\npixels %%: covered %.1f horizon %.1f cache %.1f\n          ray hit %.1f ray miss %.1f interpolated %.1f",
            100.0 * double(p.covered) / n, 100.0 * double(p.horizonCulled) / n, 100.0 * double(p.cache) / n,
            100.0 * double(p.rayHit) / n, 100.0 * double(p.rayMiss) / n, 100.0 * double(p.interpolated) / n);
        text += buf;
    }
    for (const auto& note : fs.notes) text += "\n" + note;
    if (fs.stages.count() > 0) text += "\nstages ms:";
    int k = 0;
    fs.stages.forEach([&](Stage stage, double ms) {
        std::snprintf(buf, sizeof(buf), "%s%s %.1f", k++ % 4 == 0 ? "\n  " : "  ", stageName(stage), ms);
        text += buf;
    });
    std::string fx;
    fs.effects.forEach([&](EffectId e, double ms) {
        std::snprintf(buf, sizeof(buf), "  %s %.1f", effectName(e), ms);
        fx += buf;
    });
    if (!fx.empty()) text += "\neffects ms (y g n):" + fx;
    return text;
}

struct Keys : public osgGA::GUIEventHandler {
    bool nextMode = false;
    int shots = 0;
    osg::ref_ptr<Capture> capture;
    FrameEffects* effects = nullptr;  // live toggles (the modes read it every frame)
    FrameEffects declared;            // what the scene declares (toggling back on restores it)
    bool handle(const osgGA::GUIEventAdapter& ea, osgGA::GUIActionAdapter&) override {
        if (ea.getEventType() != osgGA::GUIEventAdapter::KEYDOWN) return false;
        if (ea.getKey() == 'm') nextMode = true;
        else if (ea.getKey() == 'p') capture->pending = "vista_screenshot_" + std::to_string(shots++) + ".png";
        else if (ea.getKey() == 'y' && effects) {
            effects->haze = !effects->haze;
            if (effects->haze && !(effects->visibility < 1e29))
                effects->visibility = declared.haze ? declared.visibility : 1500.0;
        } else if (ea.getKey() == 'g' && effects) {
            effects->glass = !effects->glass && effects->glassMarked;
            if (effects->glass && effects->rayBudget <= 0)
                effects->rayBudget = declared.rayBudget > 0 ? declared.rayBudget : 50000;
        } else if (ea.getKey() == 'n' && effects) {
            effects->night = !effects->night;
        } else {
            return false;
        }
        return true;
    }
    void getUsage(osg::ApplicationUsage& u) const override {
        u.addKeyboardMouseBinding("m", "cycle the render modes (" + renderModeNames() + ")");
        u.addKeyboardMouseBinding("p", "screenshot to vista_screenshot_N.png");
        u.addKeyboardMouseBinding("y", "haze on/off (the scene's visibility, else 1500 m)");
        u.addKeyboardMouseBinding("g", "glass reflections on/off (scenes generated with glass)");
        u.addKeyboardMouseBinding("n", "night sky on/off");
    }
};

// Drive / walk / fly from `start` looking along `dir`, orbit, and path playback.
osg::ref_ptr<osgGA::KeySwitchMatrixManipulator> makeManipulators(const Path& path, bool playback,
                                                                 const SceneModel& city) {
    osg::ref_ptr<osgGA::KeySwitchMatrixManipulator> ks = new osgGA::KeySwitchMatrixManipulator;
    osg::Vec3d start(city.params.origin_x, city.params.origin_y, 1.7), dir(0, 1, 0);
    if (!path.samples.empty()) {
        const auto& s0 = path.samples.front();
        start = osg::Vec3d(s0.position.x, s0.position.y, s0.position.z);
        dir = osg::Vec3d(std::sin(s0.heading), std::cos(s0.heading), 0.0);
    }
    auto drive = new osgGA::DriveManipulator;
    auto orbit = new osgGA::TrackballManipulator;
    drive->setModelScale(1.0);
    ks->addMatrixManipulator('1', "Drive", drive);
    ks->addMatrixManipulator('2', "Walk", new osgGA::FirstPersonManipulator);
    ks->addMatrixManipulator('3', "Fly", new osgGA::FlightManipulator);
    ks->addMatrixManipulator('4', "Orbit", orbit);
    // The key switch would compute every child's home from the scene bounds
    // (OSG default), overriding the street start: only the orbit computes its own.
    ks->setAutoComputeHomePosition(false);
    ks->setHomePosition(start, start + dir * 10.0, osg::Vec3d(0, 0, 1));  // pushed to the children
    orbit->setAutoComputeHomePosition(true);
    if (playback && path.samples.size() > 1) {
        osg::ref_ptr<osg::AnimationPath> ap = new osg::AnimationPath;
        ap->setLoopMode(osg::AnimationPath::LOOP);
        for (const auto& s : path.samples) {
            Camera cc;
            cc.eye = s.position;
            cc.heading = s.heading;
            cc.pitch = s.pitch;
            const osg::Matrixd inv = osg::Matrixd::inverse(toOsg(cc.view()));
            ap->insert(s.t, osg::AnimationPath::ControlPoint(inv.getTrans(), inv.getRotate()));
        }
        ks->addMatrixManipulator('5', "Path", new osgGA::AnimationPathManipulator(ap.get()));
        ks->selectMatrixManipulator(4);
    }
    return ks;
}

// The walkthrough: --path, or the path of --seed (played back), or only the
// start position of seed 1's path.
Result<Path> viewPath(const ViewArgs& a, const SceneModel& city, bool& playback) {
    playback = !a.path.file.empty() || a.path.seed != 0;
    PathFlags f = a.path;
    if (f.seed == 0) f.seed = 1;
    auto po = parsePathFlags(f);
    if (!po) return po.status();
    if (f.file.empty() && city.streets.edges.empty()) return Path();
    auto p = walkthroughPath(f.file, po.value(), city);
    if (!p) return p;
    if (!playback && !p->samples.empty()) p->samples.resize(1);
    return p;
}

// Speeds above this (m/s) are a jump of the camera (home, a manipulator
// switch), not motion: the measured velocity is clamped to it.
constexpr double kMaxViewSpeed = 100.0;

// A streamed paged city in the viewer: the stream, the camera's measured
// velocity and the totals printed at exit.
struct ViewStream {
    std::unique_ptr<CityStream> stream;
    const PagedManifest* manifest = nullptr;
    RegionPagerOptions options;
    bool started = false;
    glm::dvec3 lastEye{0.0}, velocity{0.0};
    int framesWithArrivals = 0;
    StreamDetail detail;  // frames that drew a region below the detail its distance asks for
    std::vector<std::string> damaged;

    // Between frames: the stream follows the camera at `eye`, moving at
    // `pathVelocity` (--step) or at the velocity measured over `dtS`
    // seconds since the last frame. The first call waits for the regions
    // around the camera. Counts the frames that will draw a region below the
    // detail its distance from the eye asks for (`t`: the frame's time, s).
    Status advance(const glm::dvec3& eye, const glm::dvec3* pathVelocity, double dtS, double t, ViewModes& modes) {
        if (pathVelocity) {
            velocity = *pathVelocity;
        } else if (started && dtS > 0) {
            velocity = 0.5 * velocity + 0.5 * (eye - lastEye) / dtS;
            const double speed = glm::length(velocity);
            if (speed > kMaxViewSpeed) velocity *= kMaxViewSpeed / speed;
        }
        auto f = advancePagedStream(*stream, kCmd, eye, velocity, &damaged, !started);
        if (!f) return f.status();
        started = true;
        lastEye = eye;
        detail.add(*f, t);
        framesWithArrivals += f->arrived > 0 ? 1 : 0;
        if (f->arrived > 0 || f->dropped > 0) modes.sceneChanged(f->changed);
        return Status::ok();
    }
    // `last`: the last frame's statistics (a hybrid mode's near field: the triangles it drew).
    void report(const std::string& mode, const FrameStats& last) const {
        const RegionPagerStats st = stream->stats();
        std::string nearField;
        if (modeStreamsNearField(mode))
            nearField = "; the last frame's near field drew " + std::to_string(last.triangles) + " triangles";
        std::fprintf(stderr,
                     "%s: paged stream: %d loads, %d unloads, %.1f MB of region files read, peak %.1f MB resident; "
                     "%d of %d frames waited, %d had regions arriving, %d drew a region below the detail its "
                     "distance asks for (%d after the first second)%s\n",
                     kCmd, st.loads, st.unloads, double(st.bytesRead) / 1e6, double(st.peakResidentBytes) / 1e6,
                     st.framesWaited, detail.frames, framesWithArrivals, detail.belowDetail,
                     detail.belowDetailAfterFirstSecond, nearField.c_str());
    }
};

struct ViewState {
    osgViewer::Viewer viewer;
    osg::ref_ptr<osg::Group> slot;  // the current mode's viewer scene
    std::unique_ptr<SkyBackground> sky;
    Hud hud;
    osg::ref_ptr<Keys> keys;
    std::string mode;
    RenderMode* current = nullptr;
    ViewStream* stream = nullptr;           // a streamed paged city, or null
    const TrafficScene* traffic = nullptr;  // --traffic, or null
};

Status setUpWindow(ViewState& v, const ViewArgs& a, osg::ref_ptr<osgGA::KeySwitchMatrixManipulator> manips) {
    v.sky = std::make_unique<SkyBackground>(a.window.width, a.window.height);
    v.slot = new osg::Group;
    osg::ref_ptr<osg::Group> root = new osg::Group;
    root->addChild(v.sky->node());
    root->addChild(v.slot.get());
    v.hud = makeHud(a.window.width, a.window.height);
    if (!a.noHud) root->addChild(v.hud.camera.get());
    v.viewer.setThreadingModel(osgViewer::ViewerBase::SingleThreaded);
    v.viewer.setUseConfigureAffinity(false);  // no pinning of the main thread to core 0 (render/offscreen.cpp)
    v.viewer.setUpViewInWindow(0, 0, a.window.width, a.window.height);
    v.viewer.setSceneData(root.get());
    osg::Camera* cam = v.viewer.getCamera();
    setExactCulling(*cam);             // the bench renderer's culling: same pictures
    flushDeletedGLObjectsEvery(*cam);  // as the bench renderer: no walk over every GL buffer set each frame
    cam->setClearColor(osg::Vec4(0, 0, 0, 1));
    v.keys = new Keys;
    v.keys->capture = new Capture;
    cam->setFinalDrawCallback(v.keys->capture.get());
    v.viewer.setCameraManipulator(manips.get());
    v.viewer.addEventHandler(new osgViewer::StatsHandler);
    v.viewer.addEventHandler(new osgViewer::HelpHandler(new osg::ApplicationUsage));
    v.viewer.addEventHandler(new osgViewer::WindowSizeHandler);
    v.viewer.addEventHandler(new osgGA::StateSetManipulator(cam->getOrCreateStateSet()));
    v.viewer.addEventHandler(v.keys.get());
    v.viewer.realize();
    if (!v.viewer.isRealized())
        return Status::error("cannot open a window on display '" + std::string(std::getenv("DISPLAY")) + "'");
    return Status::ok();
}

// The traffic's time at `seconds` of wall time since the first frame when the
// camera is driven by hand: the run's own clock from its first step, looping
// over its span.
double trafficClock(const TrafficScene* traffic, double seconds) {
    if (!traffic || traffic->tracks().frames() == 0) return seconds;
    const double t0 = traffic->tracks().times.front(), span = traffic->tracks().times.back() - t0;
    return span > 0 ? t0 + std::fmod(seconds, span) : t0;
}

void showMode(ViewState& v, ViewModes& modes, const std::string& name) {
    auto m = modes.get(name);
    if (!m) return;
    v.mode = name;
    v.current = m.value();
    v.slot->removeChildren(0, v.slot->getNumChildren());
    v.slot->addChild(v.current->viewerScene());
}

// The frame loop: events, camera (manipulator or --step), the mode's frame
// hook and far plane, sky, HUD, draw; the screenshot after the last frame.
int runLoop(ViewState& v, ViewModes& modes, const ViewArgs& a, const Path& path, bool playback) {
    osg::Camera* cam = v.viewer.getCamera();
    const std::vector<size_t> stepFrames = a.step ? path.frames(size_t(a.frames), a.sampleRuns) : std::vector<size_t>();
    Stopwatch sw, clock;
    double lastMs = 0;
    for (int n = 0; !v.viewer.done(); ++n) {
        if (a.pace && n > 0) {
            // A drive at the path's own speed: this frame is shown at its path time after the first's.
            const double dueMs =
                1000.0 * (path.samples[stepFrames[size_t(n)]].t - path.samples[stepFrames[0]].t) - clock.ms();
            if (dueMs > 0) std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(dueMs));
        }
        if (n == 0) clock.restart();
        if (v.keys->nextMode) {
            v.keys->nextMode = false;
            showMode(v, modes, modes.next(v.mode));
        }
        v.viewer.advance();
        v.viewer.eventTraversal();
        v.viewer.updateTraversal();
        const osg::Viewport* vp = cam->getViewport();
        Camera c;
        c.width = vp ? int(vp->width()) : a.window.width;
        c.height = vp ? int(vp->height()) : a.window.height;
        c.fovY = degToRad(a.fovDeg);
        if (a.step) {
            c = path.camera(stepFrames[size_t(n)], c);
            cam->setViewMatrix(toOsg(c.view()));
        } else {
            c.time = trafficClock(v.traffic, clock.ms() / 1000.0);
            Camera fromOsg;
            double zf = 0;
            if (cameraFromOsg(cam->getViewMatrix(), toOsg(c.projection(0.0)), c.width, c.height, fromOsg,
                              zf)) {  // the pose
                c.eye = fromOsg.eye;
                c.heading = fromOsg.heading;
                c.pitch = fromOsg.pitch;
                c.roll = fromOsg.roll;
            }
        }
        if (v.stream) {
            const glm::dvec3 pv = a.step ? pathVelocity(path, stepFrames[size_t(n)]) : glm::dvec3(0.0);
            const double t = a.step ? path.samples[stepFrames[size_t(n)]].t : clock.ms() / 1000.0;
            if (Status st = v.stream->advance(c.eye, a.step ? &pv : nullptr, lastMs / 1000.0, t, modes); !st)
                return reportBadInput(kCmd, st);  // a stream that cannot stream: exit 2
        }
        modes.placeFrameNear(c.eye);  // ray origins near the frame origin: float precision anywhere
        cam->setProjectionMatrix(toOsg(c.projection(v.current->beginViewerFrame(c))));
        if (v.keys->effects) v.sky->setNight(v.keys->effects->night);
        const bool skyLayer = !v.current->drawsSky();  // hybrid: the far field writes every uncovered pixel
        v.sky->node()->setNodeMask(skyLayer ? ~0u : 0u);
        if (skyLayer) v.sky->showSky(c);
        v.hud.text->setText(hudText(v.mode, lastMs, v.current->lastViewerStats(), playback));
        const bool last = a.frames > 0 && n + 1 >= a.frames;
        if (last && !a.screenshot.empty()) v.keys->capture->pending = a.screenshot;
        v.viewer.renderingTraversals();
        lastMs = sw.lap();
        if (last) break;
    }
    if (v.stream) v.stream->report(v.mode, v.current->lastViewerStats());
    // A --screenshot that could not be written (its cause is on stderr, e.g. a full device) is a failed output.
    if (!a.screenshot.empty() && v.keys->capture->lastWritten != a.screenshot) return 2;
    return 0;
}

// A streamed paged city: the stream of the city's regions (no region loaded yet),
// into the modes' context. Errors name the flag or the ray scene.
Status startStream(const ViewArgs& a, const Walkthrough& walk, ModeContext& ctx, ViewStream& vs) {
    const bool rays = findRenderMode(a.mode)->needsRays || effectsNeedRays(ctx.options.effects) ||
                      ctx.options.effects.glassMarked;  // ViewModes casts reflections for every mode then
    auto so = pagedStreamOptions(a.paged, a.stream, a.memoryBudgetGb, estimateCityRunMb(0, rays));
    if (!so) return so.status();
    vs.options = *so;
    vs.manifest = walk.manifest.get();
    auto st = CityStream::create(*walk.manifest, vs.options, rays);
    if (!st) return Status::error("setting up the streamed city failed: " + st.status().message());
    vs.stream = std::move(*st);
    if (modeStreamsNearField(a.mode)) {
        // hybrid: the stream keeps the near field, its split index and the horizon grid too, and
        // chunks only for the regions around the camera; the modes that draw the whole graph
        // are then not offered (ViewModes::get).
        vs.stream->enableNearField(ctx.options.horizonGrid);
        vs.stream->setGraphLevels(streamGraphOf({a.mode}), streamNearBand(ctx.options));
    }
    holdStreamUnder(*vs.stream, a.memoryBudgetGb);
    ctx.stream = vs.stream.get();
    ctx.streamedCity = vs.stream->graph();
    ctx.scene = vs.stream->graph();
    ctx.rays = vs.stream->rays();
    notePagedStream(kCmd, *walk.manifest, vs.options);
    return Status::ok();
}

}  // namespace

// The command's entry: parse, check the memory budget, load the walkthrough,
// then open the window and run the frame loop.
int runView(int argc, char** argv) {
    CLI::App app{
        "Interactive viewer: drive (1), walk (2), fly (3), orbit (4), path playback (5); s = stats, "
        "m = render mode, p = screenshot, h = help.",
        kCmd};
    ViewArgs a;
    declareFlags(app, a);
    if (int rc = parseOrExit(app, argc, argv); rc >= 0) return rc;
    ModeContext ctx;
    if (Status s = configure(a, ctx.options); !s) return reportBadInput(kCmd, s);
    auto tracks = loadTrafficFlag(a.modeFlags.traffic);
    if (!tracks) return reportBadInput(kCmd, tracks.status());
    {
        std::error_code ec;
        const uint64_t bytes = std::filesystem::file_size(a.city, ec);
        if (!ec)
            if (Status s =
                    checkMemoryBudget("--memory-budget", a.memoryBudgetGb, estimateCityRunMb(bytes, true), bytes, true);
                !s)
                return reportBadInput(kCmd, s);
    }
    bool playback = false;
    WalkthroughRequest req;
    req.city = a.city;
    req.cmd = kCmd;
    req.paged = a.paged;
    req.streamPaged = a.streamed;
    req.pathNeedsStreets = a.path.file.empty();
    req.makePath = [&](const SceneModel& city) -> Result<Path> {
        auto p = viewPath(a, city, playback);
        if (p && a.step && p->samples.empty()) return Status::error("--step: the path has no samples");
        if (p && a.step) VISTA_RETURN_IF_ERROR(checkFrameCount(a.frames, p->samples.size(), a.repeats));
        return p;
    };
    req.beforePagedLoad = [&](uint64_t bytes) {
        return checkMemoryBudget("--memory-budget", a.memoryBudgetGb, estimateCityRunMb(bytes, true), bytes, true);
    };
    // Every baked file given is checked against the city up front (modes are switched at run time).
    req.bakedModes = {};
    req.effects = [&](const Effects& declared) { return runTimeEffects(a.effects, declared, false, kCmd); };
    auto walk = loadWalkthrough(req, ctx.options);
    if (!walk) return reportBadInput(kCmd, walk.status());
    if (int rc = requireDisplay(kCmd); rc >= 0) return rc;
    const SceneModel& city = walk->city;
    const Path& path = walk->path;
    ctx.city = &city;
    ctx.scene = sceneRoot(city);
    ViewStream stream;  // before the modes: they draw its graph
    if (a.streamed && walk->manifest)
        if (Status s = startStream(a, *walk, ctx, stream); !s) return reportBadInput(kCmd, s);
    ViewModes modes(ctx, stream.stream.get());
    std::unique_ptr<TrafficScene> traffic;  // after the modes' ray scene: released before it
    if (*tracks) {
        traffic = std::make_unique<TrafficScene>(*tracks, city.params, false);
        ctx.traffic = traffic.get();
        if (stream.stream && stream.stream->rays())
            if (Status s = traffic->attachRays(stream.stream->rays()); !s) return reportBadInput(kCmd, s);
        if (Status s = traffic->showCitySignals(city, walk->manifest.get()); !s) return reportBadInput(kCmd, s);
    }
    auto start = modes.get(a.mode);
    if (!start) return reportBadInput(kCmd, Status::error("--mode " + a.mode + ": " + start.status().message()));
    ViewState v;
    if (Status s = setUpWindow(v, a, makeManipulators(path, playback && !a.step, city)); !s) {
        std::fprintf(stderr, "%s: %s\n", kCmd, s.message().c_str());
        return 1;
    }
    v.keys->effects = &ctx.options.effects;
    v.keys->declared = FrameEffects::fromScene(city.params.effects);
    v.stream = stream.stream ? &stream : nullptr;
    v.traffic = traffic.get();
    showMode(v, modes, a.mode);
    return runLoop(v, modes, a, path, playback);
}

}  // namespace vista
