// The rig file and the poses of a rig's sensors (rig.h).
#include "runtime/engine/rig.h"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <set>

#include <nlohmann/json.hpp>

#include "citygen/json_input.h"
#include "foundation/input_file.h"
#include "foundation/number_text.h"
#include "foundation/units.h"
#include "runtime/scene/camera.h"

namespace vista {

double minFocalLength(const CameraModel& m, bool x) {
    const double c = x ? m.cx : m.cy, size = x ? m.width : m.height;
    // The image's farthest edge from the principal point (pixel centres are at
    // integers, so the image covers [-0.5, size - 0.5]).
    const double extent = std::max(c + 0.5, size - 0.5 - c);
    const double maxAngle = m.fisheye() ? kPi : std::tan(0.5 * kMaxRigPinholeFovDeg * kPi / 180.0);
    return extent / maxAngle;
}

namespace {

using Json = nlohmann::json;

const std::pair<unsigned, const char*> kChannelNames[] = {{kRigRgb, "rgb"},           {kRigDepth, "depth"},
                                                          {kRigSemantic, "semantic"}, {kRigInstance, "instance"},
                                                          {kRigFlow, "flow"},         {kRigBoxes, "boxes"}};

// A place in the rig file: its JSON pointer (number texts) and its path for messages.
struct Where {
    std::string ptr, path;
    Where key(const std::string& k) const { return {ptr + "/" + k, path.empty() ? k : path + "." + k}; }
    Where index(size_t i) const { return {ptr + "/" + std::to_string(i), path + "[" + std::to_string(i) + "]"}; }
};

// Reads the fields of the rig file's objects with messages that name them.
class FieldReader {
public:
    FieldReader(const JsonInput& in, const std::string& source) : _in(in), _source(source) {}

    Status error(const Where& w, const std::string& what) const {
        return Status::error(_source + ": " + w.path + " " + what);
    }
    // Every key of `obj` is one of `known` (or starts with '_').
    Status keys(const Json& obj, const Where& w, std::initializer_list<const char*> known) const {
        for (auto it = obj.begin(); it != obj.end(); ++it) {
            if (!it.key().empty() && it.key()[0] == '_') continue;
            bool ok = false;
            std::string list;
            for (const char* k : known) {
                ok = ok || it.key() == k;
                list += std::string(list.empty() ? "" : ", ") + k;
            }
            if (!ok)
                return Status::error(_source + ": " + (w.path.empty() ? std::string("the rig") : w.path) +
                                     " has an unknown field '" + echoText(it.key()) + "' (known: " + list + ")");
        }
        return Status::ok();
    }
    Status object(const Json& v, const Where& w) const {
        return v.is_object() ? Status::ok() : error(w, "must be a JSON object, got " + echoText(v.dump()));
    }
    // An optional real within `range` (`unit` ends the message).
    Status real(const Json& obj, const Where& parent, const char* key, const RealRange& range, const char* unit,
                double& out, bool required = false) const {
        const Where w = parent.key(key);
        if (!obj.contains(key)) return required ? error(w, "is missing") : Status::ok();
        return realValue(obj[key], w, range, unit, out);
    }
    Status realValue(const Json& v, const Where& w, const RealRange& range, const char* unit, double& out) const {
        if (!v.is_number()) return error(w, "must be a number, got " + echoText(v.dump()));
        const double d = v.get<double>();
        if (!range.contains(d))
            return error(w, "= " + _in.textOf(w.ptr, v) + " is out of range " + range.text() + " (" + unit + ")");
        out = d;
        return Status::ok();
    }
    Status integer(const Json& obj, const Where& parent, const char* key, int64_t min, int64_t max, int& out,
                   bool required = false) const {
        const Where w = parent.key(key);
        if (!obj.contains(key)) return required ? error(w, "is missing") : Status::ok();
        const Json& v = obj[key];
        const std::string written = _in.textOf(w.ptr, v);
        if (!v.is_number() || written.find_first_of(".eE") != std::string::npos)
            return error(w, "must be a whole number in " + std::to_string(min) + " .. " + std::to_string(max) +
                                ", got " + echoText(v.dump()));
        auto r = parseSignedText(w.path, written, min, max);
        if (!r)
            return error(w, "= " + written + " is out of range " + std::to_string(min) + " .. " + std::to_string(max));
        out = int(*r);
        return Status::ok();
    }

private:
    const JsonInput& _in;
    std::string _source;
};

Status readMount(const FieldReader& r, const Json& s, const Where& w, SensorMount& m) {
    if (!s.contains("pose")) return Status::ok();
    const Where p = w.key("pose");
    const Json& pose = s["pose"];
    VISTA_RETURN_IF_ERROR(r.object(pose, p));
    VISTA_RETURN_IF_ERROR(r.keys(pose, p, {"x", "y", "z", "yaw_deg", "pitch_deg", "roll_deg"}));
    const RealRange metres = RealRange::closed(-100, 100);
    VISTA_RETURN_IF_ERROR(r.real(pose, p, "x", metres, "metres", m.position.x));
    VISTA_RETURN_IF_ERROR(r.real(pose, p, "y", metres, "metres", m.position.y));
    VISTA_RETURN_IF_ERROR(r.real(pose, p, "z", metres, "metres", m.position.z));
    VISTA_RETURN_IF_ERROR(r.real(pose, p, "yaw_deg", RealRange::closed(-360, 360), "degrees", m.yawDeg));
    VISTA_RETURN_IF_ERROR(r.real(pose, p, "pitch_deg", RealRange::closed(-90, 90), "degrees", m.pitchDeg));
    return r.real(pose, p, "roll_deg", RealRange::closed(-180, 180), "degrees", m.rollDeg);
}

// fx and fy at least minFocalLength(): below it a pinhole image would span
// kMaxRigPinholeFovDeg or more, a fisheye's edge would lie past straight
// behind (the message says which and across which side).
Status checkFocalLowerBound(const FieldReader& r, const Json& in, const Where& iw, CameraModel& m) {
    for (const bool x : {true, false}) {
        const double minF = minFocalLength(m, x);
        const std::string why = "pixels; below " + shortNumber(minF) + " the image would span " +
                                (m.fisheye() ? std::string("more than 360 degrees")
                                             : "more than " + shortNumber(kMaxRigPinholeFovDeg) + " degrees") +
                                " across its " + (x ? "width" : "height");
        VISTA_RETURN_IF_ERROR(
            r.real(in, iw, x ? "fx" : "fy", RealRange::closed(minF, kMaxFocalLength), why.c_str(), x ? m.fx : m.fy));
    }
    return Status::ok();
}

Status readCamera(const FieldReader& r, const Json& s, const Where& w, bool fisheye, RigCamera& c) {
    VISTA_RETURN_IF_ERROR(r.keys(s, w, {"name", "type", "pose", "rate_hz", "intrinsics", "channels"}));
    CameraModel& m = c.model;
    m.kind = fisheye ? CameraModel::Kind::Fisheye : CameraModel::Kind::Pinhole;
    const Where iw = w.key("intrinsics");
    if (!s.contains("intrinsics")) return r.error(iw, "is missing");
    const Json& in = s["intrinsics"];
    VISTA_RETURN_IF_ERROR(r.object(in, iw));
    if (fisheye) VISTA_RETURN_IF_ERROR(r.keys(in, iw, {"width", "height", "fx", "fy", "cx", "cy", "max_fov_deg"}));
    else VISTA_RETURN_IF_ERROR(r.keys(in, iw, {"width", "height", "fx", "fy", "cx", "cy"}));
    VISTA_RETURN_IF_ERROR(r.integer(in, iw, "width", 1, 8192, m.width, true));
    VISTA_RETURN_IF_ERROR(r.integer(in, iw, "height", 1, 8192, m.height, true));
    const RealRange focal = RealRange::openMin(0, kMaxFocalLength);
    VISTA_RETURN_IF_ERROR(r.real(in, iw, "fx", focal, "pixels", m.fx, true));
    VISTA_RETURN_IF_ERROR(r.real(in, iw, "fy", focal, "pixels", m.fy, true));
    VISTA_RETURN_IF_ERROR(r.real(in, iw, "cx", RealRange::closed(0, m.width), "pixels", m.cx, true));
    VISTA_RETURN_IF_ERROR(r.real(in, iw, "cy", RealRange::closed(0, m.height), "pixels", m.cy, true));
    if (fisheye)
        VISTA_RETURN_IF_ERROR(r.real(in, iw, "max_fov_deg", RealRange::openMin(0, 360), "degrees", m.maxFovDeg, true));
    VISTA_RETURN_IF_ERROR(checkFocalLowerBound(r, in, iw, m));
    const Where cw = w.key("channels");
    if (!s.contains("channels"))
        return r.error(cw, "is missing (a list of rgb, depth, semantic, instance, flow, boxes)");
    const Json& ch = s["channels"];
    if (!ch.is_array() || ch.empty())
        return r.error(
            cw, "must be a non-empty list of rgb, depth, semantic, instance, flow, boxes, got " + echoText(ch.dump()));
    for (size_t i = 0; i < ch.size(); ++i) {
        unsigned bit = 0;
        for (const auto& [b, name] : kChannelNames)
            if (ch[i].is_string() && ch[i].get<std::string>() == name) bit = b;
        if (!bit)
            return r.error(cw.index(i), "= " + echoText(ch[i].dump()) +
                                            " is not a channel (rgb, depth, semantic, instance, flow, boxes)");
        if (c.channels & bit) return r.error(cw.index(i), "= " + ch[i].dump() + " is given twice");
        c.channels |= bit;
    }
    return Status::ok();
}

Status readBeams(const FieldReader& r, const Json& s, const Where& w, LidarSpec& spec) {
    const Where bw = w.key("beams");
    if (!s.contains("beams"))
        return r.error(bw, "is missing (a list of elevations in degrees, or {\"count\", \"min_deg\", \"max_deg\"})");
    const Json& b = s["beams"];
    const RealRange elevation = RealRange::closed(-90, 90);
    spec.elevationDeg.clear();
    if (b.is_array()) {
        if (b.empty() || b.size() > size_t(kMaxLidarBeams))
            return r.error(
                bw, "has " + std::to_string(b.size()) + " elevations, allowed 1 .. " + std::to_string(kMaxLidarBeams));
        for (size_t i = 0; i < b.size(); ++i) {
            double e = 0;
            VISTA_RETURN_IF_ERROR(r.realValue(b[i], bw.index(i), elevation, "degrees", e));
            spec.elevationDeg.push_back(e);
        }
        return Status::ok();
    }
    if (!b.is_object())
        return r.error(
            bw, "must be a list of elevations or {\"count\", \"min_deg\", \"max_deg\"}, got " + echoText(b.dump()));
    VISTA_RETURN_IF_ERROR(r.keys(b, bw, {"count", "min_deg", "max_deg"}));
    int count = 0;
    double lo = 0, hi = 0;
    VISTA_RETURN_IF_ERROR(r.integer(b, bw, "count", 1, kMaxLidarBeams, count, true));
    VISTA_RETURN_IF_ERROR(r.real(b, bw, "min_deg", elevation, "degrees", lo, true));
    VISTA_RETURN_IF_ERROR(r.real(b, bw, "max_deg", RealRange::closed(lo, 90), "degrees, at least min_deg", hi, true));
    spec.elevationDeg = evenBeamTable(count, lo, hi);
    return Status::ok();
}

Status readLidar(const FieldReader& r, const Json& s, const Where& w, RigLidar& l) {
    VISTA_RETURN_IF_ERROR(r.keys(s, w,
                                 {"name", "type", "pose", "rate_hz", "beams", "columns", "min_range_m", "max_range_m",
                                  "rotation_hz", "start_azimuth_deg", "clockwise"}));
    LidarSpec& spec = l.spec;
    VISTA_RETURN_IF_ERROR(readBeams(r, s, w, spec));
    VISTA_RETURN_IF_ERROR(r.integer(s, w, "columns", 1, 65536, spec.columns));
    if (spec.elevationDeg.size() * size_t(spec.columns) > kMaxLidarRays)
        return r.error(w.key("columns"), "= " + std::to_string(spec.columns) + " with " +
                                             std::to_string(spec.elevationDeg.size()) + " beams is more than " +
                                             std::to_string(kMaxLidarRays) + " rays per sweep (beams x columns)");
    VISTA_RETURN_IF_ERROR(r.real(s, w, "min_range_m", RealRange::openMax(0, 10000), "metres", spec.minRange));
    VISTA_RETURN_IF_ERROR(r.real(s, w, "max_range_m", RealRange::openMin(spec.minRange, 10000),
                                 "metres, beyond min_range_m", spec.maxRange));
    if (!(spec.maxRange > spec.minRange))
        return r.error(w.key("max_range_m"), "must be larger than min_range_m = " + shortNumber(spec.minRange));
    VISTA_RETURN_IF_ERROR(
        r.real(s, w, "rotation_hz", RealRange::openMin(0, 100), "revolutions per second", spec.rotationHz));
    VISTA_RETURN_IF_ERROR(
        r.real(s, w, "start_azimuth_deg", RealRange::closed(-360, 360), "degrees", spec.startAzimuthDeg));
    if (s.contains("clockwise")) {
        if (!s["clockwise"].is_boolean())
            return r.error(w.key("clockwise"), "must be true or false, got " + echoText(s["clockwise"].dump()));
        spec.clockwise = s["clockwise"].get<bool>();
    }
    if (l.rateHz == 0) l.rateHz = spec.rotationHz;
    const Status v = validateLidarSpec(spec);
    return v ? v : r.error(w, v.message());
}

bool validName(const std::string& n) {
    if (n.empty() || n.size() > 32) return false;
    for (char c : n)
        if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-')) return false;
    return true;
}

Status readSensor(const FieldReader& r, const Json& s, const Where& w, Rig& rig, std::set<std::string>& names) {
    VISTA_RETURN_IF_ERROR(r.object(s, w));
    const Where nw = w.key("name"), tw = w.key("type");
    if (!s.contains("name") || !s["name"].is_string() || !validName(s["name"].get<std::string>()))
        return r.error(nw, (s.contains("name") ? "= " + echoText(s["name"].dump()) + " is not a name"
                                               : std::string("is missing")) +
                               " (1 .. 32 characters of A-Z, a-z, 0-9, _ and -)");
    const std::string name = s["name"];
    if (!names.insert(name).second) return r.error(nw, "= \"" + name + "\" is used by two sensors (names are unique)");
    const std::string type = s.contains("type") && s["type"].is_string() ? s["type"].get<std::string>() : "";
    if (type != "pinhole" && type != "fisheye" && type != "lidar")
        return r.error(tw, (s.contains("type") ? "= " + echoText(s["type"].dump()) : std::string("is missing")) +
                               " (allowed: \"pinhole\", \"fisheye\", \"lidar\")");
    SensorMount mount;
    VISTA_RETURN_IF_ERROR(readMount(r, s, w, mount));
    double rate = 0;
    VISTA_RETURN_IF_ERROR(r.real(s, w, "rate_hz", RealRange::openMin(0, 1000), "per second", rate));
    rig.order.push_back(name);
    if (type == "lidar") {
        RigLidar l;
        l.name = name;
        l.mount = mount;
        l.rateHz = rate;
        VISTA_RETURN_IF_ERROR(readLidar(r, s, w, l));
        rig.lidars.push_back(std::move(l));
        return Status::ok();
    }
    RigCamera c;
    c.name = name;
    c.mount = mount;
    c.rateHz = rate;
    VISTA_RETURN_IF_ERROR(readCamera(r, s, w, type == "fisheye", c));
    rig.cameras.push_back(std::move(c));
    return Status::ok();
}

}  // namespace

std::string rigChannelList(unsigned channels) {
    std::string s;
    for (const auto& [bit, name] : kChannelNames)
        if (channels & bit) s += (s.empty() ? "" : ",") + std::string(name);
    return s;
}

Result<Rig> parseRigJson(const std::string& text, const std::string& source) {
    auto input = parseJsonInput(text, source);
    if (!input) return input.status();
    const FieldReader r(*input, source);
    const Json& doc = input->doc;
    const Where root;
    if (!doc.is_object()) return Status::error(source + ": a rig file is a JSON object {\"sensors\": [...]}");
    VISTA_RETURN_IF_ERROR(r.keys(doc, root, {"sensors"}));
    const Where sw = root.key("sensors");
    if (!doc.contains("sensors")) return r.error(sw, "is missing (a list of 1 .. 64 sensors)");
    const Json& sensors = doc["sensors"];
    if (!sensors.is_array() || sensors.empty() || sensors.size() > size_t(kMaxRigSensors))
        return r.error(
            sw, "must be a list of 1 .. " + std::to_string(kMaxRigSensors) + " sensors, got " +
                    (sensors.is_array() ? std::to_string(sensors.size()) + " entries" : echoText(sensors.dump())));
    Rig rig;
    std::set<std::string> names;
    for (size_t i = 0; i < sensors.size(); ++i)
        VISTA_RETURN_IF_ERROR(readSensor(r, sensors[i], sw.index(i), rig, names));
    return rig;
}

Result<Rig> loadRigFile(const std::string& path) {
    auto text = readInputFile("rig file", path, kMaxRigFileBytes);
    if (!text) return text.status();
    return parseRigJson(*text, path);
}

std::string rigToJson(const Rig& rig) {
    nlohmann::ordered_json sensors = nlohmann::ordered_json::array();
    auto pose = [](const SensorMount& m) {
        return nlohmann::ordered_json{{"x", m.position.x},   {"y", m.position.y},       {"z", m.position.z},
                                      {"yaw_deg", m.yawDeg}, {"pitch_deg", m.pitchDeg}, {"roll_deg", m.rollDeg}};
    };
    for (const std::string& name : rig.order) {
        for (const RigCamera& c : rig.cameras) {
            if (c.name != name) continue;
            const CameraModel& m = c.model;
            nlohmann::ordered_json in{{"width", m.width}, {"height", m.height}, {"fx", m.fx},
                                      {"fy", m.fy},       {"cx", m.cx},         {"cy", m.cy}};
            if (m.fisheye()) in["max_fov_deg"] = m.maxFovDeg;
            nlohmann::ordered_json ch = nlohmann::ordered_json::array();
            for (const auto& [bit, n] : kChannelNames)
                if (c.channels & bit) ch.push_back(n);
            sensors.push_back({{"name", c.name},
                               {"type", m.fisheye() ? "fisheye" : "pinhole"},
                               {"pose", pose(c.mount)},
                               {"rate_hz", c.rateHz},
                               {"intrinsics", in},
                               {"channels", ch}});
        }
        for (const RigLidar& l : rig.lidars) {
            if (l.name != name) continue;
            const LidarSpec& s = l.spec;
            sensors.push_back({{"name", l.name},
                               {"type", "lidar"},
                               {"pose", pose(l.mount)},
                               {"rate_hz", l.rateHz},
                               {"beams", s.elevationDeg},
                               {"columns", s.columns},
                               {"min_range_m", s.minRange},
                               {"max_range_m", s.maxRange},
                               {"rotation_hz", s.rotationHz},
                               {"start_azimuth_deg", s.startAzimuthDeg},
                               {"clockwise", s.clockwise}});
        }
    }
    return nlohmann::ordered_json{{"sensors", sensors}}.dump(2);
}

glm::dmat3 mountRotation(const SensorMount& m) {
    const double y = degToRad(m.yawDeg), p = degToRad(m.pitchDeg), r = degToRad(m.rollDeg);
    // glm matrices are column-major: m[col][row].
    glm::dmat3 rz(1.0), ry(1.0), rx(1.0);
    rz[0][0] = std::cos(y), rz[0][1] = std::sin(y), rz[1][0] = -std::sin(y), rz[1][1] = std::cos(y);
    // Rotation about y by -pitch: x goes to (cos p, 0, sin p).
    ry[0][0] = std::cos(p), ry[0][2] = std::sin(p), ry[2][0] = -std::sin(p), ry[2][2] = std::cos(p);
    rx[1][1] = std::cos(r), rx[1][2] = std::sin(r), rx[2][1] = -std::sin(r), rx[2][2] = std::cos(r);
    return rz * ry * rx;
}

RigPose vehiclePose(const PathSample& s) {
    LidarPose lp;
    lp.heading = s.heading;
    lp.pitch = s.pitch;
    return {s.position, lidarToWorld(lp)};
}

RigPose vehiclePoseAt(const Path& path, double t) {
    const auto& s = path.samples;
    VISTA_CHECK(!s.empty());
    if (!(t > s.front().t)) return vehiclePose(s.front());
    if (!(t < s.back().t)) return vehiclePose(s.back());
    const auto it = std::upper_bound(s.begin(), s.end(), t, [](double v, const PathSample& p) { return v < p.t; });
    const PathSample& a = *(it - 1);
    const PathSample& b = *it;
    const double w = (t - a.t) / (b.t - a.t);
    PathSample m;
    m.t = t;
    m.position = a.position + w * (b.position - a.position);
    m.pitch = a.pitch + w * (b.pitch - a.pitch);
    m.heading = a.heading + w * std::remainder(b.heading - a.heading, kTwoPi);
    return vehiclePose(m);
}

RigPose sensorPose(const RigPose& v, const SensorMount& m) {
    return {v.position + v.rotation * m.position, v.rotation * mountRotation(m)};
}

LidarPose lidarPoseOf(const RigPose& pose) {
    const glm::dvec3 f = pose.rotation[0], right = -pose.rotation[1];
    LidarPose lp;
    lp.position = pose.position;
    lp.heading = std::atan2(f.x, f.y);
    lp.pitch = std::asin(std::clamp(f.z, -1.0, 1.0));
    Camera c;
    c.heading = lp.heading;
    c.pitch = lp.pitch;
    const glm::dvec3 r0(std::cos(lp.heading), -std::sin(lp.heading), 0.0);
    const glm::dvec3 u0 = glm::cross(r0, c.forward());
    lp.roll = std::atan2(-glm::dot(right, u0), glm::dot(right, r0));
    return lp;
}

std::vector<uint8_t> firingFrames(double rateHz, const std::vector<double>& times) {
    std::vector<uint8_t> fire(times.size(), 0);
    double last = 0;
    for (size_t f = 0; f < times.size(); ++f) {
        if (f == 0 || rateHz <= 0 || times[f] - last >= 1.0 / rateHz - 1e-6) {
            fire[f] = 1;
            last = times[f];
        }
    }
    return fire;
}

double nextFiringTime(double rateHz, const std::vector<uint8_t>& fires, const std::vector<double>& times, size_t f,
                      double sampleAfter) {
    for (size_t g = f + 1; g < times.size(); ++g)
        if (fires[g] && times[g] > times[f]) return times[g];
    return rateHz > 0 ? times[f] + 1.0 / rateHz : sampleAfter;
}

}  // namespace vista
