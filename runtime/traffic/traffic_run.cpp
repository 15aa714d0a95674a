#include "runtime/traffic/traffic_run.h"

#include <expat.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "foundation/atomic_file.h"
#include "foundation/hash.h"
#include "foundation/format.h"
#include "runtime/traffic/junction_conflicts.h"
#include "runtime/traffic/junction_lanes.h"
#include "runtime/traffic/junction_turns.h"
#include "runtime/traffic/sumo_net.h"
#include "runtime/traffic/sumo_process.h"

namespace vista {

namespace fs = std::filesystem;

namespace {

constexpr const char* kPartialMark = ".vista-traffic-partial";
// The gap a pedestrian keeps to a vehicle (SUMO's default is 0.25 m, with
// which a pedestrian steps onto a crossing behind a car still leaving it and
// SUMO's junction check reports a collision).
constexpr double kPedestrianGapToVehicleM = 2.0;

std::string num(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.3f", v);
    std::string s = buf;
    while (!s.empty() && s.back() == '0') s.pop_back();
    if (!s.empty() && s.back() == '.') s.pop_back();
    return s;
}

std::string sumoConfig(const TrafficOptions& opt) {
    const uint64_t sumoSeed = opt.demand.seed % 2147483647ull;
    return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
           "<!-- vista traffic: run again with `sumo -c traffic.sumocfg` in this folder -->\n"
           "<configuration>\n"
           "    <input>\n"
           "        <net-file value=\"city.net.xml\"/>\n"
           "        <route-files value=\"demand.rou.xml\"/>\n"
           "        <additional-files value=\"signals.add.xml\"/>\n"
           "    </input>\n"
           "    <output>\n"
           "        <fcd-output value=\"fcd.xml\"/>\n"
           "        <statistic-output value=\"statistics.xml\"/>\n"
           "        <collision-output value=\"collisions.xml\"/>\n"
           "    </output>\n"
           "    <time>\n"
           "        <begin value=\"0\"/>\n"
           "        <end value=\"" +
           num(opt.demand.durationS) +
           "\"/>\n"
           "        <step-length value=\"" +
           num(opt.stepS) +
           "\"/>\n"
           "    </time>\n"
           "    <processing>\n"
           "        <collision.action value=\"warn\"/>\n"
           "        <collision.check-junctions value=\"true\"/>\n"
           "        <ignore-route-errors value=\"true\"/>\n"
           "        <pedestrian.striping.mingap-to-vehicle value=\"" +
           num(kPedestrianGapToVehicleM) +
           "\"/>\n"
           "    </processing>\n"
           "    <random_number>\n"
           "        <seed value=\"" +
           std::to_string(sumoSeed) +
           "\"/>\n"
           "    </random_number>\n"
           "    <report>\n"
           "        <no-step-log value=\"true\"/>\n"
           "    </report>\n"
           "</configuration>\n";
}

const char* kSignalsAdditional =
    "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
    "<!-- vista traffic: every traffic light's state, written when it switches -->\n"
    "<additional>\n"
    "    <timedEvent type=\"SaveTLSSwitchStates\" dest=\"signals.xml\"/>\n"
    "</additional>\n";

// SUMO's statistic output: the counts vista reports.
struct Statistics {
    int inserted = 0, persons = 0, collisions = 0, teleports = 0, emergencyStops = 0;
    bool found = false;
};

Statistics readStatistics(const std::string& path) {
    Statistics s;
    std::ifstream in(path, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    XML_Parser p = XML_ParserCreate(nullptr);
    std::unique_ptr<XML_ParserStruct, void (*)(XML_Parser)> guard(p, &XML_ParserFree);
    XML_SetUserData(p, &s);
    XML_SetStartElementHandler(p, [](void* u, const XML_Char* name, const XML_Char** a) {
        auto* s = static_cast<Statistics*>(u);
        auto get = [&](const char* key) {
            for (int i = 0; a[i]; i += 2)
                if (std::strcmp(a[i], key) == 0) return std::atoi(a[i + 1]);
            return 0;
        };
        if (std::strcmp(name, "statistics") == 0) s->found = true;
        if (std::strcmp(name, "vehicles") == 0) s->inserted = get("inserted");
        if (std::strcmp(name, "persons") == 0) s->persons = get("loaded");
        if (std::strcmp(name, "teleports") == 0) s->teleports = get("total");
        if (std::strcmp(name, "safety") == 0)
            s->collisions = get("collisions"), s->emergencyStops = get("emergencyStops");
    });
    const std::string body = text.str();
    if (XML_Parse(p, body.data(), int(body.size()), 1) == XML_STATUS_ERROR) s.found = false;
    return s;
}

}  // namespace

Result<CollisionCounts> readCollisions(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return Status::error("cannot read SUMO's collision output '" + path + "': " + errnoText());
    std::stringstream text;
    text << in.rdbuf();
    struct State {
        CollisionCounts counts;
        bool sawRoot = false;
        std::string error;
        XML_Parser parser = nullptr;
    } st;
    XML_Parser p = XML_ParserCreate(nullptr);
    std::unique_ptr<XML_ParserStruct, void (*)(XML_Parser)> guard(p, &XML_ParserFree);
    st.parser = p;
    XML_SetUserData(p, &st);
    XML_SetStartElementHandler(p, [](void* u, const XML_Char* name, const XML_Char** a) {
        auto* st = static_cast<State*>(u);
        if (!st->sawRoot) {
            st->sawRoot = true;
            if (std::strcmp(name, "collisions") != 0) {
                st->error = std::string("the root element is <") + name + ">, not <collisions>";
                XML_StopParser(st->parser, XML_FALSE);
            }
            return;
        }
        if (std::strcmp(name, "collision") != 0) return;
        const char* victimType = nullptr;
        for (int i = 0; a[i]; i += 2)
            if (std::strcmp(a[i], "victimType") == 0) victimType = a[i + 1];
        CollisionCounts& c = st->counts;
        ++c.events;
        if (victimType && std::strcmp(victimType, "pedestrian") == 0) ++c.withPedestrians;
        else ++c.betweenVehicles;
    });
    const std::string body = text.str();
    if (XML_Parse(p, body.data(), int(body.size()), 1) == XML_STATUS_ERROR || !st.error.empty()) {
        const std::string why = st.error.empty() ? XML_ErrorString(XML_GetErrorCode(p)) : st.error;
        return Status::error("SUMO's collision output '" + path + "', line " +
                             std::to_string(XML_GetCurrentLineNumber(p)) + ": " + why);
    }
    if (!st.sawRoot) return Status::error("SUMO's collision output '" + path + "' is empty");
    return st.counts;
}

namespace {

Status writeText(const std::string& path, const std::string& text) { return writeFileAtomic(path, text); }

// "<dir>.partial": created empty with its mark; an interrupted run's
// folder (with the mark) is removed first, anything else there is an error.
Result<std::string> freshWorkDir(const std::string& dir) {
    const std::string work = dir + ".partial";
    std::error_code ec;
    if (fs::exists(fs::symlink_status(work, ec))) {
        if (!fs::is_directory(fs::symlink_status(work, ec)) || !fs::exists(fs::path(work) / kPartialMark, ec))
            return Status::error("'" + work + "' exists and is not an interrupted vista traffic run: move it away");
        fs::remove_all(work, ec);
        if (ec) return Status::error("cannot remove the interrupted run '" + work + "': " + ec.message());
    }
    fs::create_directories(work, ec);
    if (ec) return Status::error("cannot create '" + work + "': " + ec.message());
    VISTA_RETURN_IF_ERROR(writeText((fs::path(work) / kPartialMark).string(), ""));
    return work;
}

// The net edits that keep SUMO's junction model within what its collision
// check sees: lane changes, tight turns, slanted crossings.
Status adaptJunctionLanes(const std::string& netPath, TrafficRunSummary& sum) {
    // No lane changes inside junctions (a vehicle moved sideways there onto a
    // pedestrian waiting on a crossing): junction_lanes.h.
    if (auto marked = forbidJunctionLaneChanges(netPath); !marked) return marked.status();
    // Long vehicles keep off turns tighter than SUMO's straight box between
    // their front and back can take (junction_turns.h).
    std::vector<TurnClass> turnClasses;
    for (int t = 0; t < kAgentTypeCount; ++t)
        if (AgentType(t) != AgentType::Pedestrian)
            turnClasses.push_back({agentTypeInfo(AgentType(t)).sumoClass, agentTypeInfo(AgentType(t)).length});
    auto closed = restrictTightTurns(netPath, turnClasses);
    if (!closed) return closed.status();
    for (size_t i = 0; i < turnClasses.size(); ++i) sum.turnsClosed.push_back({turnClasses[i].sumoClass, (*closed)[i]});
    // A vehicle counts as past a crossing only once its body has left the
    // crossing lane's vehicles, also where the lanes cross at a slant
    // (junction_conflicts.h).
    std::vector<ConflictClass> conflictClasses;
    for (int t = 0; t < kAgentTypeCount; ++t)
        if (AgentType(t) != AgentType::Pedestrian) {
            const AgentTypeInfo& info = agentTypeInfo(AgentType(t));
            conflictClasses.push_back({info.sumoClass, info.length, info.width});
        }
    auto widened = widenConflictLanes(netPath, conflictClasses);
    if (!widened) return widened.status();
    sum.conflictLanesWidened = *widened;
    return Status::ok();
}

Status runAll(const std::string& xodrText, const TrafficOptions& opt, const std::string& work, Progress& progress,
              TrafficRunSummary& sum) {
    auto tools = findSumo();
    if (!tools) return tools.status();
    sum.sumoVersion = tools->version;
    const fs::path w(work);
    const std::string logs = (w / "sumo.log").string();
    VISTA_RETURN_IF_ERROR(writeText((w / "city.xodr").string(), xodrText));

    // SUMO's own OpenDRIVE type maps: the second turns the sidewalk lanes into
    // pedestrian lanes (netconvert drops them otherwise).
    if (tools->home.empty())
        return Status::error("SUMO_HOME is not set and not found beside '" + tools->sumo +
                             "': netconvert needs SUMO's type maps (Debian: apt-get install sumo-tools)");
    const fs::path maps = fs::path(tools->home) / "data" / "typemap";
    const std::string typeFiles = (maps / "opendriveNetconvert.typ.xml").string() + "," +
                                  (maps / "opendriveNetconvertPedestrians.typ.xml").string();
    progress.begin("traffic: network (netconvert)");
    VISTA_RETURN_IF_ERROR(runSumoProgram(
        *tools, tools->netconvert,
        {"--opendrive-files", "city.xodr", "--output-file", "city.net.xml", "--type-files", typeFiles,
         "--crossings.guess", "true", "--offset.disable-normalization", "true", "--opendrive.internal-shapes", "true",
         "--opendrive.curve-resolution", "0.5", "--no-turnarounds", "true", "--no-warnings", "true"},
        work, logs));
    VISTA_RETURN_IF_ERROR(stripGeneratedDate((w / "city.net.xml").string()));
    VISTA_RETURN_IF_ERROR(adaptJunctionLanes((w / "city.net.xml").string(), sum));
    progress.end();

    progress.begin("traffic: demand");
    auto net = readSumoNet((w / "city.net.xml").string());
    if (!net) return net.status();
    sum.netOffsetX = net->offsetX;
    sum.netOffsetY = net->offsetY;
    auto demand = makeDemandXml(*net, opt.demand, &sum.demand);
    if (!demand) return demand.status();
    VISTA_RETURN_IF_ERROR(writeText((w / "demand.rou.xml").string(), *demand));
    VISTA_RETURN_IF_ERROR(writeText((w / "signals.add.xml").string(), kSignalsAdditional));
    VISTA_RETURN_IF_ERROR(writeText((w / "traffic.sumocfg").string(), sumoConfig(opt)));
    progress.end();

    progress.begin("traffic: simulation (sumo)");
    VISTA_RETURN_IF_ERROR(runSumoProgram(*tools, tools->sumo, {"-c", "traffic.sumocfg"}, work, logs));
    for (const char* out : {"fcd.xml", "signals.xml", "statistics.xml", "collisions.xml"})
        VISTA_RETURN_IF_ERROR(stripGeneratedDate((w / out).string()));
    const Statistics st = readStatistics((w / "statistics.xml").string());
    if (!st.found) return Status::error("sumo wrote no readable statistics ('statistics.xml')");
    sum.vehiclesInserted = st.inserted;
    sum.personsInserted = st.persons;
    sum.collisions = st.collisions;
    sum.teleports = st.teleports;
    sum.emergencyStops = st.emergencyStops;
    auto collisions = readCollisions((w / "collisions.xml").string());
    if (!collisions) return collisions.status();
    sum.collisionEvents = *collisions;
    progress.end();

    nlohmann::ordered_json j;
    j["format"] = "vista-traffic";
    j["version"] = 1;
    j["seed"] = opt.demand.seed;
    j["vehicles"] = opt.demand.vehicles;
    j["pedestrians"] = opt.demand.pedestrians;
    j["duration_s"] = opt.demand.durationS;
    j["step_s"] = opt.stepS;
    j["sumo_version"] = sum.sumoVersion;
    j["xodr_hash"] = hex64(hashBytes64(xodrText.data(), xodrText.size()));
    j["net_offset"] = {sum.netOffsetX, sum.netOffsetY};
    nlohmann::ordered_json types;
    for (int t = 0; t < kAgentTypeCount; ++t) types[agentTypeInfo(AgentType(t)).id] = sum.demand.byType[size_t(t)];
    j["agents_by_type"] = types;
    j["substituted_vehicles"] = sum.demand.substituted;
    nlohmann::ordered_json turns;
    for (const auto& [cls, n] : sum.turnsClosed) turns[cls] = n;
    j["junction_turns_closed"] = turns;
    j["junction_lanes_widened"] = sum.conflictLanesWidened;
    j["sumo"] = {{"vehicles_inserted", sum.vehiclesInserted},
                 {"persons_loaded", sum.personsInserted},
                 {"collisions", sum.collisions},
                 {"collision_events",
                  {{"total", sum.collisionEvents.events},
                   {"vehicle_pedestrian", sum.collisionEvents.withPedestrians},
                   {"vehicle_vehicle", sum.collisionEvents.betweenVehicles}}},
                 {"teleports", sum.teleports},
                 {"emergency_stops", sum.emergencyStops}};
    j["files"] = {{"xodr", "city.xodr"},
                  {"net", "city.net.xml"},
                  {"demand", "demand.rou.xml"},
                  {"config", "traffic.sumocfg"},
                  {"fcd", "fcd.xml"},
                  {"signals", "signals.xml"},
                  {"statistics", "statistics.xml"},
                  {"collisions", "collisions.xml"}};
    VISTA_RETURN_IF_ERROR(writeText((w / "traffic.json").string(), j.dump(2) + "\n"));
    std::error_code ec;
    fs::remove(logs, ec);
    fs::remove(w / kPartialMark, ec);
    return Status::ok();
}

}  // namespace

Status checkTrafficOptions(const TrafficOptions& opt) {
    const auto& d = opt.demand;
    if (d.vehicles < 0 || d.vehicles > kMaxTrafficAgents)
        return Status::error("--vehicles = " + std::to_string(d.vehicles) + ": allowed 0 to " +
                             std::to_string(kMaxTrafficAgents));
    if (d.pedestrians < 0 || d.pedestrians > kMaxTrafficAgents)
        return Status::error("--pedestrians = " + std::to_string(d.pedestrians) + ": allowed 0 to " +
                             std::to_string(kMaxTrafficAgents));
    if (d.vehicles + d.pedestrians == 0) return Status::error("--vehicles and --pedestrians are both 0: no traffic");
    if (!(d.durationS >= 1.0 && d.durationS <= kMaxTrafficDurationS))
        return Status::error("--duration = " + num(d.durationS) + " s: allowed 1 to " + num(kMaxTrafficDurationS) +
                             " s");
    if (!(opt.stepS >= kMinTrafficStepS && opt.stepS <= kMaxTrafficStepS))
        return Status::error("--step = " + num(opt.stepS) + " s: allowed " + num(kMinTrafficStepS) + " to " +
                             num(kMaxTrafficStepS) + " s");
    if (std::fabs(std::round(d.durationS / opt.stepS) * opt.stepS - d.durationS) > 1e-6)
        return Status::error("--duration = " + num(d.durationS) +
                             " s is not a whole number of --step = " + num(opt.stepS) + " s");
    return Status::ok();
}

Status makeTraffic(const std::string& xodrText, const TrafficOptions& opt, const std::string& dir, Progress& progress,
                   TrafficRunSummary* summary) {
    VISTA_RETURN_IF_ERROR(checkTrafficOptions(opt));
    std::error_code ec;
    if (fs::exists(fs::symlink_status(dir, ec)))
        return Status::error("-o = '" + dir + "' exists: a traffic directory is never overwritten; give a new path");
    auto work = freshWorkDir(dir);
    if (!work) return work.status();
    TrafficRunSummary local;
    TrafficRunSummary& sum = summary ? *summary : local;
    if (Status s = runAll(xodrText, opt, *work, progress, sum); !s) {
        fs::remove_all(*work, ec);
        return s;
    }
    fs::rename(*work, dir, ec);
    if (ec) {
        fs::remove_all(*work, ec);
        return Status::error("cannot rename '" + *work + "' to '" + dir + "': " + ec.message());
    }
    return Status::ok();
}

}  // namespace vista
