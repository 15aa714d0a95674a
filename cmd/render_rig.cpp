// `vista render --rig` (render_rig.h): options and rig file, city and path,
// work directory, the frames (every sensor that fires, cast and written),
// then rig.json, the traffic's tracking files, calib.txt, times.txt,
// classes.json, semantic-kitti.yaml and summary.json.
#include "cmd/render_rig.h"

#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <numeric>
#include <optional>
#include <vector>

#include <nlohmann/json.hpp>
#include <tbb/task_group.h>

#include "cmd/cli.h"
#include "cmd/render_shared.h"
#include "cmd/render_work_dir.h"
#include "foundation/atomic_file.h"
#include "foundation/file_write_queue.h"
#include "foundation/format.h"
#include "foundation/hash.h"
#include "foundation/input_file.h"
#include "foundation/progress.h"
#include "foundation/statistics.h"
#include "foundation/timing.h"
#include "nodes/render/agent_truth.h"
#include "nodes/render/traffic_scene.h"
#include "nodes/render/walkthrough.h"
#include "runtime/engine/boxes.h"
#include "runtime/engine/far_field_stages.h"
#include "runtime/engine/ground_truth.h"
#include "runtime/engine/lidar.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/engine/rig.h"
#include "runtime/engine/rig_boxes.h"
#include "runtime/engine/rig_camera.h"
#include "runtime/engine/rig_dataset.h"
#include "runtime/engine/traffic_light_labels.h"
#include "runtime/traffic/signal_states.h"

namespace vista {

namespace {

namespace fs = std::filesystem;
const char* const kCmd = "vista render";

// The output folders of camera k's channels and LiDAR j's files.
std::string twoDigits(size_t k) {
    char b[24];
    std::snprintf(b, sizeof b, "%02zu", k);
    return b;
}
struct CameraDirs {
    std::string rgb, depth, semantic, instance, flow, boxes, labels;
};
CameraDirs cameraDirs(size_t k) {
    const std::string n = twoDigits(k);
    return {"image_" + n, "depth_" + n, "semantic_" + n, "instance_" + n, "flow_" + n, "boxes_" + n, "label_" + n};
}
const char* const kBoxes3dDir = "boxes_3d";
// KITTI tracking files of a run with traffic: tracking/label_NN/0000.txt per
// pinhole camera with boxes (one sequence) and tracking/tracks.json.
const char* const kTrackingDir = "tracking";
std::string trackingFile(size_t k) { return std::string(kTrackingDir) + "/label_" + twoDigits(k) + "/0000.txt"; }
bool tracksCamera(const RigCamera& c) { return (c.channels & kRigBoxes) && !c.model.fisheye(); }
struct LidarDirs {
    std::string points, times, labels, vistaLabels, instances;
};
LidarDirs lidarDirs(size_t j) {
    const std::string s = j == 0 ? std::string() : "_" + std::to_string(j);
    return {"velodyne" + s, "velodyne_time" + s, "labels" + s, "labels_vista" + s, "lidar_instance" + s};
}
const char* const kSemanticKittiYaml = "semantic-kitti.yaml";
// Threads writing a run's files: several, so that the fsyncs of a frame's files overlap.
constexpr int kWriterThreads = 4;

// The files a sensor writes when it fires at frame `name` (paths under out/).
std::vector<std::string> cameraFiles(const RigCamera& c, size_t k, const std::string& name) {
    const CameraDirs d = cameraDirs(k);
    std::vector<std::string> f;
    if (c.channels & kRigRgb) f.push_back(d.rgb + "/" + name + ".png");
    if (c.channels & kRigDepth) f.push_back(d.depth + "/" + name + ".npy");
    if (c.channels & kRigSemantic) f.push_back(d.semantic + "/" + name + ".png");
    if (c.channels & kRigInstance) f.push_back(d.instance + "/" + name + ".npy");
    if (c.channels & kRigFlow) f.push_back(d.flow + "/" + name + ".flo");
    if (c.channels & kRigBoxes) f.push_back(d.boxes + "/" + name + ".json");
    if ((c.channels & kRigBoxes) && !c.model.fisheye()) f.push_back(d.labels + "/" + name + ".txt");
    return f;
}
std::vector<std::string> lidarFiles(size_t j, const std::string& name) {
    const LidarDirs d = lidarDirs(j);
    return {d.points + "/" + name + ".bin", d.times + "/" + name + ".bin", d.labels + "/" + name + ".label",
            d.vistaLabels + "/" + name + ".label", d.instances + "/" + name + ".bin"};
}

// The parsed run: rig, path options, frames and who fires when.
struct RigPlan {
    Rig rig;
    PathOptions path;
    ModeOptions options;
    int sampleRuns = 0;
    std::vector<size_t> idx;                               // path sample of every frame
    std::vector<double> times;                             // its time
    std::vector<std::vector<uint8_t>> camFire, lidarFire;  // per sensor, per frame
    CommandFiles files;                                    // checked by configure; holds the output's lock
    std::shared_ptr<const TrafficTracks> traffic;          // --traffic (null: none)
    TrafficScene* agents = nullptr;                        // its agents in the ray scene, placed per frame
    bool needsLabels() const {
        if (!rig.lidars.empty()) return true;
        for (const RigCamera& c : rig.cameras)
            if (c.channels & (kRigSemantic | kRigInstance | kRigBoxes)) return true;
        return false;
    }
    // A camera asks for boxes: the run writes boxes_3d/ for every frame.
    bool hasBoxes() const {
        for (const RigCamera& c : rig.cameras)
            if (c.channels & kRigBoxes) return true;
        return false;
    }
    // Camera k writes traffic-light state labels (traffic_lights_NN/): it
    // asks for boxes and the traffic recorded its lights' states.
    bool labelsLights(size_t k) const { return (rig.cameras[k].channels & kRigBoxes) && traffic && traffic->signals; }
};

// Camera k's traffic-light labels folder, and its file of frame `name`.
std::string lightsDir(size_t k) { return "traffic_lights_" + twoDigits(k); }
std::string lightsFile(size_t k, const std::string& name) { return lightsDir(k) + "/" + name + ".txt"; }

Status configure(const RigRunRequest& a, RigPlan& p) {
    if (a.frames < 1 || a.frames > 1000000)
        return Status::error("--frames " + std::to_string(a.frames) + " out of range 1 .. 1000000");
    auto sampling = parseSampling(a.sampling);
    if (!sampling) return sampling.status();
    p.sampleRuns = *sampling;
    VISTA_RETURN_IF_ERROR(parseModeFlags(a.modeFlags, p.options));
    auto po = parsePathFlags(a.path);
    if (!po) return po.status();
    p.path = *po;
    auto rig = loadRigFile(a.rig);
    if (!rig) return Status::error("--rig: " + rig.status().message());
    p.rig = std::move(*rig);
    auto tracks = loadTrafficFlag(a.modeFlags.traffic);
    if (!tracks) return tracks.status();
    p.traffic = *tracks;
    return checkRunFiles(p.files.outputDirectory("--out", a.out, true).input("--rig", a.rig), a.city, a.path,
                         a.modeFlags);
}

Result<Walkthrough> loadCityAndFrames(const RigRunRequest& a, RigPlan& p) {
    const std::string labelsFor = p.needsLabels() ? "LiDAR labels and the semantic, instance and boxes channels" : "";
    WalkthroughRequest req =
        renderRequest(a.city, a.path.file, p.path, a.frames, p.sampleRuns, a.repeats, labelsFor, p.idx);
    req.effects = [](const Effects& declared) { return runTimeEffects(std::nullopt, declared, true, kCmd); };
    auto w = loadWalkthrough(req, p.options);
    if (!w) return w;
    for (size_t i : p.idx) p.times.push_back(w->path.samples[i].t);
    for (const RigCamera& c : p.rig.cameras) p.camFire.push_back(firingFrames(c.rateHz, p.times));
    for (const RigLidar& l : p.rig.lidars) p.lidarFire.push_back(firingFrames(l.rateHz, p.times));
    return w;
}

// Hash of the rig's canonical form (every field that changes an output byte).
std::string rigHash(const Rig& rig) {
    const std::string text = rigToJson(rig);
    Hasher64 h;
    h.update(reinterpret_cast<const unsigned char*>(text.data()), text.size());
    return hex64(h.finish());
}

Status openWorkDir(const RigRunRequest& a, const RigPlan& p, const Path& path, RenderWorkDir& out) {
    uint64_t cityBytes = 0;
    auto cityHash = fileHash(a.city, cityBytes);
    if (!cityHash) return cityHash.status();
    nlohmann::json manifest = {{"kind", "rig"},
                               {"city_hash", *cityHash},
                               {"city_bytes", cityBytes},
                               {"frames", p.idx.size()},
                               {"camera_poses_hash", posesHash(path, p.idx)},
                               {"rig_hash", rigHash(p.rig)}};
    if (p.traffic) {  // the agents decide pixels and points, the lamps the traffic-light labels
        auto traffic = trafficHash(*p.traffic, a.modeFlags.traffic);
        if (!traffic) return traffic.status();
        manifest["traffic_hash"] = *traffic;
    }
    VISTA_RETURN_IF_ERROR(out.open(manifest, a.restart));
    for (size_t k = 0; k < p.rig.cameras.size(); ++k) {
        for (const std::string& f : cameraFiles(p.rig.cameras[k], k, "x"))
            VISTA_RETURN_IF_ERROR(out.subdir(fs::path(f).parent_path().string()));
        if (p.labelsLights(k)) VISTA_RETURN_IF_ERROR(out.subdir(lightsDir(k)));
    }
    for (size_t j = 0; j < p.rig.lidars.size(); ++j)
        for (const std::string& f : lidarFiles(j, "x"))
            VISTA_RETURN_IF_ERROR(out.subdir(fs::path(f).parent_path().string()));
    if (p.hasBoxes()) VISTA_RETURN_IF_ERROR(out.subdir(kBoxes3dDir));
    if (p.traffic)
        for (size_t k = 0; k < p.rig.cameras.size(); ++k)
            if (tracksCamera(p.rig.cameras[k]))
                VISTA_RETURN_IF_ERROR(out.subdir(fs::path(trackingFile(k)).parent_path().string()));
    return Status::ok();
}

// The files of frame f: those of the sensors that fired, and its boxes.
std::vector<std::string> frameFiles(const RigPlan& p, size_t f) {
    std::vector<std::string> files;
    const std::string name = frameName(f);
    for (size_t k = 0; k < p.rig.cameras.size(); ++k)
        if (p.camFire[k][f]) {
            for (auto& s : cameraFiles(p.rig.cameras[k], k, name)) files.push_back(s);
            if (p.labelsLights(k)) files.push_back(lightsFile(k, name));
        }
    for (size_t j = 0; j < p.rig.lidars.size(); ++j)
        if (p.lidarFire[j][f])
            for (auto& s : lidarFiles(j, name)) files.push_back(s);
    if (p.hasBoxes()) files.push_back(std::string(kBoxes3dDir) + "/" + name + ".json");
    return files;
}

// Frames an interrupted run finished: their record, and every file of the sensors that fired with the size
// and content hash the record gives (a damaged one is rendered again).
std::vector<nlohmann::json> finishedFrames(const RenderWorkDir& out, const RigPlan& p, size_t& kept) {
    std::vector<nlohmann::json> records(p.idx.size());
    kept = 0;
    if (!out.resumed()) return records;
    for (size_t f = 0; f < records.size(); ++f) {
        records[f] = out.frameRecord(f);
        if (records[f].is_null()) continue;
        if (!out.frameIntact(records[f], frameFiles(p, f))) records[f] = nullptr;
        kept += records[f].is_null() ? 0 : 1;
    }
    return records;
}

// The time camera k's flow at frame f looks ahead to (rig.h nextFiringTime).
double nextShotTime(const RigPlan& p, const Path& path, size_t k, size_t f) {
    const double sampleAfter = path.samples[std::min(p.idx[f] + 1, path.samples.size() - 1)].t;
    return nextFiringTime(p.rig.cameras[k].rateHz, p.camFire[k], p.times, f, sampleAfter);
}

// A frame's boxes: the city's 3D boxes and the sightings of the sensors that fired.
struct FrameBoxState {
    const CityBoxes* city = nullptr;   // null: no camera asks for boxes
    std::vector<MovingObject> movers;  // the traffic's agents at the frame's time (sorted by id)
    FrameSightings seen;
    double t = 0;  // the frame's time: the traffic lights' lamps
};

// Camera k's 2D boxes from its instance image (into `fb`): boxes_NN/ and, for a pinhole, KITTI lines in label_NN/.
Status writeCameraBoxes(const RigPlan& p, const Walkthrough& w, size_t k, const RigPose& vehicle, const RigPose& pose,
                        const std::string& name, const CameraImages& im, const CameraRayTable& rays,
                        const RenderWorkDir& out, FileWriteQueue& io, const FrameBoxState& boxes,
                        std::vector<FrameBox>& fb) {
    const RigCamera& c = p.rig.cameras[k];
    const BoxCamera cam = rigBoxCamera(c.model, pose);
    FrameBoxOptions o;
    o.threads = 0;  // the frame's arena (renderFrames)
    o.rays = &rays;
    fb = frameBoxes(w.city, *boxes.city, boxes.movers, cam, im.ids, o);
    const CameraDirs d = cameraDirs(k);
    const glm::dvec3 offset(w.city.params.origin_x, w.city.params.origin_y, 0.0);
    io.write(out.file(d.boxes + "/" + name + ".json"), frameBoxesJson(fb, cam, offset, c.name));
    if (p.labelsLights(k)) {
        const SignalStates& lamps = *p.traffic->signals;
        auto lamp = [&](uint32_t head) { return std::string(lampStateName(lamps.lampAt(head, boxes.t))); };
        io.write(out.file(lightsFile(k, name)), trafficLightLabels(fb, lamp));
    }
    if (c.model.fisheye()) return Status::ok();
    io.write(out.file(d.labels + "/" + name + ".txt"),
             kittiRigLabels(fb, sensorPose(vehicle, kittiRectifiedMount(p.rig))));
    return Status::ok();
}

// A camera's image files: encoded here, written by the queue `io`.
Status writeCamera(const RigCamera& c, size_t k, const std::string& name, const CameraImages& im,
                   const RenderWorkDir& out, FileWriteQueue& io) {
    const std::vector<std::string> files = cameraFiles(c, k, name);
    size_t i = 0;
    if (c.channels & kRigRgb) {
        const std::string path = out.file(files[i++]);
        auto png = pngRgbBytes(im.rgb, path);
        if (!png) return png.status();
        io.write(path, std::move(*png));
    }
    if (c.channels & kRigDepth) io.write(out.file(files[i++]), npyBytes(im.depth.data(), im.width, im.height));
    if (c.channels & kRigSemantic) {
        const std::string path = out.file(files[i++]);
        auto png = pngGray8Bytes(im.classes, im.width, im.height, path);
        if (!png) return png.status();
        io.write(path, std::move(*png));
    }
    if (c.channels & kRigInstance) io.write(out.file(files[i++]), npyBytes(im.ids.data(), im.width, im.height));
    if (c.channels & kRigFlow) io.write(out.file(files[i++]), floBytes(im.flow.data(), im.width, im.height));
    return Status::ok();
}

// A sweep's files: encoded here, written by the queue `io`.
void writeLidar(const LidarSweep& s, size_t j, const std::string& name, const RenderWorkDir& out, FileWriteQueue& io) {
    const std::vector<std::string> files = lidarFiles(j, name);
    io.write(out.file(files[0]), velodyneBytes(s));
    io.write(out.file(files[1]), lidarTimeBytes(s));
    io.write(out.file(files[2]), semanticKittiLabelBytes(s));
    io.write(out.file(files[3]), vistaLabelBytes(s));
    io.write(out.file(files[4]), lidarInstanceBytes(s));
}

// The traffic at time t, every agent in the ray scene (the split at 0: all of them are rays' business).
Status placeAgents(const RigPlan& p, double t, const glm::dvec3& eye) {
    VISTA_RETURN_IF_ERROR(p.agents->setFrame(t, eye, /*splitFollows=*/true));
    return p.agents->setSplit(0.0);
}

// The frame's 3D boxes file: every object some sensor saw, in the city's own coordinates.
void writeFrameBoxes3d(const Walkthrough& w, const FrameBoxState& boxes, const RigPose& vehicle,
                       const std::string& name, const RenderWorkDir& out, FileWriteQueue& io) {
    const glm::dvec3 offset(w.city.params.origin_x, w.city.params.origin_y, 0.0);
    io.write(out.file(std::string(kBoxes3dDir) + "/" + name + ".json"),
             frameBoxes3dJson(*boxes.city, boxes.seen, vehicle, offset, name, boxes.t, boxes.movers));
}

// One rig frame: every sensor that fires, cast and its files encoded (each
// stage timed into the record: cast, write, boxes), then the frame's 3D
// boxes; the files go to `io`, which writes them after the call returns
// (renderFrames waits for them). Runs in the caller's task arena; its casts,
// boxes and encoding tasks share it.
Status renderFrame(const RigPlan& p, const Walkthrough& w, RayScene& rays, size_t f, const RenderWorkDir& out,
                   const CityBoxes* cityBoxes, const std::vector<CameraRayTable>& pixelRays,
                   std::vector<CameraImages>& ims, FileWriteQueue& io, nlohmann::json& record) {
    const Path& path = w.path;
    const RigPose vehicle = vehiclePose(path.samples[p.idx[f]]);
    // Ray origins near the scene's frame origin: float precision anywhere in the city.
    VISTA_RETURN_IF_ERROR(rays.placeFrameNear(vehicle.position));
    // The traffic at the frame's time, every agent in the ray scene (the vehicle's own excepted).
    if (p.agents) VISTA_RETURN_IF_ERROR(placeAgents(p, p.times[f], vehicle.position));
    const std::string name = frameName(f);
    const int threads = 0;  // the caller's arena: renderFrames runs each frame in one of --threads workers
    FrameBoxState boxes;
    boxes.city = cityBoxes;
    boxes.t = p.times[f];
    if (p.agents && cityBoxes)
        boxes.movers = agentObjects(p.agents->tracks(), p.agents->models(), w.city.params, p.times[f]);
    std::vector<ObjectMotion> motions;
    // A sensor's files (and a camera's boxes) are written by a task while the next sensor casts: the
    // task reads only that sensor's images or sweep and the frame's boxes, never the ray scene (which
    // the casts, and a LiDAR's moving agents, change). Sightings join in sensor order after the wait.
    struct Firing {
        bool fired = false;
        double castMs = 0, writeMs = 0, boxesMs = 0;
        Status status;
        std::vector<FrameBox> boxes;
    };
    std::vector<Firing> cams(p.rig.cameras.size()), lidars(p.rig.lidars.size());
    std::vector<LidarSweep> sweeps(p.rig.lidars.size());
    tbb::task_group writers;
    Stopwatch frame;
    for (size_t k = 0; k < p.rig.cameras.size(); ++k) {
        if (!p.camFire[k][f]) continue;
        const RigCamera& c = p.rig.cameras[k];
        CameraShot shot;
        shot.model = c.model;
        shot.pose = sensorPose(vehicle, c.mount);
        shot.channels = c.channels;
        shot.fx = &p.options.effects;
        shot.rays = &pixelRays[k];
        if (c.channels & kRigFlow) {
            const double next = nextShotTime(p, path, k, f);
            shot.next = sensorPose(vehiclePoseAt(path, next), c.mount);
            // The agents move between the two shots too: their flow follows their own motion.
            if (p.agents) {
                motions = agentMotions(p.agents->tracks(), p.agents->models(), w.city.params, p.times[f], next);
                shot.motions = &motions;
            }
        }
        Stopwatch cast;
        castRigCamera(w.city, rays, shot, ims[k], threads);
        cams[k].fired = true;
        cams[k].castMs = cast.ms();
        writers.run([&, k, pose = shot.pose] {
            Firing& o = cams[k];
            Stopwatch stage;
            o.status = writeCamera(p.rig.cameras[k], k, name, ims[k], out, io);
            o.writeMs = stage.lap();
            if (o.status && (p.rig.cameras[k].channels & kRigBoxes))
                o.status =
                    writeCameraBoxes(p, w, k, vehicle, pose, name, ims[k], pixelRays[k], out, io, boxes, o.boxes);
            o.boxesMs = stage.lap();
        });
    }
    for (size_t j = 0; j < p.rig.lidars.size(); ++j) {
        if (!p.lidarFire[j][f]) continue;
        const RigLidar& l = p.rig.lidars[j];
        const LidarPoseAt poseAt = [&](double t) { return lidarPoseOf(sensorPose(vehiclePoseAt(path, t), l.mount)); };
        // The agents move during the sweep: each column sees them where they are when it fires.
        LidarMovers movers;
        if (p.agents) movers.place = [&](double t) { return placeAgents(p, t, vehiclePoseAt(path, t).position); };
        Stopwatch cast;
        auto sweep = castLidarSweep(w.city, rays, l.spec, poseAt, p.times[f], movers, threads);
        if (!sweep) {
            writers.wait();
            (void)io.wait();  // the frame is not finished: its files are left for a rerun to replace
            return sweep.status();
        }
        sweeps[j] = std::move(*sweep);
        lidars[j].fired = true;
        lidars[j].castMs = cast.ms();
        writers.run([&, j] {
            Stopwatch stage;
            writeLidar(sweeps[j], j, name, out, io);
            lidars[j].writeMs = stage.ms();
        });
    }
    writers.wait();
    nlohmann::json ms = nlohmann::json::object(), stages = nlohmann::json::object(), lidar = nlohmann::json::object();
    for (size_t k = 0; k < cams.size(); ++k) {
        if (!cams[k].fired) continue;
        VISTA_RETURN_IF_ERROR(cams[k].status);
        const std::string& sensor = p.rig.cameras[k].name;
        addCameraSightings(boxes.seen, sensor, cams[k].boxes);
        ms[sensor] = cams[k].castMs + cams[k].writeMs + cams[k].boxesMs;
        stages[sensor] = {{"cast", cams[k].castMs}, {"write", cams[k].writeMs}, {"boxes", cams[k].boxesMs}};
    }
    for (size_t j = 0; j < lidars.size(); ++j) {
        if (!lidars[j].fired) continue;
        VISTA_RETURN_IF_ERROR(lidars[j].status);
        const RigLidar& l = p.rig.lidars[j];
        Stopwatch stage;
        if (boxes.city) addLidarSightings(boxes.seen, l.name, sweeps[j], *boxes.city, boxes.movers);
        lidars[j].boxesMs = stage.ms();
        ms[l.name] = lidars[j].castMs + lidars[j].writeMs + lidars[j].boxesMs;
        stages[l.name] = {{"cast", lidars[j].castMs}, {"write", lidars[j].writeMs}, {"boxes", lidars[j].boxesMs}};
        lidar[l.name] = {{"points", sweeps[j].points.size()}, {"misses", sweeps[j].misses}};
    }
    Stopwatch boxes3d;
    if (boxes.city) writeFrameBoxes3d(w, boxes, vehicle, name, out, io);
    // frame_ms: the casts and encoding; renderFrames adds the wait for the files (io_wait_ms).
    record = {{"frame_ms", frame.ms()},     {"sensor_ms", ms}, {"stage_ms", stages}, {"boxes_3d_ms", boxes3d.ms()},
              {"sensors_fired", ms.size()}, {"lidar", lidar}};
    return Status::ok();
}

Status renderFrames(const RigRunRequest& a, const RigPlan& p, const Walkthrough& w, RayScene& rays, RenderWorkDir& out,
                    std::vector<nlohmann::json>& records, size_t kept) {
    // City boxes once per run, and only when a camera asks for boxes and a frame is left to render.
    CityBoxes cityBoxes;
    const bool anyLeft =
        std::any_of(records.begin(), records.end(), [](const nlohmann::json& r) { return r.is_null(); });
    if (p.hasBoxes() && anyLeft) cityBoxes = buildCityBoxes(w.city, p.options.threads);
    // Every camera's pixel rays once per run: its casts and its fisheye masks read them.
    std::vector<CameraRayTable> pixelRays;
    if (anyLeft)
        for (const RigCamera& c : p.rig.cameras) pixelRays.emplace_back(c.model, p.options.threads);
    std::unique_ptr<Progress> progress;
    if (!a.quiet) progress = std::make_unique<StderrProgress>(isatty(2));
    const long killAfter = killAfterFrames();
    long finishedNow = 0;
    const size_t n = p.idx.size();
    if (progress)
        progress->begin("render " + std::to_string(n) + " rig frames (" +
                        std::to_string(p.rig.cameras.size() + p.rig.lidars.size()) + " sensors)" +
                        (kept ? ", resuming: " + std::to_string(kept) + " done" : std::string()));
    std::vector<CameraImages> ims(
        p.rig.cameras.size());  // one per camera: a camera's files are written while the next casts
    // The frames' files are written by threads that are not the casts' workers (file_write_queue.h),
    // a frame's while the next one casts: a queue per frame parity. A frame is finished (its record
    // written) once its files are; the wait for them counts in its wall time (so the frames' times
    // still add up to the run's), as io_wait_ms.
    FileWriteQueue evenFrames(kWriterThreads), oddFrames(kWriterThreads);
    auto queueOf = [&](size_t f) -> FileWriteQueue& { return f % 2 ? oddFrames : evenFrames; };
    auto finish = [&](size_t f) -> Status {
        Stopwatch wait;
        const Status s = queueOf(f).wait();
        const double waitMs = wait.ms();
        if (!s) return Status::error("frame " + std::to_string(f) + ": " + s.message());
        records[f]["io_wait_ms"] = waitMs;
        records[f]["frame_ms"] = records[f]["frame_ms"].get<double>() + waitMs;
        VISTA_RETURN_IF_ERROR(out.finishFrame(f, records[f], frameFiles(p, f)));
        if (killAfter > 0 && ++finishedNow == killAfter) std::raise(SIGKILL);
        if (progress) progress->update(double(f + 1) / double(n));
        return Status::ok();
    };
    std::optional<size_t> writing;  // the frame whose files are on their way
    for (size_t f = 0; f < n; ++f) {
        if (!records[f].is_null()) continue;
        Status s;
        // The frame's casts and encoding tasks share one arena of --threads workers.
        inArena(p.options.threads, [&] {
            s = renderFrame(p, w, rays, f, out, p.hasBoxes() ? &cityBoxes : nullptr, pixelRays, ims, queueOf(f),
                            records[f]);
        });
        if (!s) return Status::error("frame " + std::to_string(f) + ": " + s.message());
        if (writing) VISTA_RETURN_IF_ERROR(finish(*writing));
        writing = f;
    }
    if (writing) VISTA_RETURN_IF_ERROR(finish(*writing));
    if (progress) progress->end();
    return Status::ok();
}

nlohmann::json matrixJson(const RowMajor4& m) {
    nlohmann::json j = nlohmann::json::array();
    for (const auto& row : m) j.push_back({row[0], row[1], row[2], row[3]});
    return j;
}

// rig.json: the rig, the conventions, and per frame the vehicle's pose and
// the pose of every sensor that fired (a LiDAR: at its sweep's start).
nlohmann::json rigManifest(const RigPlan& p, const Walkthrough& w) {
    const glm::dvec3 offset(w.city.params.origin_x, w.city.params.origin_y, 0.0);
    nlohmann::json sensors = nlohmann::json::array();
    const nlohmann::json rig = nlohmann::json::parse(rigToJson(p.rig));
    for (size_t k = 0; k < p.rig.cameras.size(); ++k) {
        const CameraDirs d = cameraDirs(k);
        const RigCamera& c = p.rig.cameras[k];
        sensors.push_back({{"name", c.name},
                           {"index", k},
                           {"dirs",
                            {{"rgb", d.rgb},
                             {"depth", d.depth},
                             {"semantic", d.semantic},
                             {"instance", d.instance},
                             {"flow", d.flow},
                             {"boxes", d.boxes},
                             {"kitti_labels", c.model.fisheye() ? nlohmann::json(nullptr) : nlohmann::json(d.labels)}}},
                           {"channels", rigChannelList(c.channels)},
                           {"sensor_to_vehicle",
                            matrixJson(poseToWorld({c.mount.position, mountRotation(c.mount)}, glm::dvec3(0.0)))}});
        if (p.labelsLights(k)) sensors.back()["dirs"]["traffic_lights"] = lightsDir(k);
    }
    for (size_t j = 0; j < p.rig.lidars.size(); ++j) {
        const LidarDirs d = lidarDirs(j);
        const RigLidar& l = p.rig.lidars[j];
        sensors.push_back({{"name", l.name},
                           {"index", j},
                           {"dirs",
                            {{"points", d.points},
                             {"times", d.times},
                             {"labels", d.labels},
                             {"vista_labels", d.vistaLabels},
                             {"instances", d.instances}}},
                           {"sensor_to_vehicle",
                            matrixJson(poseToWorld({l.mount.position, mountRotation(l.mount)}, glm::dvec3(0.0)))}});
    }
    nlohmann::json frames = nlohmann::json::array();
    for (size_t f = 0; f < p.idx.size(); ++f) {
        const RigPose v = vehiclePose(w.path.samples[p.idx[f]]);
        nlohmann::json fired = nlohmann::json::object();
        for (size_t k = 0; k < p.rig.cameras.size(); ++k)
            if (p.camFire[k][f])
                fired[p.rig.cameras[k].name] = {
                    {"camera_to_world", matrixJson(cameraToWorld(sensorPose(v, p.rig.cameras[k].mount), offset))}};
        for (size_t j = 0; j < p.rig.lidars.size(); ++j)
            if (p.lidarFire[j][f])
                fired[p.rig.lidars[j].name] = {{"sensor_to_world_at_start",
                                                matrixJson(poseToWorld(sensorPose(v, p.rig.lidars[j].mount), offset))}};
        frames.push_back({{"frame", f},
                          {"name", frameName(f)},
                          {"path_index", p.idx[f]},
                          {"t_s", p.times[f]},
                          {"vehicle_to_world", matrixJson(poseToWorld(v, offset))},
                          {"sensors", fired}});
    }
    nlohmann::json doc = {
        {"format", "vista rig run 1"},
        {"conventions",
         "world: metres, x east, y north, z up, minus world_offset; vehicle and sensor frames: x forward, y left, "
         "z up; camera_to_world maps the OpenCV camera frame (x right, y down, z forward); matrices 4x4 "
         "row-major"},
        {"world_offset", {offset.x, offset.y, offset.z}},
        {"rig", rig},
        {"sensors", sensors},
        {"frames", frames}};
    if (p.hasBoxes()) doc["boxes_3d"] = kBoxes3dDir;
    if (p.traffic) {
        nlohmann::json files = nlohmann::json::object();
        for (size_t k = 0; k < p.rig.cameras.size(); ++k)
            if (tracksCamera(p.rig.cameras[k])) files[p.rig.cameras[k].name] = trackingFile(k);
        if (!files.empty())
            doc["tracking"] = {{"tracks", std::string(kTrackingDir) + "/tracks.json"}, {"labels", files}};
    }
    return doc;
}

// summary.json: per sensor its firings, median and mean ms (cast and write),
// LiDAR points and misses; rig frames per second over every frame's wall time.
nlohmann::json rigSummary(const RigRunRequest& a, const RigPlan& p, const std::vector<nlohmann::json>& records,
                          size_t kept) {
    nlohmann::json sensors = nlohmann::json::object();
    double totalMs = 0;
    std::vector<double> fired, boxes3d, ioWait;
    for (const auto& r : records) {
        if (r.contains("frame_ms") && r["frame_ms"].is_number()) totalMs += r["frame_ms"].get<double>();
        if (r.contains("sensor_ms") && r["sensor_ms"].is_object()) fired.push_back(double(r["sensor_ms"].size()));
        if (r.contains("boxes_3d_ms") && r["boxes_3d_ms"].is_number())
            boxes3d.push_back(r["boxes_3d_ms"].get<double>());
        if (r.contains("io_wait_ms") && r["io_wait_ms"].is_number()) ioWait.push_back(r["io_wait_ms"].get<double>());
    }
    for (const std::string& name : p.rig.order) {
        std::vector<double> ms;
        std::map<std::string, std::vector<double>> stageMs;  // cast, write, boxes
        std::vector<double> boxesShare;                      // per firing: boxes / the whole firing
        uint64_t points = 0, misses = 0;
        for (const auto& r : records) {
            if (r.contains("sensor_ms") && r["sensor_ms"].contains(name))
                ms.push_back(r["sensor_ms"][name].get<double>());
            if (r.contains("stage_ms") && r["stage_ms"].contains(name)) {
                for (const auto& [stage, v] : r["stage_ms"][name].items())
                    if (v.is_number()) stageMs[stage].push_back(v.get<double>());
                const double whole = r["sensor_ms"][name].get<double>();
                if (r["stage_ms"][name].contains("boxes") && whole > 0)
                    boxesShare.push_back(r["stage_ms"][name]["boxes"].get<double>() / whole);
            }
            if (r.contains("lidar") && r["lidar"].contains(name)) {
                points += r["lidar"][name]["points"].get<uint64_t>();
                misses += r["lidar"][name]["misses"].get<uint64_t>();
            }
        }
        nlohmann::json s = {
            {"firings", ms.size()},
            {"median_ms", medianOf(ms)},
            {"mean_ms", ms.empty() ? nlohmann::json(nullptr)
                                   : nlohmann::json(std::accumulate(ms.begin(), ms.end(), 0.0) / double(ms.size()))}};
        nlohmann::json stages = nlohmann::json::object();
        for (const auto& [stage, v] : stageMs) stages[stage] = medianOf(v);
        s["stage_median_ms"] = stages;
        s["boxes_share_median"] = medianOf(boxesShare);
        bool isLidar = false;
        for (const RigLidar& l : p.rig.lidars) isLidar = isLidar || l.name == name;
        if (isLidar) s["points"] = points, s["misses"] = misses;
        sensors[name] = s;
    }
    return {{"command", a.command},
            {"kind", "rig"},
            {"frames", p.idx.size()},
            {"frames_resumed", kept},
            {"rig_frames_per_second",
             totalMs > 0 ? nlohmann::json(double(records.size()) * 1000.0 / totalMs) : nlohmann::json(nullptr)},
            {"sensors", sensors},
            {"sensors_fired_per_frame",
             fired.empty() ? nlohmann::json(nullptr)
                           : nlohmann::json(std::accumulate(fired.begin(), fired.end(), 0.0) / double(fired.size()))},
            {"boxes_3d_median_ms", medianOf(boxes3d)},
            {"io_wait_median_ms", medianOf(ioWait)},
            {"note",
             "per sensor: ray casting, its boxes and writing its files, in ms per firing (stage_median_ms: the "
             "median of each stage: cast (the rays alone; a LiDAR's sweep), write (encoding the images or points "
             "and handing them to the file writers), boxes with their files; boxes_share_median: "
             "the median over firings of the boxes stage's share of the firing); io_wait_median_ms: the median "
             "over the frames of the wait, at a frame's end, for its files to reach the disk (written by threads "
             "of their own while the sensors cast); "
             "sensors_fired_per_frame: the mean over the frames; rig_frames_per_second: "
             "frames divided by the sum of every frame's wall time, each timed by the run that rendered it "
             "(frames_resumed: frames an interrupted run had finished)"}};
}

// The traffic's tracking files, from every frame's KITTI labels (rendered now or by an interrupted run).
Status writeTracking(const RigPlan& p, const RenderWorkDir& out) {
    bool any = false;
    for (size_t k = 0; k < p.rig.cameras.size(); ++k) {
        if (!tracksCamera(p.rig.cameras[k])) continue;
        any = true;
        std::vector<std::pair<size_t, std::string>> labels;
        for (size_t f = 0; f < p.idx.size(); ++f) {
            if (!p.camFire[k][f]) continue;
            auto text = readInputFile("label file", out.file(cameraDirs(k).labels + "/" + frameName(f) + ".txt"),
                                      kMaxPathCsvBytes);
            if (!text) return Status::error("--out: " + text.status().message());
            labels.emplace_back(f, std::move(*text));
        }
        VISTA_RETURN_IF_ERROR(writeFileAtomic(out.file(trackingFile(k)), kittiTrackingLines(labels)));
    }
    if (!any) return Status::ok();
    nlohmann::json tracks = nlohmann::json::array();
    const TrafficTracks& t = *p.traffic;
    for (size_t a = 0; a < t.agentIds.size(); ++a) {
        const AgentType type = a < t.agentTypes.size() ? t.agentTypes[a] : AgentType::Car;
        const uint32_t id = agentLabel(type, uint32_t(a));
        tracks.push_back({{"track_id", a},
                          {"sumo_id", t.agentIds[a]},
                          {"class", semanticClassName(SemanticClass(agentClass(type)))},
                          {"instance_id", id}});
    }
    const nlohmann::json doc = {{"format", "vista.tracks"}, {"version", 1}, {"tracks", tracks}};
    return writeFileAtomic(out.file(std::string(kTrackingDir) + "/tracks.json"), doc.dump(1) + "\n");
}

Status writeMetadata(const RigRunRequest& a, const RigPlan& p, const Walkthrough& w,
                     const std::vector<nlohmann::json>& records, size_t kept, RenderWorkDir& out,
                     nlohmann::json& summary) {
    VISTA_RETURN_IF_ERROR(writeFileAtomic(out.file("rig.json"), rigManifest(p, w).dump(2) + "\n"));
    if (p.traffic) VISTA_RETURN_IF_ERROR(writeTracking(p, out));
    const std::string calib = kittiCalib(p.rig);
    if (!calib.empty()) VISTA_RETURN_IF_ERROR(writeFileAtomic(out.file("calib.txt"), calib));
    std::string times;
    for (double t : p.times) {
        char b[40];
        std::snprintf(b, sizeof b, "%.6e\n", t - p.times.front());
        times += b;
    }
    VISTA_RETURN_IF_ERROR(writeFileAtomic(out.file("times.txt"), times));
    VISTA_RETURN_IF_ERROR(writeFileAtomic(out.file("classes.json"), classesJson().dump(2) + "\n"));
    if (!p.rig.lidars.empty())
        VISTA_RETURN_IF_ERROR(writeFileAtomic(out.file(kSemanticKittiYaml), semanticKittiYaml()));
    summary = rigSummary(a, p, records, kept);
    VISTA_RETURN_IF_ERROR(writeFileAtomic(out.file("summary.json"), summary.dump(2) + "\n"));
    return out.commit();
}

void printStats(const RigRunRequest& a, const RigPlan& p, const nlohmann::json& summary, const RenderWorkDir& out) {
    if (!a.quiet || a.stats)
        std::printf("%s: %zu rig frames, %zu sensors -> %s\n", kCmd, p.idx.size(), p.rig.order.size(),
                    out.outPath().c_str());
    if (!a.stats) return;
    for (const std::string& name : p.rig.order) {
        const auto& s = summary["sensors"][name];
        if (s["median_ms"].is_null()) continue;
        std::fprintf(stderr, "  %-24s %8.2f ms median, %8.2f ms mean over %d firings", name.c_str(),
                     s["median_ms"].get<double>(), s["mean_ms"].get<double>(), s["firings"].get<int>());
        for (const char* stage : {"cast", "write", "boxes"})
            if (s["stage_median_ms"].contains(stage) && s["stage_median_ms"][stage].is_number())
                std::fprintf(stderr, "; %s %.2f", stage, s["stage_median_ms"][stage].get<double>());
        std::fprintf(stderr, "\n");
    }
    if (!summary["rig_frames_per_second"].is_null())
        std::fprintf(stderr, "  %-24s %8.3f\n", "rig frames per second",
                     summary["rig_frames_per_second"].get<double>());
}

}  // namespace

int runRigRender(const RigRunRequest& a) {
    RigPlan plan;
    if (Status s = configure(a, plan); !s) return reportBadInput(kCmd, s);
    RenderWorkDir out;
    if (Status s = out.checkOut(a.out); !s) return reportBadInput(kCmd, s);
    auto walk = loadCityAndFrames(a, plan);
    if (!walk) return reportBadInput(kCmd, walk.status());
    auto rays = RayScene::build(walk->city);
    if (!rays)
        return reportBadInput(kCmd, Status::error("building the Embree ray scene failed: " + rays.status().message()));
    if (Status s = openWorkDir(a, plan, walk->path, out); !s) return reportBadInput(kCmd, s);
    std::unique_ptr<TrafficScene> traffic;
    if (plan.traffic) {
        traffic = std::make_unique<TrafficScene>(plan.traffic, walk->city.params, false);
        if (Status s = traffic->attachRays(rays->get()); !s) return reportBadInput(kCmd, s);
        if (Status s = traffic->showCitySignals(walk->city, walk->manifest.get()); !s) return reportBadInput(kCmd, s);
        plan.agents = traffic.get();
    }
    size_t kept = 0;
    std::vector<nlohmann::json> records = finishedFrames(out, plan, kept);
    if (Status s = renderFrames(a, plan, *walk, **rays, out, records, kept); !s) return reportBadInput(kCmd, s);
    nlohmann::json summary;
    if (Status s = writeMetadata(a, plan, *walk, records, kept, out, summary); !s) return reportBadInput(kCmd, s);
    printStats(a, plan, summary, out);
    return 0;
}

}  // namespace vista
