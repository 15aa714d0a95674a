// vista path: a deterministic walkthrough path along the city's streets -> CSV.
#include <cstdio>
#include <string>

#include "runtime/scene/city_file.h"
#include "foundation/atomic_file.h"
#include "foundation/output_paths.h"
#include "foundation/units.h"
#include "cmd/cli.h"
#include "cmd/commands.h"
#include "cmd/options.h"
#include "runtime/scene/paged_walkthrough.h"
#include "runtime/scene/paths.h"
#include "runtime/traffic/ego_path.h"

namespace vista {

namespace {

// `vista path --traffic DIR`: the path rides a vehicle of the traffic.
int runEgoPath(const std::string& city, const std::string& out, const std::string& traffic, const std::string& ego,
               const PathOptions& o, const CLI::App& app) {
    const char* cmd = "vista path";
    if (traffic.empty()) return reportBadInput(cmd, Status::error("--traffic: give the traffic directory"));
    for (const char* flag : {"--kind", "--lht", "--route", "--speed", "--yaw-rate", "--fly-height", "--fly-pitch",
                             "--run-up", "--xodr-positions"})
        if (app.count(flag) > 0)
            return reportBadInput(cmd,
                                  Status::error(std::string(flag) + ": not with --traffic (the path rides a "
                                                                    "vehicle SUMO drove: a car at eye height 1.2 m)"));
    CommandFiles files;  // held until the output is written (its lock)
    if (Status s = files.input("city", city).input("--traffic", traffic).output("-o", out).check(); !s)
        return reportBadInput(cmd, s);
    if (Status s = checkWritablePath("--output", out); !s) return reportBadInput(cmd, s);
    auto tracks = loadTrafficTracks(traffic);
    if (!tracks) return reportBadInput(cmd, tracks.status());
    auto vehicle = chooseEgo(*tracks, ego, o.seed);
    if (!vehicle) return reportBadInput(cmd, vehicle.status());
    Result<SceneModel> c = Status::error("no city");
    if (isPagedCityPath(city)) {
        auto paged = openPagedCity(city, false);
        if (!paged) return reportBadInput(cmd, paged.status());
        c = std::move(paged->stub);
    } else {
        c = loadCityFile(city);
    }
    if (!c) return reportBadInput(cmd, c.status());
    PathOptions car = o;
    car.kind = PathKind::Car;
    auto p = egoPath(*tracks, *vehicle, c->params, o.dt, o.duration, car.eyeHeight());
    if (!p) return reportBadInput(cmd, p.status());
    if (Status s = savePathCsv(*p, out); !s) return reportBadInput(cmd, s);
    std::fprintf(stderr, "vista path: %zu samples (%.1f s riding %s) -> %s\n", p->samples.size(),
                 p->samples.back().t - p->samples.front().t, tracks->agentIds[*vehicle].c_str(), out.c_str());
    return 0;
}

}  // namespace

int runPath(int argc, char** argv) {
    CLI::App app{
        "Make a deterministic walkthrough path along the city's street graph (CSV: "
        "t_s,x_m,y_m,z_m,heading_deg,pitch_deg).",
        "vista path"};
    std::string city, out, kind = "car", positions, route = "tour", traffic, ego;
    PathOptions o;
    double yawDeg = 45.0, pitchDeg = o.flyPitch * 180.0 / kPi;
    // Options: one CLI11 call per flag.
    app.add_option("city", city,
                   "city scene file (.osgb) written by `vista gen`, or a paged city directory (DIR.paged: its street "
                   "graph is grown again from the manifest's params, no region is read; the same path as the "
                   "single-file city's)")
        ->required();
    addSeedOption(app, "--seed", o.seed, "random seed of the route (default 1)");
    app.add_option("--kind", kind, "walk (eye 1.7 m), car (eye 1.2 m) or fly (elevated fly-over); default car");
    addNumberOption(app, "--duration", o.duration, path_range::duration,
                    "path length in seconds, (0, 86400] (default 60)");
    addNumberOption(
        app, "--run-up", o.runUp, path_range::runUp,
        "seconds driven before the path starts and dropped, so it starts at cruising speed, 0 .. 600 (default 8)");
    app.add_option("--route", route,
                   "tour (default): head for far goals along shortest paths, so a long drive keeps going across "
                   "the city; wander: a seeded random walk that prefers going straight on");
    addNumberOption(app, "--dt", o.dt, path_range::dt, "seconds between samples, (0, 10] (default 1/30)");
    auto* speed = addNumberOption(app, "--speed", o.maxSpeed, path_range::speed,
                                  "maximum speed in m/s, (0, 1000] (default: walk 1.4, car and fly 14)");
    addNumberOption(app, "--yaw-rate", yawDeg, path_range::yawRateDeg,
                    "maximum yaw rate in degrees/s, (0, 720] (default 45)");
    addNumberOption(app, "--fly-height", o.flyHeight, path_range::flyHeight,
                    "fly-over height above the terrain in metres, (0, 10000) (default 80)");
    addNumberOption(app, "--fly-pitch", pitchDeg, path_range::flyPitchDeg,
                    "fly-over pitch in degrees, (-90, 90) (default -11.5)");
    app.add_flag("--lht", o.leftHandTraffic,
                 "car: left-hand traffic, every lane driven against its right-hand direction (the lane model is "
                 "right-hand traffic; one-way streets are then driven the wrong way)");
    app.add_option("-o,--output", out, "output CSV file")->required();
    app.add_option("--xodr-positions", positions,
                   "car: also write the OpenDRIVE position of every sample (CSV: t_s,road_id,lane_id,s_m,t_offset_m) "
                   "on the roads `vista gen --xodr` writes for this city");
    auto* trafficOpt = app.add_option(
        "--traffic", traffic,
        "ride one of the vehicles of a traffic directory (`vista traffic`): the path follows it as SUMO drove it, "
        "stopping at red lights and in queues; --seed picks the vehicle, --duration and --dt as usual");
    app.add_option("--ego", ego, "with --traffic: the id of the vehicle to ride (veh<N>; default: picked by --seed)");
    int rc = parseOrExit(app, argc, argv);
    if (rc >= 0) return rc;
    if (trafficOpt->count() > 0) return runEgoPath(city, out, traffic, ego, o, app);
    if (!ego.empty()) return reportBadInput("vista path", Status::error("--ego: only with --traffic DIR"));

    auto k = parsePathKind(kind);
    if (!k) return reportBadInput("vista path", Status::error("--kind: " + k.status().message()));
    o.kind = k.value();
    if (Status s = checkLeftHandTraffic(o.leftHandTraffic, o.kind); !s) return reportBadInput("vista path", s);
    if (speed->count() == 0) o.maxSpeed = defaultSpeed(o.kind);
    auto r = parseRouteStyle(route);
    if (!r) return reportBadInput("vista path", Status::error("--route: " + r.status().message()));
    o.route = r.value();
    o.maxYawRate = yawDeg * kPi / 180.0;
    o.flyPitch = pitchDeg * kPi / 180.0;
    if (Status s = validatePathOptions(o); !s) return reportBadInput("vista path", s);
    CommandFiles files;  // held until the outputs are written (the locks)
    if (Status s = files.input("city", city).output("-o", out).output("--xodr-positions", positions).check(); !s)
        return reportBadInput("vista path", s);
    if (Status s = checkWritablePath("--output", out); !s) return reportBadInput("vista path", s);
    if (!positions.empty() && o.kind != PathKind::Car)
        return reportBadInput("vista path", Status::error("--xodr-positions: only with --kind car (walk and fly "
                                                          "paths do not drive in lanes)"));
    if (!positions.empty())
        if (Status s = checkWritablePath("--xodr-positions", positions); !s) return reportBadInput("vista path", s);
    Result<SceneModel> c = Status::error("no city");
    if (isPagedCityPath(city)) {
        auto paged = openPagedCity(city, true);
        if (!paged) return reportBadInput("vista path", paged.status());
        c = std::move(paged->stub);
    } else {
        c = loadCityFile(city);
    }
    if (!c) return reportBadInput("vista path", c.status());
    auto p = generatePath(c->streets, c->params, o);
    if (!p) return reportBadInput("vista path", p.status());
    if (!positions.empty() && p->lanes.size() != p->samples.size())
        return reportBadInput("vista path",
                              Status::error("option --xodr-positions = '" + positions +
                                            "': this car path has no lane positions, so it follows the street centre "
                                            "lines (" +
                                            p->lanesMissing + "); leave out --xodr-positions to write that path"));
    // Both outputs or neither.
    OutputBatch batch;
    if (!positions.empty())
        if (Status s = saveLanePositionsCsv(p.value(), batch.stage(positions)); !s)
            return reportBadInput("vista path", s);
    if (Status s = savePathCsv(p.value(), batch.stage(out)); !s) return reportBadInput("vista path", s);
    if (Status s = batch.commit(); !s) return reportBadInput("vista path", s);
    std::fprintf(stderr, "vista path: %zu samples (%.1f s, %s) -> %s\n", p->samples.size(), o.duration,
                 pathKindName(o.kind), out.c_str());
    return 0;
}

}  // namespace vista
