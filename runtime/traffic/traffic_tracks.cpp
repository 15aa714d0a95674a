#include "runtime/traffic/traffic_tracks.h"

#include <expat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <unordered_map>

#include "foundation/atomic_file.h"
#include "foundation/input_file.h"
#include "foundation/units.h"
#include "runtime/traffic/xml_feed.h"

#include <nlohmann/json.hpp>

namespace vista {

namespace {

constexpr double kMaxFcdTime = 1e9;          // s
constexpr double kMaxFcdCoordinate = 2e7;    // m, world frame
constexpr double kMaxFcdAngleDeg = 36000.0;  // degrees
constexpr double kMaxFcdSpeed = 1000.0;      // m/s

const char* attr(const XML_Char** atts, const char* name) {
    for (int i = 0; atts[i]; i += 2)
        if (std::strcmp(atts[i], name) == 0) return atts[i + 1];
    return nullptr;
}

bool number(const char* text, double* out) {
    if (!text || !*text) return false;
    char* end = nullptr;
    *out = std::strtod(text, &end);
    return end && *end == '\0' && std::isfinite(*out);
}

struct Reader {
    XML_Parser parser = nullptr;
    double offsetX = 0.0, offsetY = 0.0;
    TrafficTracks tracks;
    std::unordered_map<std::string, uint32_t> agentIndex;
    bool sawRoot = false, inStep = false;
    std::string error;

    void fail(const std::string& why) {
        if (error.empty()) error = "line " + std::to_string(XML_GetCurrentLineNumber(parser)) + ": " + why;
        XML_StopParser(parser, XML_FALSE);
    }

    void start(const char* name, const XML_Char** atts) {
        if (!sawRoot) {
            if (std::strcmp(name, "fcd-export") != 0)
                return fail(std::string("the root element is <") + name + ">, not <fcd-export>");
            sawRoot = true;
            return;
        }
        if (std::strcmp(name, "timestep") == 0) {
            double t = 0.0;
            if (!number(attr(atts, "time"), &t)) return fail("a <timestep> has no numeric time");
            if (std::abs(t) > kMaxFcdTime) return fail("time " + std::to_string(t) + " is outside [-1e9, 1e9] s");
            if (!tracks.times.empty() && t <= tracks.times.back())
                return fail("time " + std::to_string(t) + " does not follow " + std::to_string(tracks.times.back()));
            tracks.times.push_back(t);
            tracks.frameStart.push_back(uint32_t(tracks.poses.size()));
            inStep = true;
            return;
        }
        const bool vehicle = std::strcmp(name, "vehicle") == 0, person = std::strcmp(name, "person") == 0;
        if (!vehicle && !person) return;
        if (!inStep) return fail(std::string("a <") + name + "> outside a <timestep>");
        const char* id = attr(atts, "id");
        if (!id) return fail(std::string("a <") + name + "> has no id");
        AgentType type = AgentType::Pedestrian;
        if (vehicle) {
            const char* t = attr(atts, "type");
            if (!t || !agentTypeFromId(t, &type) || type == AgentType::Pedestrian)
                return fail(std::string("vehicle '") + id + "' has the type '" + (t ? t : "") +
                            "', not one of car, van, bus, truck, bicycle");
        }
        double x = 0, y = 0, angle = 0, speed = 0;
        if (!number(attr(atts, "x"), &x) || !number(attr(atts, "y"), &y) || !number(attr(atts, "angle"), &angle))
            return fail(std::string("agent '") + id + "' lacks a numeric x, y or angle");
        if (attr(atts, "speed") && !number(attr(atts, "speed"), &speed))
            return fail(std::string("agent '") + id + "' has a speed that is not a number");
        // Ranges (the path CSV's): positions within 2e7 m of the origin once
        // the network offset is removed, angles within 36000 degrees, speeds
        // 0 .. 1000 m/s; beyond them a pose means nothing and would not fit a
        // float.
        if (std::abs(x - offsetX) > kMaxFcdCoordinate || std::abs(y - offsetY) > kMaxFcdCoordinate)
            return fail(std::string("agent '") + id + "' stands outside |x|, |y| <= 2e7 m (world frame)");
        if (std::abs(angle) > kMaxFcdAngleDeg)
            return fail(std::string("agent '") + id + "' has an angle outside [-36000, 36000] degrees");
        if (!(speed >= 0.0 && speed <= kMaxFcdSpeed))
            return fail(std::string("agent '") + id + "' has a speed outside [0, 1000] m/s");
        auto [it, added] = agentIndex.try_emplace(id, uint32_t(tracks.agentIds.size()));
        if (added) {
            tracks.agentIds.push_back(id);
            tracks.agentTypes.push_back(type);
        } else if (tracks.agentTypes[it->second] != type) {
            return fail(std::string("agent '") + id + "' changes its type");
        }
        AgentPose p;
        p.agent = it->second;
        p.x = float(x - offsetX);
        p.y = float(y - offsetY);
        p.heading = float(degToRad(90.0 - angle));
        p.speed = float(speed);
        tracks.poses.push_back(p);
    }
    void end(const char* name) {
        // A stopped parser may still report the end of the element it stopped
        // in (a root <timestep>, say): only a step that started closes one.
        if (std::strcmp(name, "timestep") != 0 || !inStep || !error.empty()) return;
        inStep = false;
        const size_t first = tracks.frameStart.back();  // an empty step (before the first insertion) has no poses
        std::sort(tracks.poses.begin() + first, tracks.poses.end(),
                  [](const AgentPose& a, const AgentPose& b) { return a.agent < b.agent; });
        for (size_t i = first; i + 1 < tracks.poses.size(); ++i)
            if (tracks.poses[i].agent == tracks.poses[i + 1].agent)
                return fail("agent '" + tracks.agentIds[tracks.poses[i].agent] + "' twice in one step");
    }
};

const AgentPose* findIn(const TrafficTracks& t, size_t frame, uint32_t agent) {
    const auto first = t.poses.begin() + t.frameStart[frame];
    const auto last = frame + 1 < t.frameStart.size() ? t.poses.begin() + t.frameStart[frame + 1] : t.poses.end();
    auto it = std::lower_bound(first, last, agent, [](const AgentPose& p, uint32_t a) { return p.agent < a; });
    return it != last && it->agent == agent ? &*it : nullptr;
}

}  // namespace

size_t TrafficTracks::frameAt(double t) const {
    auto it = std::upper_bound(times.begin(), times.end(), t);
    return it == times.begin() ? 0 : size_t(it - times.begin()) - 1;
}

bool TrafficTracks::poseAt(uint32_t agent, double t, AgentPose* out) const {
    if (times.empty() || t < times.front() || t > times.back()) return false;
    const size_t f = frameAt(t);
    const AgentPose* a = findIn(*this, f, agent);
    if (!a) return false;
    *out = *a;
    if (f + 1 >= times.size()) return true;
    const AgentPose* b = findIn(*this, f + 1, agent);
    if (!b) return t == times[f];  // gone after its last sample
    const float w = float((t - times[f]) / (times[f + 1] - times[f]));
    out->x = a->x + (b->x - a->x) * w;
    out->y = a->y + (b->y - a->y) * w;
    out->speed = a->speed + (b->speed - a->speed) * w;
    float turn = std::remainder(b->heading - a->heading, float(kTwoPi));
    out->heading = a->heading + turn * w;
    return true;
}

Result<TrafficTracks> readFcd(const std::string& path, double offsetX, double offsetY) {
    std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
    if (!f) return Status::error("cannot read the floating-car data '" + path + "': " + errnoText());
    Reader r;
    r.offsetX = offsetX;
    r.offsetY = offsetY;
    r.parser = XML_ParserCreate(nullptr);
    std::unique_ptr<XML_ParserStruct, void (*)(XML_Parser)> guard(r.parser, &XML_ParserFree);
    XML_SetUserData(r.parser, &r);
    XML_SetElementHandler(
        r.parser, [](void* u, const XML_Char* n, const XML_Char** a) { static_cast<Reader*>(u)->start(n, a); },
        [](void* u, const XML_Char* n) { static_cast<Reader*>(u)->end(n); });
    if (Status st = feedXml(r.parser, f.get(), r.error, "floating-car data", path); !st.isOk()) return st;
    if (!r.sawRoot) return Status::error("floating-car data '" + path + "' is empty");
    return std::move(r.tracks);
}

Result<TrafficTracks> loadTrafficTracks(const std::string& dir) {
    const std::string manifest = dir + "/traffic.json";
    auto text = readInputFile("traffic manifest", manifest, kMaxManifestBytes);
    if (!text) return Status::error("--traffic = '" + dir + "': " + text.status().message());
    nlohmann::json j = nlohmann::json::parse(*text, nullptr, false);
    if (j.is_discarded() || !j.is_object()) return Status::error("'" + manifest + "' is not a JSON object");
    if (j.value("format", "") != "vista-traffic")
        return Status::error("'" + manifest + "': format is not \"vista-traffic\" (not a `vista traffic` directory)");
    if (!j["version"].is_number_integer() || j["version"].get<int64_t>() != 1)
        return Status::error("'" + manifest + "': version must be 1");
    const auto& off = j["net_offset"];
    if (!off.is_array() || off.size() != 2 || !off[0].is_number() || !off[1].is_number() ||
        !std::isfinite(off[0].get<double>()) || !std::isfinite(off[1].get<double>()))
        return Status::error("'" + manifest + "': net_offset must be two finite numbers");
    const auto& files = j["files"];
    if (!files.is_object() || !files["fcd"].is_string())
        return Status::error("'" + manifest + "': files.fcd is missing");
    const std::string fcd = files["fcd"].get<std::string>();
    if (fcd.empty() || fcd.find('/') != std::string::npos || fcd == "." || fcd == "..")
        return Status::error("'" + manifest + "': files.fcd = '" + fcd + "' must name a file in the directory");
    return readFcd(dir + "/" + fcd, off[0].get<double>(), off[1].get<double>());
}

}  // namespace vista
