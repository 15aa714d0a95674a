// vista render: ground truth per frame of a walkthrough — colour (rgb), metric
// depth, semantic classes and instance ids — plus cameras.json, classes.json
// and summary.json (per-channel timings). docs/formats.md "Ground truth
// (vista render)" describes every output.
//
// Labels come from the render mode itself: the label pass (nodes/label_pass.h)
// draws the chunks the mode rasterised (RenderMode::lastRaster) with the same
// far plane; pixels the mode took from the far field (hybrid: uncovered, or
// beyond its near distance) are labelled by Embree rays cast per frame
// (runtime/engine/ground_truth.h). The colour cache of hybrid applies to rgb only.
// Output goes into the work directory "<out>.partial" (cmd/render_work_dir.h):
// every frame's files are written atomically, then its record; a rerun of the
// same command after an interruption keeps the finished frames and renders
// the rest (hybrid first re-renders the finished frames before the last
// missing one without writing them, so that its panoramic cache holds what
// an uninterrupted run's held); "<out>.partial/out" is renamed to <out> when
// every frame is written.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <csignal>
#include <cstdlib>
#include <cstring>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "citygen/labels.h"
#include "foundation/format.h"
#include "cmd/cli.h"
#include "cmd/commands.h"
#include "cmd/options.h"
#include "cmd/render_work_dir.h"
#include "foundation/atomic_file.h"
#include "foundation/hash.h"
#include "foundation/progress.h"
#include "foundation/statistics.h"
#include "foundation/timing.h"
#include "foundation/units.h"
#include "nodes/render/offscreen.h"
#include "runtime/engine/far_field_rays.h"
#include "runtime/engine/ground_truth.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/scene_graph.h"

namespace vista {

namespace {

namespace fs = std::filesystem;
const char* const kCmd = "vista render";

enum Channel : unsigned { kRgb = 1, kDepth = 2, kSemantic = 4, kInstance = 8 };
constexpr unsigned kLabelChannels = kDepth | kSemantic | kInstance;

struct RenderArgs {
    std::string city, size = "640x480", mode = "full", out, channels = "rgb,depth,semantic,instance", fov = "60";
    std::string sampling = "spread";
    int frames = 60;
    bool stats = false, quiet = false, restart = false;
    PathFlags path;
    ModeFlags modeFlags;
};

Result<unsigned> parseChannels(const std::string& s) {
    unsigned out = 0;
    size_t start = 0;
    while (start <= s.size()) {
        const size_t end = s.find(',', start);
        const std::string name = s.substr(start, end == std::string::npos ? std::string::npos : end - start);
        unsigned c = name == "rgb" ? kRgb : name == "depth" ? kDepth : name == "semantic" ? kSemantic : name == "instance" ? kInstance : 0;
        if (!c) return Status::error("--channels: unknown channel '" + name + "' (known: rgb, depth, semantic, instance)");
        if (out & c) return Status::error("--channels: channel '" + name + "' given twice");
        out |= c;
        if (end == std::string::npos) break;
        start = end + 1;
    }
    return out;
}

std::string frameName(size_t f) {
    char b[16];
    std::snprintf(b, sizeof b, "%06zu", f);
    return b;
}

// A frame's eye may stand this far outside the city square (streets run up
// to its border and a vehicle drives beside their centre line).
constexpr double kPathMargin = 50.0;

// World xy of every frame inside the city square (params.origin +- size/2) grown by kPathMargin.
Status checkPathInCity(const Path& path, const std::vector<size_t>& idx, const SceneModel& city) {
    const double half = 0.5 * city.params.size_m + kPathMargin;
    for (size_t f = 0; f < idx.size(); ++f) {
        const glm::dvec3& p = path.samples[idx[f]].position;
        const double x = p.x - city.params.origin_x, y = p.y - city.params.origin_y;
        if (!(std::abs(x) <= half && std::abs(y) <= half)) {
            char b[256];
            std::snprintf(b, sizeof b,
                          "path sample %zu (frame %zu) at city-frame (%.1f, %.1f) m lies outside the city square (+ 50 m) [-%.0f, %.0f] m",
                          idx[f], f, x, y, half, half);
            return Status::error(b);
        }
    }
    return Status::ok();
}

nlohmann::json classesJson() {
    nlohmann::json classes = nlohmann::json::array();
    for (int c = 0; c < kSemanticClassCount; ++c) {
        uint8_t rgb[3];
        semanticClassColor(SemanticClass(c), rgb);
        classes.push_back({{"id", c}, {"name", semanticClassName(SemanticClass(c))}, {"color", {rgb[0], rgb[1], rgb[2]}}});
    }
    nlohmann::json kinds = nlohmann::json::array();
    for (uint32_t k = 0; k < uint32_t(InstanceKind::Count); ++k)
        kinds.push_back({{"kind", k}, {"name", instanceKindName(InstanceKind(k))}});
    return {{"semantic_classes", classes},
            {"semantic_unknown", 255},
            {"instance_encoding", "id = kind << 28 | index (uint32); 0 = sky or terrain"},
            {"instance_kinds", kinds}};
}

// OpenCV camera-from-world (x right, y down, z forward) relative to `offset`.
nlohmann::json cameraFromWorld(const Camera& c, const glm::dvec3& offset) {
    const glm::dvec3 r = c.right(), d = -c.up(), f = c.forward(), e = c.eye - offset;
    const glm::dvec3 rows[3] = {r, d, f};
    nlohmann::json m = nlohmann::json::array();
    for (const auto& row : rows) m.push_back({row.x, row.y, row.z, -glm::dot(row, e)});
    m.push_back({0.0, 0.0, 0.0, 1.0});
    return m;
}

struct Timings {
    std::vector<double> rgb, labelRaster, labelRays, labels, writeRgb, writeDepth, writeSemantic, writeInstance, farPixels;
    // The frame's record in the work directory (its costs, measured when it was rendered).
    static nlohmann::json record(const Timings& t) {
        nlohmann::json r = nlohmann::json::object();
        auto put = [&](const char* k, const std::vector<double>& v) {
            if (!v.empty()) r[k] = v.back();
        };
        put("rgb", t.rgb), put("labels_raster_pass", t.labelRaster), put("labels_far_rays", t.labelRays);
        put("labels_total", t.labels), put("write_rgb", t.writeRgb), put("write_depth", t.writeDepth);
        put("write_semantic", t.writeSemantic), put("write_instance", t.writeInstance), put("far_label_pixels", t.farPixels);
        return r;
    }
    void add(const nlohmann::json& r) {
        auto get = [&](const char* k, std::vector<double>& v) {
            if (r.contains(k) && r[k].is_number()) v.push_back(r[k].get<double>());
        };
        get("rgb", rgb), get("labels_raster_pass", labelRaster), get("labels_far_rays", labelRays);
        get("labels_total", labels), get("write_rgb", writeRgb), get("write_depth", writeDepth);
        get("write_semantic", writeSemantic), get("write_instance", writeInstance), get("far_label_pixels", farPixels);
    }
};

// Content hash of a file's bytes (hex), streamed.
Result<std::string> fileHash(const std::string& path, uint64_t& bytes) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return Status::error("cannot read '" + path + "': " + errnoText());
    Hasher64 h;
    std::vector<unsigned char> buf(1 << 20);
    bytes = 0;
    size_t n;
    while ((n = std::fread(buf.data(), 1, buf.size(), f)) > 0) {
        h.update(buf.data(), n);
        bytes += n;
    }
    const bool bad = std::ferror(f) != 0;
    std::fclose(f);
    if (bad) return Status::error("cannot read '" + path + "': read error");
    return hex64(h.finish());
}

// Hash of the frames' camera poses (path index, time, eye, heading, pitch):
// whatever chose them (--path file, --seed/--kind/--duration/--run-up,
// --frames, --sampling), equal poses give equal frames.
std::string posesHash(const Path& path, const std::vector<size_t>& idx) {
    Hasher64 h;
    auto put = [&](uint64_t v) {
        unsigned char b[8];
        storeLE64(b, v);
        h.update(b, 8);
    };
    auto putD = [&](double d) {
        uint64_t v;
        std::memcpy(&v, &d, 8);
        put(v);
    };
    for (size_t i : idx) {
        const PathSample& s = path.samples[i];
        put(i);
        putD(s.t), putD(s.position.x), putD(s.position.y), putD(s.position.z), putD(s.heading), putD(s.pitch);
    }
    return hex64(h.finish());
}

std::string channelList(unsigned c) {
    std::string s;
    for (const auto& [bit, name] : {std::pair<unsigned, const char*>{kRgb, "rgb"}, {kDepth, "depth"}, {kSemantic, "semantic"}, {kInstance, "instance"}})
        if (c & bit) s += (s.empty() ? "" : ",") + std::string(name);
    return s;
}

std::string num(double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%.17g", v);
    return b;
}

// Test hook (docs/formats.md): VISTA_RENDER_KILL_AFTER_FRAMES=N makes the run
// kill itself with SIGKILL after it finished N frames, as an interruption would.
long killAfterFrames() {
    const char* e = std::getenv("VISTA_RENDER_KILL_AFTER_FRAMES");
    return e && *e ? std::atol(e) : 0;
}

nlohmann::json medianOf(const std::vector<double>& v) { return v.empty() ? nlohmann::json(nullptr) : nlohmann::json(median(v)); }

int run(RenderArgs& a, const std::string& command) {
    // ---- options -------------------------------------------------------------
    auto size = parseImageSize(a.size);
    if (!size) return reportBadInput(kCmd, size.status());
    auto fov = parseFov(a.fov);
    if (!fov) return reportBadInput(kCmd, fov.status());
    if (a.mode != "full" && a.mode != "hybrid")
        return reportBadInput(kCmd, Status::error("--mode '" + a.mode + "': ground truth is rendered in full or hybrid"));
    auto channels = parseChannels(a.channels);
    if (!channels) return reportBadInput(kCmd, channels.status());
    if (a.frames < 1 || a.frames > 1000000)
        return reportBadInput(kCmd, Status::error("--frames " + std::to_string(a.frames) + " out of range 1 .. 1000000"));
    auto sampling = parseSampling(a.sampling);
    if (!sampling) return reportBadInput(kCmd, sampling.status());
    ModeOptions mo;
    if (Status s = parseModeFlags(a.modeFlags, mo); !s) return reportBadInput(kCmd, s);
    mo.cacheAdaptive = false;  // ground truth: the cache never pauses on timings (frames stay deterministic)
    auto po = parsePathFlags(a.path);
    if (!po) return reportBadInput(kCmd, po.status());
    if (!fs::exists(a.city)) return reportBadInput(kCmd, Status::error("city file '" + a.city + "' does not exist"));
    RenderWorkDir out;
    if (Status s = out.checkOut(a.out); !s) return reportBadInput(kCmd, s);

    // ---- city, path ------------------------------------------------------------
    auto city = loadCityFile(a.city);
    if (!city) return reportBadInput(kCmd, city.status());
    const bool labels = (*channels & kLabelChannels) != 0;
    if ((*channels & (kSemantic | kInstance)) && !city->labelled)
        return reportBadInput(kCmd, Status::error("city file '" + a.city +
                                                  "' has no ground-truth labels (written by an older vista): regenerate the "
                                                  "city with this version (`vista gen`) for the semantic and instance channels"));
    auto path = walkthroughPath(a.path, *po, *city);
    if (!path) return reportBadInput(kCmd, path.status());
    if (path->samples.empty()) return reportBadInput(kCmd, Status::error("the walkthrough path has no samples"));
    const std::vector<size_t> idx = path->frames(size_t(a.frames), *sampling);
    if (Status s = checkPathInCity(*path, idx, *city); !s) return reportBadInput(kCmd, s);
    auto fx = runTimeEffects("", city->params.effects, true, kCmd);
    if (!fx) return reportBadInput(kCmd, fx.status());
    mo.effects = *fx;

    // ---- work directory: new, or the one of an interrupted run with the same parameters ----
    uint64_t cityBytes = 0;
    auto cityHash = fileHash(a.city, cityBytes);
    if (!cityHash) return reportBadInput(kCmd, cityHash.status());
    const nlohmann::json manifest = {
        {"city_hash", *cityHash}, {"city_bytes", cityBytes},
        {"frames", idx.size()}, {"camera_poses_hash", posesHash(*path, idx)},
        {"size", std::to_string(size->width) + "x" + std::to_string(size->height)}, {"fov_deg", num(*fov)},
        {"mode", a.mode}, {"channels", channelList(*channels)},
        {"near", num(mo.nearDistance)}, {"triangle_budget", mo.triangleBudget}, {"pixel_budget", mo.pixelBudget},
        {"horizon_grid", mo.horizonGrid}, {"cache", mo.cache}, {"cache_error_px", num(mo.cacheErrorPx)},
        {"frame_ms", num(mo.frameMsTarget)}, {"far_step", mo.farStep}};
    if (Status s = out.open(manifest, a.restart); !s) return reportBadInput(kCmd, s);
    for (const char* d : {"rgb", "depth", "semantic", "instance"}) {
        const unsigned c = std::string(d) == "rgb" ? kRgb : std::string(d) == "depth" ? kDepth : std::string(d) == "semantic" ? kSemantic : kInstance;
        if (*channels & c)
            if (Status s = out.subdir(d); !s) return reportBadInput(kCmd, s);
    }

    // ---- set up ------------------------------------------------------------------
    auto fail = [&](const Status& s) {
        std::fprintf(stderr, "%s: %s\n", kCmd, s.message().c_str());
        return 1;
    };
    auto renderer = OffscreenRenderer::create(size->width, size->height);
    if (!renderer) return fail(renderer.status());
    std::unique_ptr<RayScene> rays;
    ModeContext ctx;
    ctx.city = &city.value();
    ctx.scene = sceneRoot(*city);
    ctx.renderer = renderer->get();
    ctx.options = mo;
    ctx.labels = labels;
    if (findRenderMode(a.mode)->needsRays || effectsNeedRays(mo.effects)) {
        auto r = RayScene::build(*city);
        if (!r) return fail(Status::error("building the Embree ray scene failed: " + r.status().message()));
        rays = std::move(r.value());
        ctx.rays = rays.get();
    }
    auto mode = createRenderMode(a.mode, ctx);
    if (!mode) return fail(mode.status());
    const NearFieldScene& nf = ctx.nearField();
    osg::ref_ptr<osg::Group> labelRoot = new osg::Group;
    if (labels) labelRoot->setStateSet(nf.labelRootState.get());

    Camera base;
    base.width = size->width;
    base.height = size->height;
    base.fovY = degToRad(*fov);
    const glm::dvec3 offset(city->params.origin_x, city->params.origin_y, 0.0);
    const double fy = 0.5 * base.height / std::tan(0.5 * base.fovY);
    nlohmann::json frames = nlohmann::json::array();
    std::unique_ptr<Progress> progress;
    if (!a.quiet) progress = std::make_unique<StderrProgress>(isatty(2));
    // Finished frames (record and every channel file present) are kept. The
    // hybrid mode carries state from frame to frame (panoramic cache, adaptive
    // split): it re-renders the finished frames before the last missing one
    // (rgb only, nothing written) so that every frame it writes sees the state
    // of an uninterrupted run.
    std::vector<nlohmann::json> records(idx.size());
    long lastMissing = -1;
    size_t kept = 0;
    for (size_t f = 0; f < idx.size(); ++f) {
        if (out.resumed()) {
            records[f] = out.frameRecord(f);
            const std::string name = frameName(f);
            for (const auto& [bit, file] : {std::pair<unsigned, std::string>{kRgb, "rgb/" + name + ".png"}, {kDepth, "depth/" + name + ".npy"},
                                            {kSemantic, "semantic/" + name + ".png"}, {kInstance, "instance/" + name + ".npy"}})
                if (!records[f].is_null() && (*channels & bit) && !fs::exists(out.file(file))) records[f] = nullptr;
        }
        if (records[f].is_null())
            lastMissing = long(f);
        else
            ++kept;
    }
    const bool stateful = a.mode == "hybrid";
    const long killAfter = killAfterFrames();
    long finishedNow = 0;
    if (progress)
        progress->begin("render " + std::to_string(idx.size()) + " frames (" + a.mode + ")" +
                        (kept ? ", resuming: " + std::to_string(kept) + " done" : std::string()));

    // ---- frames ------------------------------------------------------------------
    Image img;
    LabelImage gt;
    LabelFrame raster;
    std::vector<uint32_t> far;
    for (size_t f = 0; f < idx.size(); ++f) {
        const Camera cam = path->camera(idx[f], base);
        const PathSample& ps = path->samples[idx[f]];
        frames.push_back({{"frame", f}, {"name", frameName(f)}, {"path_index", idx[f]}, {"t_s", ps.t},
                          {"eye_world", {ps.position.x, ps.position.y, ps.position.z}},
                          {"heading_deg", radToDeg(ps.heading)}, {"pitch_deg", radToDeg(ps.pitch)},
                          {"camera_from_world", cameraFromWorld(cam, offset)}});
        const bool done = !records[f].is_null();
        if (done && !(stateful && long(f) < lastMissing)) continue;
        FrameStats st;
        if (Status s = (*mode)->renderFrame(cam, img, st); !s) return fail(Status::error("frame " + std::to_string(f) + ": " + s.message()));
        if (done) {  // hybrid warm-up: the state, not the image
            if (progress) progress->update(double(f + 1) / double(idx.size()));
            continue;
        }
        Timings tm;
        tm.rgb.push_back(st.frameMs);
        const std::string name = frameName(f);
        if (labels) {
            const RasterSelection* sel = (*mode)->lastRaster();
            if (!sel) return fail(Status::error("mode " + a.mode + " reports no raster selection"));
            labelRoot->removeChildren(0, labelRoot->getNumChildren());
            for (uint32_t i : sel->chunks)
                if (i < nf.labelChunks.size()) labelRoot->addChild(nf.labelChunks[i].get());
            FrameStats ls;
            if (Status s = (*renderer)->renderLabels(labelRoot.get(), cam, sel->zFar, raster, ls); !s) return fail(s);
            tm.labelRaster.push_back(ls.frameMs);
            Stopwatch sw;
            gt.resize(cam.width, cam.height);
            far.clear();
            const PixelRays gen(cam);
            const glm::dvec3 fwd = cam.forward();
            for (int y = 0; y < cam.height; ++y)
                for (int x = 0; x < cam.width; ++x) {
                    const size_t p = size_t(y) * size_t(cam.width) + size_t(x);
                    const float z = raster.depth[p];
                    bool keep = z > 0.0f;
                    if (keep && sel->nearDistance < 1e299) keep = double(z) / glm::dot(gen.dir(x, y), fwd) <= sel->nearDistance;
                    if (keep) {
                        gt.ids[p] = raster.ids[p];
                        gt.classes[p] = raster.classes[p];
                        gt.depth[p] = z;
                    } else if (ctx.rays && (sel->nearDistance < 1e299 || a.mode == "hybrid")) {
                        far.push_back(uint32_t(p));
                    }
                }
            if (!far.empty()) castLabels(*city, *ctx.rays, cam, far, gt, mo.threads);
            tm.labelRays.push_back(sw.ms());
            tm.farPixels.push_back(double(far.size()));
            tm.labels.push_back(tm.labelRaster.back() + tm.labelRays.back());
        }
        // Writes (not part of the channel costs; timed apart).
        Stopwatch w;
        if (*channels & kRgb) {
            if (Status s = writePngRgb(img, out.file("rgb/" + name + ".png")); !s) return fail(s);
            tm.writeRgb.push_back(w.lap());
        }
        if (*channels & kDepth) {
            if (Status s = writeFileAtomic(out.file("depth/" + name + ".npy"), npyBytes(gt.depth.data(), gt.width, gt.height)); !s) return fail(s);
            tm.writeDepth.push_back(w.lap());
        }
        if (*channels & kSemantic) {
            if (Status s = writePngGray8(gt.classes, gt.width, gt.height, out.file("semantic/" + name + ".png")); !s) return fail(s);
            tm.writeSemantic.push_back(w.lap());
        }
        if (*channels & kInstance) {
            if (Status s = writeFileAtomic(out.file("instance/" + name + ".npy"), npyBytes(gt.ids.data(), gt.width, gt.height)); !s) return fail(s);
            tm.writeInstance.push_back(w.lap());
        }
        records[f] = Timings::record(tm);
        if (Status s = out.finishFrame(f, records[f]); !s) return fail(s);
        if (killAfter > 0 && ++finishedNow == killAfter) std::raise(SIGKILL);
        if (progress) progress->update(double(f + 1) / double(idx.size()));
    }
    if (progress) progress->end();
    Timings tm;  // every frame's, whichever run rendered it
    for (const auto& r : records) tm.add(r);

    // ---- metadata, commit ----------------------------------------------------------
    const nlohmann::json cameras = {
        {"convention",
         "OpenCV pinhole: camera x right, y down, z forward (optical axis); camera_from_world maps world points minus "
         "world_offset (metres, x east, y north, z up) to camera coordinates; pixel (u, v) has its centre at integer "
         "coordinates (u = column, v = row from the top), so cx = (width - 1) / 2"},
        {"width", base.width}, {"height", base.height},
        {"fx", fy}, {"fy", fy}, {"cx", 0.5 * (base.width - 1)}, {"cy", 0.5 * (base.height - 1)},
        {"fov_y_deg", *fov}, {"z_near_m", base.zNear},
        {"world_offset", {offset.x, offset.y, offset.z}},
        {"depth", "float32 metres along the optical axis (camera z), +inf = sky"},
        {"frames", frames}};
    const nlohmann::json summary = {
        {"command", command}, {"mode", a.mode}, {"frames", idx.size()}, {"width", base.width}, {"height", base.height},
        {"channels", a.channels}, {"gl_renderer", (*renderer)->glRenderer()},
        {"median_ms",
         {{"rgb", medianOf(tm.rgb)},
          {"labels_raster_pass", medianOf(tm.labelRaster)},
          {"labels_far_rays", medianOf(tm.labelRays)},
          {"labels_total", medianOf(tm.labels)},
          {"write_rgb", medianOf(tm.writeRgb)},
          {"write_depth", medianOf(tm.writeDepth)},
          {"write_semantic", medianOf(tm.writeSemantic)},
          {"write_instance", medianOf(tm.writeInstance)}}},
        {"median_far_label_pixels", medianOf(tm.farPixels)},
        {"frames_resumed", kept},
        {"note", "depth, semantic and instance come from one label pass (+ far-field rays in hybrid): their cost is "
                 "labels_total, shared; write_* is encoding and writing the files; medians over every frame, each timed "
                 "by the run that rendered it (frames_resumed: frames an interrupted run had finished)"}};
    for (const auto& [file, j] : {std::pair<const char*, const nlohmann::json*>{"cameras.json", &cameras},
                                  {"summary.json", &summary}}) {
        if (Status s = writeFileAtomic(out.file(file), j->dump(2) + "\n"); !s) return fail(s);
    }
    if (Status s = writeFileAtomic(out.file("classes.json"), classesJson().dump(2) + "\n"); !s) return fail(s);
    if (Status s = out.commit(); !s) return fail(s);
    if (a.stats || !a.quiet) {
        std::printf("%s: %zu frames, %s, %dx%d -> %s\n", kCmd, idx.size(), a.mode.c_str(), base.width, base.height, out.outPath().c_str());
        if (a.stats) {
            auto p = [](const char* what, const std::vector<double>& v) {
                if (!v.empty()) std::printf("  %-22s %8.2f ms (median)\n", what, median(v));
            };
            p("rgb (mode frame)", tm.rgb);
            p("labels: raster pass", tm.labelRaster);
            p("labels: far rays", tm.labelRays);
            p("labels: total", tm.labels);
            p("write rgb", tm.writeRgb);
            p("write depth", tm.writeDepth);
            p("write semantic", tm.writeSemantic);
            p("write instance", tm.writeInstance);
        }
    }
    return 0;
}

}  // namespace

int runRender(int argc, char** argv) {
    CLI::App app{"Ground truth per frame of a walkthrough: rgb, metric depth, semantic classes, instance ids, "
                 "cameras.json and classes.json (docs/formats.md).",
                 kCmd};
    RenderArgs a;
    app.add_option("city", a.city, "city scene file (.osgb) from `vista gen`")->required();
    addPathFlags(app, a.path, true);
    app.add_option("--frames", a.frames, "frames rendered, 1 .. 1000000 (default 60)");
    app.add_option("--sampling", a.sampling, "which path samples are the frames: spread (default), consecutive or runs:K");
    app.add_option("--size", a.size, "image size WIDTHxHEIGHT, 1x1 .. 8192x8192 (default 640x480)");
    app.add_option("--fov", a.fov, "vertical field of view in degrees, (1, 179) (default 60)");
    app.add_option("--mode", a.mode, "render mode: full (every triangle rasterised) or hybrid (near field + ray-cast far field) (default full)");
    app.add_option("--channels", a.channels, "comma-separated channels: rgb, depth, semantic, instance (default all)");
    addModeFlags(app, a.modeFlags);
    app.add_option("--out", a.out, "output directory (must not exist or be empty; its parent must exist); work goes into "
                                    "OUT.partial and a rerun of the same command resumes it")->required();
    app.add_flag("--restart", a.restart, "discard the work directory (OUT.partial) of an interrupted run and start over");
    app.add_flag("--stats", a.stats, "print the median per-channel costs (also in OUT/summary.json)");
    app.add_flag("-q,--quiet", a.quiet, "no progress on stderr");
    if (int rc = parseOrExit(app, argc, argv); rc >= 0) return rc;
    std::string command = kCmd;
    for (int i = 1; i < argc; ++i) command += std::string(" ") + argv[i];
    return run(a, command);
}

}  // namespace vista
