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
//
// A paged city (DIR.paged) is streamed (the default, as in `vista bench`:
// cmd/paged_stream.h): the mode's graph, its ray scene and the label pass's
// twin follow the camera, loaded on a worker thread, and every frame waits
// for the regions within reach of its camera, so its files are those of a
// preloaded run of the same regions and a resumed run writes the same bytes
// (--paged-stream: a stream whose frames do not wait). --paged-preload, or a
// run that cannot stream (hybrid with label channels), loads the regions
// around the whole path before the first frame instead. Instance ids
// of a paged city are numbered per region (docs/formats.md "Paged city"): the
// instance channel is not written for one.
//
// Past one machine (docs/formats.md "Shards", "Dataset manifest"): --shard K/N
// renders a contiguous block of the frames (shardRange) into OUT.shards/K-of-N
// with a record of its inputs and files (cmd/render_shards.h); hybrid first
// renders the frames before its block without writing them, as a resume does.
// --merge --shards N checks every shard and writes OUT. --dataset M.json
// renders a drive per (city, path, rig) of a dataset manifest
// (runtime/scene/dataset_manifest.h), sharded by whole drives.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
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
#include "cmd/memory.h"
#include "cmd/options.h"
#include "cmd/paged_stream.h"
#include "cmd/render_rig.h"
#include "cmd/render_shards.h"
#include "cmd/render_shared.h"
#include "cmd/render_work_dir.h"
#include "foundation/atomic_file.h"
#include "foundation/format.h"
#include "foundation/hash.h"
#include "foundation/number_text.h"
#include "foundation/progress.h"
#include "foundation/shard.h"
#include "foundation/statistics.h"
#include "foundation/timing.h"
#include "foundation/units.h"
#include "nodes/render/city_stream.h"
#include "nodes/render/ground_truth_session.h"
#include "nodes/render/offscreen.h"
#include "nodes/render/traffic_scene.h"
#include "runtime/engine/ground_truth.h"
#include "runtime/engine/ray_scene.h"
#include "nodes/render/walkthrough.h"
#include "runtime/scene/dataset_manifest.h"
#include "runtime/scene/paged_load.h"
#include "runtime/scene/paths.h"
#include "runtime/engine/rig.h"
#include "runtime/engine/traffic_light_labels.h"
#include "runtime/traffic/signal_states.h"
#include "runtime/scene/scene_graph.h"

namespace vista {

namespace {

namespace fs = std::filesystem;
const char* const kCmd = "vista render";

enum Channel : unsigned { kRgb = 1, kDepth = 2, kSemantic = 4, kInstance = 8 };
// Not a channel one asks for: the traffic-light labels a run with --traffic
// writes beside the instance channel (RenderPlan::written).
constexpr unsigned kTrafficLights = 16;
constexpr unsigned kLabelChannels = kDepth | kSemantic | kInstance;
// The output folder of each channel, in output order.
const std::pair<unsigned, const char*> kChannelDirs[] = {
    {kRgb, "rgb"}, {kDepth, "depth"}, {kSemantic, "semantic"}, {kInstance, "instance"}};

struct RenderArgs {
    std::string city, size = "640x480", mode = "full", out, channels = "rgb,depth,semantic,instance";
    std::string sampling = "spread", rig;
    int frames = 60;
    double fov = 60, memoryBudgetGb = 0;
    bool repeats = false;  // --allow-repeated-frames
    bool stats = false, quiet = false, restart = false, channelsGiven = false;
    // --shard K/N: this run renders frames shardRange(frames, shard) into
    // shardDir(out, shard); --merge --shards N assembles the N shards into out.
    std::string shard;
    std::optional<int> shards;
    bool merge = false;
    std::string dataset;  // --dataset M.json
    PathFlags path;
    ModeFlags modeFlags;
    PagedReach paged;
    PagedStreamFlags stream;
};

Result<unsigned> parseChannels(const std::string& s) {
    unsigned out = 0;
    size_t start = 0;
    while (start <= s.size()) {
        const size_t end = s.find(',', start);
        const std::string name = s.substr(start, end == std::string::npos ? std::string::npos : end - start);
        unsigned c = name == "rgb"        ? kRgb
                     : name == "depth"    ? kDepth
                     : name == "semantic" ? kSemantic
                     : name == "instance" ? kInstance
                                          : Channel{0};
        if (!c)
            return Status::error("--channels: unknown channel '" + name + "' (known: rgb, depth, semantic, instance)");
        if (out & c) return Status::error("--channels: channel '" + name + "' given twice");
        out |= c;
        if (end == std::string::npos) break;
        start = end + 1;
    }
    return out;
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
    std::vector<double> rgb, labelRaster, labelRays, labels, writeRgb, writeDepth, writeSemantic, writeInstance,
        farPixels;
    // The frame's record in the work directory (its costs, measured when it was rendered).
    static nlohmann::json record(const Timings& t) {
        nlohmann::json r = nlohmann::json::object();
        auto put = [&](const char* k, const std::vector<double>& v) {
            if (!v.empty()) r[k] = v.back();
        };
        put("rgb", t.rgb), put("labels_raster_pass", t.labelRaster), put("labels_far_rays", t.labelRays);
        put("labels_total", t.labels), put("write_rgb", t.writeRgb), put("write_depth", t.writeDepth);
        put("write_semantic", t.writeSemantic), put("write_instance", t.writeInstance),
            put("far_label_pixels", t.farPixels);
        return r;
    }
    // summary.json's median_ms.
    static nlohmann::json medians(const Timings& t) {
        return {{"rgb", medianOf(t.rgb)},
                {"labels_raster_pass", medianOf(t.labelRaster)},
                {"labels_far_rays", medianOf(t.labelRays)},
                {"labels_total", medianOf(t.labels)},
                {"write_rgb", medianOf(t.writeRgb)},
                {"write_depth", medianOf(t.writeDepth)},
                {"write_semantic", medianOf(t.writeSemantic)},
                {"write_instance", medianOf(t.writeInstance)}};
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

std::string channelList(unsigned c) {
    std::string s;
    for (const auto& [bit, name] : {std::pair<unsigned, const char*>{kRgb, "rgb"},
                                    {kDepth, "depth"},
                                    {kSemantic, "semantic"},
                                    {kInstance, "instance"}})
        if (c & bit) s += (s.empty() ? "" : ",") + std::string(name);
    return s;
}

// The parsed options of a run.
struct RenderPlan {
    ImageSize size;
    double fovDeg = 0;
    unsigned channels = 0;
    int sampleRuns = 0;
    ModeOptions options;
    PathOptions path;
    bool paged = false;                            // the city is a paged city directory
    bool streamed = false;                         // a streamed paged city (choosePagedStream)
    bool rays = false;                             // the mode casts rays (the memory estimate's ray scene)
    double estimateMb = 0;                         // the memory estimate before the first frame
    double memoryBudgetGb = 0;                     // --memory-budget (0 = none)
    RegionPagerOptions stream;                     // streamed
    CommandFiles files;                            // checked by configure; holds the output's lock for the run
    std::optional<Shard> shard;                    // --shard K/N
    std::string outDir;                            // where this run publishes: --out, or the shard's directory
    std::shared_ptr<const TrafficTracks> traffic;  // --traffic (null: none)
    bool labels() const { return (channels & kLabelChannels) != 0; }
    // The files each frame writes: the channels, and traffic_lights/ when
    // the instance channel is written with traffic that recorded its lights.
    unsigned written() const {
        return channels | ((channels & kInstance) && traffic && traffic->signals ? kTrafficLights : 0u);
    }
};

// The paged-city options: streaming only for a paged city and a mode that
// streams; no instance channel (ids are numbered per region), which the
// default channels then leave out.
Status configurePaged(const RenderArgs& a, RenderPlan& p) {
    VISTA_RETURN_IF_ERROR(validatePagedReach(a.paged));
    PagedStreamFlags stream = a.stream;
    VISTA_RETURN_IF_ERROR(validatePagedStream(stream));
    p.paged = isPagedCityPath(a.city);
    // Over a streamed city the label pass draws the stream's label twin of the
    // whole city; far-field ray labels would need the regions' models.
    std::string cannotStream;
    if (Status modes = checkStreamingModes({a.mode}); !modes) cannotStream = modes.message();
    else if ((p.channels & kLabelChannels) && a.mode != "full")
        cannotStream =
            "the depth, semantic and instance channels of a streamed city come from mode full (the far "
            "field of mode " +
            a.mode + " is labelled from the whole loaded city); give --channels rgb or --mode full";
    auto streamed = choosePagedStream(kCmd, stream, a.city, cannotStream, a.quiet);
    if (!streamed) return streamed.status();
    p.streamed = *streamed;
    if (!p.paged || !(p.channels & kInstance)) return Status::ok();
    if (a.channelsGiven)
        return Status::error(
            "--channels: instance is not available for a paged city: its instance ids are numbered "
            "per region (give rgb, depth, semantic)");
    p.channels &= ~unsigned(kInstance);
    if (!a.quiet)
        std::fprintf(stderr, "%s: paged city: channels rgb, depth, semantic (instance ids are numbered per region)\n",
                     kCmd);
    return Status::ok();
}

// Every option checked before anything is loaded; errors name the flag.
Status configure(const RenderArgs& a, RenderPlan& p) {
    auto size = parseImageSize(a.size);
    if (!size) return size.status();
    p.size = *size;
    VISTA_RETURN_IF_ERROR(checkFov(a.fov));
    p.fovDeg = a.fov;
    if (a.mode != "full" && a.mode != "hybrid")
        return Status::error("--mode '" + a.mode + "': ground truth is rendered in full or hybrid");
    auto channels = parseChannels(a.channels);
    if (!channels) return channels.status();
    p.channels = *channels;
    if (a.frames < 1 || a.frames > 1000000)
        return Status::error("--frames " + std::to_string(a.frames) + " out of range 1 .. 1000000");
    auto sampling = parseSampling(a.sampling);
    if (!sampling) return sampling.status();
    p.sampleRuns = *sampling;
    VISTA_RETURN_IF_ERROR(parseModeFlags(a.modeFlags, p.options));
    // Ground truth follows no timing, so that a rerun or a resumed run writes the same bytes: the
    // cache and the horizon never pause on measured times, and the hybrid's split is fixed (--near auto draws at
    // the default near distance instead of choosing per frame from measured costs).
    p.options.cacheAdaptive = false;
    p.options.horizonAdaptive = false;
    if (p.options.nearDistance < 0) p.options.nearDistance = kDefaultNearDistance;
    auto po = parsePathFlags(a.path);
    if (!po) return po.status();
    p.path = *po;
    p.outDir = a.out;
    if (!a.shard.empty()) {
        auto sh = parseShard("--shard", a.shard);
        if (!sh) return sh.status();
        p.shard = *sh;
        VISTA_RETURN_IF_ERROR(RenderWorkDir::checkParent(a.out));
        p.outDir = shardDir(a.out, *sh);
    }
    // A shard's directory sits in OUT.shards, which the first shard creates.
    VISTA_RETURN_IF_ERROR(
        checkRunFiles(p.files.outputDirectory("--out", p.outDir, !p.shard), a.city, a.path, a.modeFlags));
    VISTA_RETURN_IF_ERROR(configurePaged(a, p));
    auto tracks = loadTrafficFlag(a.modeFlags.traffic);
    if (!tracks) return tracks.status();
    p.traffic = *tracks;
    p.rays = findRenderMode(a.mode)->needsRays;
    if (p.paged) return Status::ok();  // estimated on the selected regions' bytes (loadCityAndFrames)
    std::error_code ec;
    const uint64_t bytes = fs::file_size(a.city, ec);
    if (ec) return Status::ok();
    p.estimateMb = estimateCityRunMb(bytes, p.rays);
    return checkMemoryBudget("--memory-budget", a.memoryBudgetGb, p.estimateMb, bytes, p.rays);
}

// The city (labelled when a label channel needs it), the walkthrough and the
// path indices of the frames (`idx`), each frame inside the city.
Result<Walkthrough> loadCityAndFrames(const RenderArgs& a, RenderPlan& p, std::vector<size_t>& idx) {
    const std::string labelsFor = (p.channels & (kSemantic | kInstance)) ? "the semantic and instance channels" : "";
    WalkthroughRequest req =
        renderRequest(a.city, a.path.file, p.path, a.frames, p.sampleRuns, a.repeats, labelsFor, idx);
    req.bakedModes = {a.mode};
    req.effects = [](const Effects& declared) { return runTimeEffects(std::nullopt, declared, true, kCmd); };
    if (p.paged) {
        // The regions' files carry the labels; the merged model (or the
        // streamed stub) is unlabelled by construction (paged_load.h).
        req.allowPaged = true;
        req.quiet = a.quiet;
        req.paged = a.paged;
        req.streamPaged = p.streamed;
        req.checkCity = nullptr;
        req.beforePagedLoad = [&a, &p](uint64_t bytes) {
            p.estimateMb = estimateCityRunMb(bytes, p.rays);
            return checkMemoryBudget("--memory-budget", a.memoryBudgetGb, p.estimateMb, bytes, p.rays);
        };
    }
    auto w = loadWalkthrough(req, p.options);
    if (!w || !p.streamed) return w;
    // Ground truth follows no load timing: unless --paged-stream asks for a stream that does not
    // wait, every frame waits for the regions within reach of its camera.
    PagedStreamFlags flags = a.stream;
    if (!flags.stream) flags.wait = true;
    auto so = pagedStreamOptions(a.paged, flags, a.memoryBudgetGb, p.estimateMb);
    if (!so) return so.status();
    p.stream = *so;
    p.memoryBudgetGb = a.memoryBudgetGb;
    if (!a.quiet) notePagedStream(kCmd, *w->manifest, p.stream);
    return w;
}

// The content hash of the city: its file's bytes, or for a paged city its
// manifest's (which holds every region file's size and content hash).
Result<std::string> cityHash(const std::string& city, bool paged, uint64_t& bytes) {
    return fileHash(paged ? (fs::path(city) / "manifest.json").string() : city, bytes);
}

// The path without loading the city: the --path file's content hash, or the
// flags that make the path on the city's streets. A merge compares it (with
// the city's hash, --frames and --sampling) to the shards' inputs, so a shard
// rendered along another path is refused.
Result<std::string> pathInput(const RenderArgs& a) {
    std::string path;
    if (!a.path.file.empty()) {
        uint64_t bytes = 0;
        auto h = fileHash(a.path.file, bytes);
        if (!h) return Status::error("--path: " + h.status().message());
        path = "file " + *h;
    } else {
        const PathFlags& f = a.path;
        path = "seed " + std::to_string(f.seed) + ", kind " + f.kind + ", route " + f.route + ", duration " +
               manifestNumber(f.duration) + ", run-up " + manifestNumber(f.runUp) + (f.lht ? ", lht" : "");
    }
    return path;
}

// What decides the bytes, from the arguments alone: the city's content, the
// path (pathInput) and the frames taken from it, every option that changes a pixel, the traffic's tracks
// and lamps, and for a paged city the reach of a frame. The work directory's
// manifest adds the frames' count and poses; a merge compares this with the
// shards' inputs.
Result<nlohmann::json> runInputs(const RenderArgs& a, const RenderPlan& p) {
    const ModeOptions& mo = p.options;
    nlohmann::json manifest = {{"size", std::to_string(p.size.width) + "x" + std::to_string(p.size.height)},
                               {"fov_deg", manifestNumber(p.fovDeg)},
                               {"mode", a.mode},
                               {"channels", channelList(p.channels)},
                               {"near", manifestNumber(mo.nearDistance)},
                               {"triangle_budget", mo.triangleBudget},
                               {"pixel_budget", mo.pixelBudget},
                               {"horizon_grid", mo.horizonGrid},
                               {"cache", mo.cache},
                               {"cache_error_px", manifestNumber(mo.cacheErrorPx)},
                               {"frame_ms", manifestNumber(mo.frameMsTarget)},
                               {"far_step", mo.farStep}};
    if (p.traffic) {
        // The agents' poses and the heads' lamps decide pixels: a resumed run must draw the same traffic.
        auto traffic = trafficHash(*p.traffic, a.modeFlags.traffic);
        if (!traffic) return traffic.status();
        manifest["traffic_hash"] = *traffic;
    }
    uint64_t cityBytes = 0;
    auto hash = cityHash(a.city, p.paged, cityBytes);
    if (!hash) return hash.status();
    manifest["city_hash"] = *hash;
    manifest["city_bytes"] = cityBytes;
    auto path = pathInput(a);
    if (!path) return path.status();
    manifest["path"] = *path;
    manifest["sampling"] = std::to_string(a.frames) + " frames, " + a.sampling;
    if (p.paged) {
        // What decides the regions a frame sees.
        const bool streamed = p.streamed;
        manifest["paged"] = {{"radius", manifestNumber(a.paged.radius)},
                             {"far", manifestNumber(a.paged.far)},
                             {"stream", streamed},
                             {"wait", streamed && p.stream.wait},
                             {"prefetch", manifestNumber(streamed ? p.stream.prefetchS : 0.0)},
                             {"budget_bytes", streamed ? p.stream.budgetBytes : 0}};
    }
    return manifest;
}

// The work directory: new, or the one of an interrupted run with the same
// parameters (the manifest: runInputs, the frames' count and camera poses; a
// shard's K/N), with a folder per channel. `inputs` receives the manifest
// without the shard (a shard's record carries it).
Status openWorkDir(const RenderArgs& a, const RenderPlan& p, const Path& path, const std::vector<size_t>& idx,
                   RenderWorkDir& out, nlohmann::json& inputs) {
    auto run = runInputs(a, p);
    if (!run) return run.status();
    nlohmann::json manifest = std::move(*run);
    manifest["frames"] = idx.size();
    manifest["camera_poses_hash"] = posesHash(path, idx);
    inputs = manifest;
    if (p.shard) manifest["shard"] = shardText(*p.shard);
    VISTA_RETURN_IF_ERROR(out.open(manifest, a.restart));
    for (const auto& [bit, dir] : kChannelDirs)
        if (p.channels & bit) VISTA_RETURN_IF_ERROR(out.subdir(dir));
    if (p.written() & kTrafficLights) VISTA_RETURN_IF_ERROR(out.subdir("traffic_lights"));
    return Status::ok();
}

// What the frames are drawn with (nodes/render/ground_truth_session.h) and
// what the frames saw of the stream of a paged city.
struct RenderSession {
    GroundTruthSession gt;
    int framesWithArrivals = 0;        // streamed: frames before which region levels arrived
    StreamDetail detail;               // streamed: frames that drew a region below the detail asked for
    std::vector<std::string> damaged;  // streamed: region files that failed to load
};

Status setUp(const std::string& modeName, const RenderPlan& p, const Walkthrough& w, RenderSession& s) {
    GroundTruthSetup g;
    g.mode = modeName;
    g.width = p.size.width;
    g.height = p.size.height;
    g.options = p.options;
    g.labels = p.labels();
    if (p.streamed) {
        g.streamed = w.manifest.get();
        g.stream = p.stream;
        const double budgetGb = p.memoryBudgetGb;
        g.streamReady = [budgetGb](CityStream& stream) { holdStreamUnder(stream, budgetGb); };
    }
    g.traffic = p.traffic;
    g.paged = w.manifest.get();
    return s.gt.setUp(g, w.city);
}

// A streamed city follows the camera of path sample i (the first frame, and
// every frame with --paged-wait, waits for the regions within its reach).
Status advanceStream(RenderSession& s, const Path& path, size_t i, const Camera& cam, bool first) {
    if (!s.gt.stream) return Status::ok();
    auto f = advancePagedStream(*s.gt.stream, kCmd, cam.eye, pathVelocity(path, i), &s.damaged, first);
    if (!f) return f.status();
    s.framesWithArrivals += f->arrived > 0 ? 1 : 0;
    s.detail.add(*f, path.samples[i].t);
    // A mode that caches what it traced (hybrid's panoramic cache) drops it when regions change.
    if ((f->arrived > 0 || f->dropped > 0) && s.gt.mode) s.gt.mode->sceneChanged(f->changed);
    return Status::ok();
}

// Frames an interrupted run finished (their record, and every channel file
// with the size and content hash the record gives) are kept; a damaged one is
// rendered again. The hybrid mode carries state from frame to frame
// (panoramic cache, adaptive split): it re-renders the finished frames before
// the last missing one (rgb only, nothing written) so that every frame it
// writes sees the state of an uninterrupted run.
struct Progressed {
    std::vector<nlohmann::json> records;  // per frame; null = still to render
    long lastMissing = -1;
    size_t kept = 0;
};

// The files of frame `name` for `channels`, relative to the output.
std::vector<std::string> frameFiles(unsigned channels, const std::string& name) {
    std::vector<std::string> files;
    for (const auto& [bit, file] : {std::pair<unsigned, std::string>{kRgb, "rgb/" + name + ".png"},
                                    {kDepth, "depth/" + name + ".npy"},
                                    {kSemantic, "semantic/" + name + ".png"},
                                    {kInstance, "instance/" + name + ".npy"},
                                    {kTrafficLights, "traffic_lights/" + name + ".txt"}})
        if (channels & bit) files.push_back(file);
    return files;
}

// A finished frame is kept only when its files still have the sizes and hashes its record gives.
// Frames outside `range` (another shard's) stay null and are not missing.
Progressed finishedFrames(const RenderWorkDir& out, unsigned channels, size_t frames, ShardRange range) {
    Progressed r;
    r.records.resize(frames);
    for (size_t f = range.begin; f < range.end; ++f) {
        if (out.resumed()) {
            r.records[f] = out.frameRecord(f);
            if (!r.records[f].is_null() && !out.frameIntact(r.records[f], frameFiles(channels, frameName(f))))
                r.records[f] = nullptr;
        }
        if (r.records[f].is_null()) r.lastMissing = long(f);
        else ++r.kept;
    }
    return r;
}

// The camera of every frame: the path's pose at the plan's size and field of view.
Camera baseCamera(const RenderPlan& p) {
    Camera base;
    base.width = p.size.width;
    base.height = p.size.height;
    base.fovY = degToRad(p.fovDeg);
    return base;
}

using FrameBuffers = GroundTruthBuffers;

// The labels of the frame the mode just rendered (GroundTruthSession::renderLabels). Costs into `tm`.
Status frameLabels(const Camera& cam, int threads, RenderSession& s, FrameBuffers& b, Timings& tm) {
    LabelCosts c;
    VISTA_RETURN_IF_ERROR(s.gt.renderLabels(cam, threads, b, c));
    tm.labelRaster.push_back(c.rasterMs);
    tm.labelRays.push_back(c.raysMs);
    tm.farPixels.push_back(double(c.farPixels));
    tm.labels.push_back(c.rasterMs + c.raysMs);
    return Status::ok();
}

// The frame's channel files, each written atomically (costs into `tm`,
// apart from the channel costs).
Status writeFrameFiles(unsigned channels, const std::string& name, const FrameBuffers& b, const RenderWorkDir& out,
                       Timings& tm) {
    Stopwatch w;
    if (channels & kRgb) {
        VISTA_RETURN_IF_ERROR(writePngRgb(b.img, out.file("rgb/" + name + ".png")));
        tm.writeRgb.push_back(w.lap());
    }
    const LabelImage& gt = b.gt;
    if (channels & kDepth) {
        VISTA_RETURN_IF_ERROR(
            writeFileAtomic(out.file("depth/" + name + ".npy"), npyBytes(gt.depth.data(), gt.width, gt.height)));
        tm.writeDepth.push_back(w.lap());
    }
    if (channels & kSemantic) {
        VISTA_RETURN_IF_ERROR(writePngGray8(gt.classes, gt.width, gt.height, out.file("semantic/" + name + ".png")));
        tm.writeSemantic.push_back(w.lap());
    }
    if (channels & kInstance) {
        VISTA_RETURN_IF_ERROR(
            writeFileAtomic(out.file("instance/" + name + ".npy"), npyBytes(gt.ids.data(), gt.width, gt.height)));
        tm.writeInstance.push_back(w.lap());
    }
    return Status::ok();
}

// The frame's traffic-light labels (traffic_light_labels.h) from its
// instance image: each head's lamp at the frame's time `t`.
Status writeTrafficLights(const RenderPlan& p, const std::string& name, const LabelImage& gt, double t,
                          const RenderWorkDir& out) {
    const SignalStates& lamps = *p.traffic->signals;
    auto lamp = [&](uint32_t head) { return std::string(lampStateName(lamps.lampAt(head, t))); };
    return writeFileAtomic(out.file("traffic_lights/" + name + ".txt"),
                           trafficLightLabels(trafficLightBoxes(gt.ids, gt.width, gt.height), lamp));
}

// Renders every frame still missing (and hybrid's warm-up frames), writes
// its files and record; `frames` receives every frame's camera entry of
// cameras.json.
// A shard writes the frames of `range` only; hybrid renders the frames before
// it too (its warm-up), so that its cache holds what one whole run's held.
Status renderFrames(const RenderArgs& a, const RenderPlan& p, const Walkthrough& w, const std::vector<size_t>& idx,
                    ShardRange range, RenderSession& s, RenderWorkDir& out, Progressed& done, nlohmann::json& frames) {
    std::unique_ptr<Progress> progress;
    if (!a.quiet) progress = std::make_unique<StderrProgress>(isatty(2));
    const bool stateful = a.mode == "hybrid";
    const long killAfter = killAfterFrames();
    long finishedNow = 0;
    if (progress)
        progress->begin("render " + std::to_string(idx.size()) + " frames (" + a.mode + ")" +
                        (done.kept ? ", resuming: " + std::to_string(done.kept) + " done" : std::string()));
    const Camera base = baseCamera(p);
    const glm::dvec3 offset(w.city.params.origin_x, w.city.params.origin_y, 0.0);
    FrameBuffers b;
    bool streamStarted = false;
    for (size_t f = 0; f < idx.size(); ++f) {
        const Camera cam = w.path.camera(idx[f], base);
        const PathSample& ps = w.path.samples[idx[f]];
        frames.push_back({{"frame", f},
                          {"name", frameName(f)},
                          {"path_index", idx[f]},
                          {"t_s", ps.t},
                          {"eye_world", {ps.position.x, ps.position.y, ps.position.z}},
                          {"heading_deg", radToDeg(ps.heading)},
                          {"pitch_deg", radToDeg(ps.pitch)},
                          {"camera_from_world", cameraFromWorld(cam, offset)}});
        const bool finished = !range.contains(f) || !done.records[f].is_null();
        if (finished && !(stateful && long(f) < done.lastMissing)) continue;
        FrameStats st;
        VISTA_RETURN_IF_ERROR(advanceStream(s, w.path, idx[f], cam, !streamStarted));
        streamStarted = true;
        if (Status e = s.gt.renderFrame(cam, b, st); !e)
            return Status::error("frame " + std::to_string(f) + ": " + e.message());
        if (finished) {  // hybrid warm-up: the state, not the image
            if (progress) progress->update(double(f + 1) / double(idx.size()));
            continue;
        }
        Timings tm;
        tm.rgb.push_back(st.frameMs);
        if (p.labels()) VISTA_RETURN_IF_ERROR(frameLabels(cam, p.options.threads, s, b, tm));
        VISTA_RETURN_IF_ERROR(writeFrameFiles(p.channels, frameName(f), b, out, tm));
        if (p.written() & kTrafficLights) VISTA_RETURN_IF_ERROR(writeTrafficLights(p, frameName(f), b.gt, ps.t, out));
        done.records[f] = Timings::record(tm);
        VISTA_RETURN_IF_ERROR(out.finishFrame(f, done.records[f], frameFiles(p.written(), frameName(f))));
        if (killAfter > 0 && ++finishedNow == killAfter) std::raise(SIGKILL);
        if (progress) progress->update(double(f + 1) / double(idx.size()));
    }
    if (progress) progress->end();
    return Status::ok();
}

// cameras.json, summary.json and classes.json (every shard writes the
// cameras of every frame).
Status writeMetadata(const RenderArgs& a, const RenderPlan& p, const std::string& command, const SceneModel& city,
                     const std::vector<size_t>& idx, const nlohmann::json& frames, const Timings& tm, size_t kept,
                     const nlohmann::json& paged, const OffscreenRenderer& renderer, RenderWorkDir& out) {
    const Camera base = baseCamera(p);
    const glm::dvec3 offset(city.params.origin_x, city.params.origin_y, 0.0);
    const double fy = 0.5 * base.height / std::tan(0.5 * base.fovY);
    const nlohmann::json cameras = {
        {"convention",
         "OpenCV pinhole: camera x right, y down, z forward (optical axis); camera_from_world maps world points minus "
         "world_offset (metres, x east, y north, z up) to camera coordinates; pixel (u, v) has its centre at integer "
         "coordinates (u = column, v = row from the top), so cx = (width - 1) / 2"},
        {"width", base.width},
        {"height", base.height},
        {"fx", fy},
        {"fy", fy},
        {"cx", 0.5 * (base.width - 1)},
        {"cy", 0.5 * (base.height - 1)},
        {"fov_y_deg", p.fovDeg},
        {"z_near_m", base.zNear},
        {"world_offset", {offset.x, offset.y, offset.z}},
        {"depth", "float32 metres along the optical axis (camera z), +inf = sky"},
        {"frames", frames}};
    nlohmann::json summary = {
        {"command", command},
        {"mode", a.mode},
        {"frames", idx.size()},
        {"width", base.width},
        {"height", base.height},
        {"channels", channelList(p.channels)},
        {"gl_renderer", renderer.glRenderer()},
        {"median_ms", Timings::medians(tm)},
        {"median_far_label_pixels", medianOf(tm.farPixels)},
        {"frames_resumed", kept},
        {"note",
         "depth, semantic and instance come from one label pass (+ far-field rays in hybrid): their cost is "
         "labels_total, shared; write_* is encoding and writing the files; medians over every frame, each timed "
         "by the run that rendered it (frames_resumed: frames an interrupted run had finished)"}};
    if (!paged.is_null()) summary["paged"] = paged;
    for (const auto& [file, j] :
         {std::pair<const char*, const nlohmann::json*>{"cameras.json", &cameras}, {"summary.json", &summary}}) {
        VISTA_RETURN_IF_ERROR(writeFileAtomic(out.file(file), j->dump(2) + "\n"));
    }
    VISTA_RETURN_IF_ERROR(writeFileAtomic(out.file("classes.json"), classesJson().dump(2) + "\n"));
    return Status::ok();
}

void printResult(const RenderArgs& a, const RenderPlan& p, size_t frames, const Timings& tm, const RenderWorkDir& out) {
    if (!a.stats && a.quiet) return;
    std::printf("%s: %zu frames, %s, %dx%d -> %s\n", kCmd, frames, a.mode.c_str(), p.size.width, p.size.height,
                out.outPath().c_str());
    if (!a.stats) return;
    auto line = [](const char* what, const std::vector<double>& v) {
        if (!v.empty()) std::printf("  %-22s %8.2f ms (median)\n", what, median(v));
    };
    line("rgb (mode frame)", tm.rgb);
    line("labels: raster pass", tm.labelRaster);
    line("labels: far rays", tm.labelRays);
    line("labels: total", tm.labels);
    line("write rgb", tm.writeRgb);
    line("write depth", tm.writeDepth);
    line("write semantic", tm.writeSemantic);
    line("write instance", tm.writeInstance);
}

// A shard's directory that is already published: true (nothing to do) when
// its record checks; a damaged one, or any with --restart, is removed and
// rendered again. A directory without a record is left to checkOut.
Result<bool> publishedShard(const std::string& dir, const Shard& shard, bool restart, bool quiet) {
    std::error_code ec;
    if (!fs::exists(fs::path(dir) / kShardRecordFile, ec)) return false;
    auto r = readShardRecord(dir, shard);
    if (r && !restart) return true;
    if (!quiet)
        std::fprintf(stderr, "%s: shard %s in '%s': %s; rendering it again\n", kCmd, shardText(shard).c_str(),
                     dir.c_str(), r ? "--restart" : r.status().message().c_str());
    fs::remove_all(dir, ec);
    if (ec) return Status::error("--out: cannot remove '" + dir + "': " + ec.message());
    return false;
}

// The record of a finished shard (render_shards.h): its inputs, its frames
// [begin, end) and their records (timings, for the merged summary.json).
Status writeFrameShardRecord(const RenderWorkDir& out, const Shard& shard, const nlohmann::json& inputs,
                             ShardRange range, const Progressed& done) {
    nlohmann::json records = nlohmann::json::array();
    for (size_t f = range.begin; f < range.end; ++f) {
        nlohmann::json r = done.records[f];
        if (r.is_object()) r.erase("files");
        records.push_back(r);
    }
    return writeShardRecord(out.file(""), shard,
                            {{"inputs", inputs}, {"frames", {range.begin, range.end}}, {"frame_records", records}});
}

// The command's steps: options, display, city and path, work directory,
// set-up, frames, metadata and commit; any failure (bad input, a write that
// fails) is a message and exit 2, no display exit 1 before any work.
// Finished frames stay in OUT.partial for the rerun. A shard (--shard K/N)
// writes its frames and its record into OUT.shards/K-of-N the same way.
int run(const RenderArgs& a, const std::string& command) {
    RenderPlan plan;
    if (Status s = configure(a, plan); !s) return reportBadInput(kCmd, s);
    if (plan.shard) {
        auto published = publishedShard(plan.outDir, *plan.shard, a.restart, a.quiet);
        if (!published) return reportBadInput(kCmd, published.status());
        if (*published) {
            if (!a.quiet)
                std::fprintf(stderr, "%s: shard %s is done (%s)\n", kCmd, shardText(*plan.shard).c_str(),
                             plan.outDir.c_str());
            return 0;
        }
    }
    RenderWorkDir out;
    if (Status s = out.checkOut(plan.outDir); !s) return reportBadInput(kCmd, s);
    if (int rc = requireDisplay(kCmd); rc >= 0) return rc;
    std::vector<size_t> idx;
    auto walk = loadCityAndFrames(a, plan, idx);
    if (!walk) return reportBadInput(kCmd, walk.status());
    nlohmann::json inputs;
    if (Status s = openWorkDir(a, plan, walk->path, idx, out, inputs); !s) return reportBadInput(kCmd, s);

    RenderSession session;
    if (Status s = setUp(a.mode, plan, *walk, session); !s) return reportBadInput(kCmd, s);
    const ShardRange range = plan.shard ? shardRange(idx.size(), *plan.shard) : ShardRange{0, idx.size()};
    Progressed done = finishedFrames(out, plan.written(), idx.size(), range);
    nlohmann::json frames = nlohmann::json::array();
    if (Status s = renderFrames(a, plan, *walk, idx, range, session, out, done, frames); !s)
        return reportBadInput(kCmd, s);
    Timings tm;  // every frame's, whichever run rendered it
    for (const auto& r : done.records) tm.add(r);
    nlohmann::json paged;  // summary.json paged: the regions loaded, or the stream's totals
    if (!walk->pagedJson.empty()) paged = nlohmann::json::parse(walk->pagedJson);
    if (session.gt.stream)
        paged["stream"] = pagedStreamJson(session.gt.stream->options(), session.gt.stream->stats(),
                                          session.framesWithArrivals, session.damaged, session.detail);
    if (session.gt.stream) noteStreamDetail(kCmd, session.detail);
    if (Status s =
            writeMetadata(a, plan, command, walk->city, idx, frames, tm, done.kept, paged, *session.gt.renderer, out);
        !s)
        return reportBadInput(kCmd, s);
    if (plan.shard)
        if (Status s = writeFrameShardRecord(out, *plan.shard, inputs, range, done); !s) return reportBadInput(kCmd, s);
    if (Status s = out.commit(); !s) return reportBadInput(kCmd, s);
    printResult(a, plan, range.size(), tm, out);
    return 0;
}

// The option (or argument) that sets an input of runInputs, for messages.
std::string inputOption(const std::string& key) {
    static const std::map<std::string, std::string> options = {{"size", "--size"},
                                                               {"fov_deg", "--fov"},
                                                               {"mode", "--mode"},
                                                               {"channels", "--channels"},
                                                               {"near", "--near"},
                                                               {"triangle_budget", "--triangle-budget"},
                                                               {"pixel_budget", "--budget"},
                                                               {"horizon_grid", "--horizon-grid"},
                                                               {"cache", "--no-cache"},
                                                               {"cache_error_px", "--cache-error"},
                                                               {"frame_ms", "--frame-ms"},
                                                               {"far_step", "--far-step"},
                                                               {"traffic_hash", "--traffic"},
                                                               {"city_hash", "the city file"},
                                                               {"city_bytes", "the city file"},
                                                               {"path", "--path"},
                                                               {"camera_poses_hash", "--path"},
                                                               {"frames", "--frames"},
                                                               {"sampling", "--frames, --sampling"},
                                                               {"paged", "--paged-*"}};
    auto it = options.find(key);
    return it == options.end() ? "" : " (" + it->second + ")";
}

// "key (--option): A in shard 1/4, B in shard 3/4": the first field where two
// shards' inputs differ, "" if none.
std::string inputsDifference(const nlohmann::json& a, const std::string& aName, const nlohmann::json& b,
                             const std::string& bName) {
    if (!a.is_object() || !b.is_object()) return "inputs: not an object";
    auto shown = [](const nlohmann::json& o, const std::string& k) {
        return o.contains(k) ? (o[k].is_string() ? o[k].get<std::string>() : o[k].dump()) : std::string("(none)");
    };
    for (const auto* o : {&a, &b})
        for (const auto& [key, value] : o->items())
            if (!a.contains(key) || !b.contains(key) || a[key] != b[key])
                return key + inputOption(key) + ": " + shown(a, key) + " " + aName + ", " + shown(b, key) + " " + bName;
    return "";
}

// The last step of a sharded render: `vista render CITY ... --out OUT --merge
// --shards N` checks every shard (present, intact, the inputs the merge's own
// arguments give, the frames its share) and writes OUT: the shards' files
// and summary.json with every frame's timings.
int runMerge(const RenderArgs& a, int count, const std::string& command, const std::string& rerun) {
    RenderPlan plan;
    if (Status s = configure(a, plan); !s) return reportBadInput(kCmd, s);
    RenderWorkDir out;
    if (Status s = out.checkOut(a.out); !s) return reportBadInput(kCmd, s);
    auto inputs = runInputs(a, plan);
    if (!inputs) return reportBadInput(kCmd, inputs.status());
    const nlohmann::json& expect = *inputs;
    nlohmann::json first;  // the first good shard's inputs: its frames and poses agree with it
    std::string firstName;
    auto differ = [&](const Shard& s, const nlohmann::json& r) -> std::string {
        const nlohmann::json& in = r["inputs"];
        if (!in.is_object() || !in.contains("frames") || !in["frames"].is_number_unsigned())
            return "its inputs are not a render manifest";
        nlohmann::json mine = nlohmann::json::object();
        for (const auto& [key, value] : expect.items()) mine[key] = in.contains(key) ? in[key] : nlohmann::json();
        if (std::string d = inputsDifference(mine, "in the shard", expect, "now"); !d.empty()) return d;
        const ShardRange range = shardRange(in["frames"].get<size_t>(), s);
        if (r["frames"] != nlohmann::json{range.begin, range.end} || !r.contains("frame_records") ||
            r["frame_records"].size() != range.size())
            return "frames " + r["frames"].dump() + ", not its share [" + std::to_string(range.begin) + ", " +
                   std::to_string(range.end) + ")";
        if (first.is_null()) first = in, firstName = "in shard " + shardText(s);
        return inputsDifference(first, firstName, in, "in this shard");
    };
    auto records = readShards(a.out, count, differ, rerun);
    if (!records) return reportBadInput(kCmd, records.status());
    if (Status s = out.open({{"merge_shards", count}, {"inputs", first}}, true); !s) return reportBadInput(kCmd, s);
    if (Status s = assembleShards(a.out, *records, out.file(""), {"summary.json"}); !s) return reportBadInput(kCmd, s);
    // summary.json: the first shard's, with every frame's timings.
    const std::string firstSummary = shardDir(a.out, Shard{0, count}) + "/summary.json";
    std::ifstream in(firstSummary, std::ios::binary);
    nlohmann::json summary = nlohmann::json::parse(in, nullptr, false);
    if (summary.is_discarded() || !summary.is_object())
        return reportBadInput(kCmd, Status::error("--merge: '" + firstSummary + "' is not a summary.json"));
    Timings tm;
    for (const auto& r : *records)
        for (const auto& f : r["frame_records"]) tm.add(f);
    summary["command"] = command;
    summary["median_ms"] = Timings::medians(tm);
    summary["median_far_label_pixels"] = medianOf(tm.farPixels);
    summary["frames_resumed"] = 0;
    summary["shards"] = count;
    if (Status s = writeFileAtomic(out.file("summary.json"), summary.dump(2) + "\n"); !s)
        return reportBadInput(kCmd, s);
    if (Status s = out.commit(); !s) return reportBadInput(kCmd, s);
    if (!a.quiet || a.stats)
        std::printf("%s: merged %d shards, %zu frames -> %s\n", kCmd, count, first["frames"].get<size_t>(),
                    out.outPath().c_str());
    return 0;
}

// --- datasets (--dataset M.json) ---------------------------------------------

PathFlags datasetPathFlags(const DatasetPath& p) {
    PathFlags f;
    f.file = p.file;
    if (p.seed) f.seed = *p.seed;
    if (p.kind) f.kind = *p.kind;
    if (p.route) f.route = *p.route;
    if (p.duration) f.duration = *p.duration;
    if (p.runUp) f.runUp = *p.runUp;
    if (p.lht) f.lht = *p.lht;
    return f;
}

// The values whose ranges the render flags own, checked before any drive
// renders; each error names the manifest's field.
Status checkDatasetValues(const DatasetManifest& m, const std::string& source) {
    auto err = [&](const std::string& field, const std::string& why) {
        return Status::error("dataset '" + source + "': " + field + ": " + why);
    };
    for (size_t i = 0; i < m.paths.size(); ++i) {
        const DatasetPath& p = m.paths[i];
        const std::string field = "paths[" + std::to_string(i) + "]";
        if (p.duration && !path_range::duration.contains(*p.duration))
            return err(field + ".duration", shortNumber(*p.duration) + " out of range " + path_range::duration.text());
        if (p.runUp && !path_range::runUp.contains(*p.runUp))
            return err(field + ".run_up", shortNumber(*p.runUp) + " out of range " + path_range::runUp.text());
        auto po = parsePathFlags(datasetPathFlags(p));
        if (!po) return err(field, po.status().message());
    }
    for (size_t i = 0; i < m.rigs.size(); ++i) {
        const DatasetRig& r = m.rigs[i];
        const std::string field = "rigs[" + std::to_string(i) + "]";
        if (!r.file.empty()) {
            if (auto rig = loadRigFile(r.file); !rig) return err(field + ".file", rig.status().message());
            continue;
        }
        if (r.size)
            if (auto size = parseImageSize(*r.size); !size) return err(field + ".size", size.status().message());
        if (r.fov)
            if (Status s = checkFov(*r.fov); !s) return err(field + ".fov", s.message());
        if (r.mode && *r.mode != "full" && *r.mode != "hybrid")
            return err(field + ".mode", "'" + *r.mode + "': ground truth is rendered in full or hybrid");
        if (r.channels)
            if (auto c = parseChannels(*r.channels); !c) return err(field + ".channels", c.status().message());
    }
    if (m.options.sampling)
        if (auto sm = parseSampling(*m.options.sampling); !sm) return err("options.sampling", sm.status().message());
    return Status::ok();
}

// What decides a dataset's bytes: the manifest's content and every file it
// names (a paged city: its manifest.json), keyed by the manifest's field.
Result<nlohmann::json> datasetInputs(const std::string& file, const DatasetManifest& m) {
    uint64_t bytes = 0;
    auto h = fileHash(file, bytes);
    if (!h) return Status::error("--dataset: " + h.status().message());
    nlohmann::json in = {{"manifest_hash", *h}};
    auto add = [&](const std::string& key, const std::string& path) -> Status {
        auto fh = cityHash(path, isPagedCityPath(path), bytes);
        if (!fh) return Status::error("dataset '" + file + "': " + key + ": " + fh.status().message());
        in[key] = *fh;
        return Status::ok();
    };
    for (size_t i = 0; i < m.cities.size(); ++i)
        VISTA_RETURN_IF_ERROR(add("cities[" + std::to_string(i) + "].file", m.cities[i].file));
    for (size_t i = 0; i < m.paths.size(); ++i)
        if (!m.paths[i].file.empty())
            VISTA_RETURN_IF_ERROR(add("paths[" + std::to_string(i) + "].file", m.paths[i].file));
    for (size_t i = 0; i < m.rigs.size(); ++i)
        if (!m.rigs[i].file.empty()) VISTA_RETURN_IF_ERROR(add("rigs[" + std::to_string(i) + "].file", m.rigs[i].file));
    return in;
}

// One drive: a camera (run) or a sensor rig (runRigRender) into `out`, resumable as either is.
int renderDrive(const RenderArgs& base, const DatasetManifest& m, const DatasetDrive& d, const std::string& out,
                const std::string& command) {
    const DatasetRig& rig = m.rigs[d.rig];
    const DatasetOptions& o = m.options;
    const std::string cmd = command + " (drive " + d.name + ")";
    if (!rig.file.empty()) {
        RigRunRequest r;
        r.city = m.cities[d.city].file, r.rig = rig.file, r.out = out, r.command = cmd;
        r.sampling = o.sampling.value_or(r.sampling), r.frames = o.frames.value_or(r.frames);
        r.repeats = o.allowRepeatedFrames, r.stats = base.stats, r.quiet = base.quiet;
        r.path = datasetPathFlags(m.paths[d.path]);
        return runRigRender(r);
    }
    RenderArgs a;
    a.city = m.cities[d.city].file, a.out = out, a.path = datasetPathFlags(m.paths[d.path]);
    a.frames = o.frames.value_or(a.frames), a.sampling = o.sampling.value_or(a.sampling);
    a.repeats = o.allowRepeatedFrames, a.stats = base.stats, a.quiet = base.quiet;
    a.size = rig.size.value_or(a.size), a.fov = rig.fov.value_or(a.fov), a.mode = rig.mode.value_or(a.mode);
    a.channels = rig.channels.value_or(a.channels), a.channelsGiven = rig.channels.has_value();
    return run(a, cmd);
}

std::vector<std::string> driveNames(const std::vector<DatasetDrive>& drives, ShardRange range) {
    std::vector<std::string> names;
    for (size_t i = range.begin; i < range.end; ++i) names.push_back(drives[i].name);
    return names;
}

// OUT from the dataset's shards: every drive's folder, and dataset.json.
int mergeDataset(const RenderArgs& a, const DatasetManifest& m, const std::vector<DatasetDrive>& drives,
                 const nlohmann::json& inputs, int count, const std::string& command, const std::string& rerun) {
    RenderWorkDir out;
    if (Status s = out.checkOut(a.out); !s) return reportBadInput(kCmd, s);
    auto differ = [&](const Shard& s, const nlohmann::json& r) -> std::string {
        if (std::string d = inputsDifference(r["inputs"], "in the shard", inputs, "now"); !d.empty()) return d;
        const nlohmann::json expected = driveNames(drives, shardRange(drives.size(), s));
        if (r.value("drives", nlohmann::json()) != expected)
            return "drives " + r.value("drives", nlohmann::json()).dump() + ", not its share " + expected.dump();
        return "";
    };
    auto records = readShards(a.out, count, differ, rerun);
    if (!records) return reportBadInput(kCmd, records.status());
    if (Status s = out.open({{"dataset_merge_shards", count}, {"inputs", inputs}}, true); !s)
        return reportBadInput(kCmd, s);
    if (Status s = assembleShards(a.out, *records, out.file(""), {}); !s) return reportBadInput(kCmd, s);
    nlohmann::json list = nlohmann::json::array();
    for (const DatasetDrive& d : drives)
        list.push_back({{"name", d.name},
                        {"city", m.cities[d.city].name},
                        {"path", m.paths[d.path].name},
                        {"rig", m.rigs[d.rig].name}});
    const nlohmann::json dataset = {{"format", "vista dataset 1"}, {"inputs", inputs}, {"drives", list}};
    if (Status s = writeFileAtomic(out.file("dataset.json"), dataset.dump(2) + "\n"); !s)
        return reportBadInput(kCmd, s);
    if (Status s = out.commit(); !s) return reportBadInput(kCmd, s);
    if (!a.quiet || a.stats)
        std::printf("%s: dataset of %zu drives from %d shard%s -> %s\n", kCmd, drives.size(), count,
                    count == 1 ? "" : "s", out.outPath().c_str());
    return 0;
}

// `vista render --dataset M.json --out OUT [--shard K/N | --merge --shards N]`:
// shard K renders the drives shardRange(drives, K/N) (whole drives, each
// resumable) into OUT.shards/K-of-N and records them; the merge assembles
// OUT; without --shard the run is shard 1/1 and its merge, and the shard's
// directory is removed once OUT is written.
int runDataset(const RenderArgs& a, const std::string& command, const std::string& rerun) {
    auto m = loadDatasetManifest(a.dataset);
    if (!m) return reportBadInput(kCmd, m.status());
    if (Status s = checkDatasetValues(*m, a.dataset); !s) return reportBadInput(kCmd, s);
    if (Status s = RenderWorkDir::checkParent(a.out); !s) return reportBadInput(kCmd, s);
    auto inputs = datasetInputs(a.dataset, *m);
    if (!inputs) return reportBadInput(kCmd, inputs.status());
    const std::vector<DatasetDrive> drives = m->drives();
    if (a.merge) return mergeDataset(a, *m, drives, *inputs, *a.shards, command, rerun);
    Shard shard;
    if (!a.shard.empty()) {
        auto sh = parseShard("--shard", a.shard);
        if (!sh) return reportBadInput(kCmd, sh.status());
        shard = *sh;
    } else if (RenderWorkDir probe; Status s = probe.checkOut(a.out)) {
    } else {
        return reportBadInput(kCmd, s);
    }
    const std::string dir = shardDir(a.out, shard);
    std::error_code ec;
    if (a.restart) fs::remove_all(dir, ec);
    auto published = publishedShard(dir, shard, false, a.quiet);
    if (!published) return reportBadInput(kCmd, published.status());
    const ShardRange range = shardRange(drives.size(), shard);
    if (!*published) {
        fs::create_directories(dir, ec);
        if (ec) return reportBadInput(kCmd, Status::error("--out: cannot create '" + dir + "': " + ec.message()));
        for (size_t i = range.begin; i < range.end; ++i) {
            const std::string out = (fs::path(dir) / drives[i].name).string();
            if (fs::exists(out, ec) && !fs::is_empty(out, ec)) continue;  // published by an earlier run
            fs::create_directories(fs::path(out).parent_path(), ec);
            if (ec) return reportBadInput(kCmd, Status::error("--out: cannot create '" + out + "': " + ec.message()));
            if (int rc = renderDrive(a, *m, drives[i], out, command); rc != 0) {
                std::fprintf(stderr,
                             "%s: --dataset: drive %s (%zu of %zu, shard %s) failed; the same command resumes it\n",
                             kCmd, drives[i].name.c_str(), i + 1, drives.size(), shardText(shard).c_str());
                return rc;
            }
        }
        if (Status s = writeShardRecord(dir, shard, {{"inputs", *inputs}, {"drives", driveNames(drives, range)}}); !s)
            return reportBadInput(kCmd, s);
    }
    if (!a.shard.empty()) {
        if (!a.quiet)
            std::fprintf(stderr, "%s: shard %s: %zu of %zu drives in %s\n", kCmd, shardText(shard).c_str(),
                         range.size(), drives.size(), dir.c_str());
        return 0;
    }
    if (int rc = mergeDataset(a, *m, drives, *inputs, 1, command, rerun); rc != 0) return rc;
    fs::remove_all(dir, ec);
    fs::remove(fs::path(dir).parent_path(), ec);  // OUT.shards, when empty
    return 0;
}

}  // namespace

int runRender(int argc, char** argv) {
    CLI::App app{
        "Ground truth per frame of a walkthrough: rgb, metric depth, semantic classes, instance ids, "
        "cameras.json and classes.json (docs/formats.md).",
        kCmd};
    RenderArgs a;
    app.add_option("city", a.city,
                   "city scene file (.osgb) from `vista gen`, or a paged city directory (DIR.paged: streamed, "
                   "every frame waiting for the regions within reach of its camera; channels rgb, depth, semantic); "
                   "required unless --dataset");
    addPathFlags(app, a.path, true);
    addPagedFlags(app, a.paged);
    addPagedStreamFlags(app, a.stream);
    addNumberOption(
        app, "--memory-budget", a.memoryBudgetGb, kMemoryBudgetGbRange,
        "GB, (0, 65536]: refuse up front a run whose estimated peak memory (from the city file's size, or the paged "
        "regions' bytes) exceeds it; a streamed paged city's regions are held within it, and a budget that "
        "cannot hold the regions at the camera is an error naming the budget they need (default: no budget)");
    addNumberOption(app, "--frames", a.frames, 1, 1000000,
                    "frames rendered, 1 .. 1000000 and at most the path's sample count (default 60)");
    addRepeatedFramesFlag(app, a.repeats);
    app.add_option("--sampling", a.sampling,
                   "which path samples are the frames: spread (default), consecutive or runs:K");
    app.add_option("--size", a.size, "image size WIDTHxHEIGHT, 1x1 .. 8192x8192 (default 640x480)");
    addNumberOption(app, "--fov", a.fov, kFovRange, "vertical field of view in degrees, (1, 179) (default 60)");
    app.add_option(
        "--mode", a.mode,
        "render mode: full (every triangle rasterised) or hybrid (near field + ray-cast far field) (default full)");
    app.add_option("--channels", a.channels, "comma-separated channels: rgb, depth, semantic, instance (default all)");
    app.add_option("--rig", a.rig,
                   "sensor rig file (JSON: cameras, fisheyes, LiDARs, each with its pose, rate and channels; "
                   "docs/formats.md): every sensor is ray cast and written KITTI-style; replaces --size, --fov, "
                   "--mode and --channels");
    addModeFlags(app, a.modeFlags);
    app.add_option("--out", a.out,
                   "output directory (must not exist or be empty; its parent must exist); work goes into "
                   "OUT.partial and a rerun of the same command resumes it")
        ->required();
    app.add_flag("--restart", a.restart,
                 "discard the work directory (OUT.partial) of an interrupted run and start over");
    app.add_flag("--stats", a.stats,
                 "print the median per-channel costs (with --rig: per-sensor ms and rig frames per second, on "
                 "stderr; also in OUT/summary.json)");
    app.add_option("--dataset", a.dataset,
                   "dataset manifest (JSON: cities x paths x rigs, plus options; docs/formats.md): renders a drive "
                   "per (city, path, rig) into OUT/CITY/PATH/RIG and OUT/dataset.json; with --shard K/N, shard K "
                   "renders its share of whole drives; no CITY and no flags but --out, --shard, --merge, --shards, "
                   "--restart, --stats, -q");
    app.add_option("--shard", a.shard,
                   "shard K of N (K/N, 1 <= K <= N <= 100000): render only a contiguous block of the frames (of the "
                   "drives, with --dataset) into OUT.shards/K-of-N (resumable); then --merge --shards N writes OUT");
    app.add_flag("--merge", a.merge,
                 "with --shards N and the shards' other arguments: check every shard in OUT.shards (present, intact, "
                 "same inputs: city, path, frames, options, traffic; a difference is named with its option) and "
                 "write OUT, the bytes of one unsharded run (summary.json aside)");
    addNumberOption(app, "--shards", a.shards, 1, kMaxShards,
                    "with --merge: N, 1 .. 100000, the shard count of the shards' --shard K/N; a merge that finds a "
                    "shard missing, damaged or of other inputs names it and the command that runs it again");
    app.add_flag("-q,--quiet", a.quiet, "no progress on stderr");
    if (int rc = parseOrExit(app, argc, argv); rc >= 0) return rc;
    a.channelsGiven = app.count("--channels") > 0;
    std::string command = kCmd;
    for (int i = 1; i < argc; ++i) command += std::string(" ") + argv[i];
    // The command that runs one shard again (the merge's arguments without --merge --shards N).
    std::string rerun = kCmd;
    for (int i = 1; i < argc; ++i) {
        const std::string w = argv[i];
        if (w == "--merge" || w.rfind("--shards=", 0) == 0) continue;
        if (w == "--shards") {
            ++i;
            continue;
        }
        rerun += " " + shellWord(w);
    }
    rerun += " --shard";
    if (a.merge && !a.shard.empty())
        return reportBadInput(kCmd, Status::error("option --merge: not with --shard (the merge covers every shard)"));
    if (a.merge && !a.shards)
        return reportBadInput(kCmd, Status::error("option --merge: needs --shards N (the shards' --shard K/N)"));
    if (a.shards && !a.merge)
        return reportBadInput(kCmd, Status::error("option --shards: only with --merge (shards take --shard K/N)"));
    if (!a.dataset.empty()) {
        const std::set<std::string> allowed = {"--dataset", "--out",     "--shard", "--merge",
                                               "--shards",  "--restart", "--stats", "--quiet"};
        for (const CLI::Option* o : app.get_options())
            if (o->count() > 0 && !allowed.count(o->get_name()))
                return reportBadInput(kCmd, Status::error("option " + o->get_name() +
                                                          " does not apply with --dataset: the manifest gives the "
                                                          "cities, paths, rigs and options"));
        return runDataset(a, command, rerun);
    }
    if (a.city.empty()) return reportBadInput(kCmd, Status::error("city: a city file is required (or --dataset)"));
    if (!a.rig.empty()) {
        for (const char* flag : {"--size", "--fov", "--mode", "--channels"})
            if (app.count(flag))
                return reportBadInput(
                    kCmd, Status::error(std::string(flag) + " does not apply with --rig: the rig file gives each "
                                                            "sensor's model, size and channels"));
        // A rig casts every sensor into one ray scene of the loaded city, its
        // labels from the city's models: it takes a city file, not a paged city.
        for (const char* flag : {"--paged-stream", "--paged-preload", "--paged-wait", "--paged-prefetch",
                                 "--paged-radius", "--paged-far", "--memory-budget"})
            if (app.count(flag))
                return reportBadInput(
                    kCmd, Status::error(std::string(flag) + " does not apply with --rig: a rig renders a city file, "
                                                            "not a paged city (its sensors' labels come from the "
                                                            "whole loaded city)"));
        if (!a.shard.empty() || a.merge)
            return reportBadInput(kCmd, Status::error(std::string(a.merge ? "--merge" : "--shard") +
                                                      " does not apply with --rig: shard a dataset of rig drives "
                                                      "(--dataset) by whole drives"));
        RigRunRequest r;
        r.city = a.city, r.rig = a.rig, r.out = a.out, r.command = command, r.sampling = a.sampling;
        r.frames = a.frames, r.repeats = a.repeats, r.stats = a.stats, r.quiet = a.quiet, r.restart = a.restart;
        r.path = a.path, r.modeFlags = a.modeFlags;
        return runRigRender(r);
    }
    if (a.merge) return runMerge(a, *a.shards, command, rerun);
    return run(a, command);
}

}  // namespace vista
