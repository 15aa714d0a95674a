#include "runtime/scene/paths.h"
#include "foundation/atomic_file.h"
#include "foundation/input_file.h"
#include "foundation/number_text.h"
#include "foundation/statistics.h"
#include "foundation/units.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <sstream>

#include <unistd.h>

#include "foundation/rng.h"
#include "citygen/blocks.h"
#include "citygen/lanes.h"
#include "citygen/terrain.h"
#include "runtime/scene/tour.h"

namespace vista {

namespace {

constexpr double kMinSpeed = 2.0;    // m/s while turning sharply
constexpr double kTurnRadius = 6.0;  // metres of corner cut we allow at full yaw rate
// Car lane keeping: heading rate = speed x (curvature - kLateralGain x
// lateral error - kHeadingGain x heading error), critically damped over
// about 5 m of travel.
constexpr double kLateralGain = 0.3;     // 1/m^2
constexpr double kHeadingGain = 1.1;     // 1/m (2 sqrt(kLateralGain))
constexpr double kBrakeShare = 0.8;      // share of the braking limit the speed profile plans with
constexpr double kProgressWindow = 3.0;  // metres ahead of the progress where the closest route point is searched

// The vehicle is simulated in steps of at most kMaxSimStep seconds whatever
// the sample spacing: steering at a coarser step overshoots and can circle.
constexpr double kMaxSimStep = 1.0 / 30.0;

// The clock of a drive: `samples` kept samples `o.dt` apart after `skip`
// dropped run-up samples, each sample interval simulated in `sub` steps of
// `dt` seconds. The run-up is simulated exactly like the path and then
// dropped, so the first kept sample is where the vehicle is after runUp
// seconds, at speed.
struct DriveClock {
    size_t samples, skip, sub;
    double dt;
    explicit DriveClock(const PathOptions& o)
        : samples(size_t(std::floor(o.duration / o.dt + 1e-9)) + 1),
          skip(size_t(std::floor(o.runUp / o.dt + 1e-9))),
          sub(std::max<size_t>(1, size_t(std::ceil(o.dt / kMaxSimStep - 1e-9)))),
          dt(o.dt / double(sub)) {}
    size_t steps() const { return (samples + skip) * sub; }
    // Step j begins kept sample index() when kept(j).
    bool kept(size_t j) const { return j % sub == 0 && j / sub >= skip; }
    size_t index(size_t j) const { return j / sub - skip; }
};

double headingOf(const glm::dvec2& d) { return std::atan2(d.x, d.y); }  // clockwise from north

// The route: node sequence chosen by a seeded walk, extended on demand.
class Route {
public:
    Route(const StreetGraph& g, uint64_t seed, RouteStyle style) : _g(g), _rng(seed, 0, Stream::Paths) {
        _adj.resize(g.nodes.size());
        for (size_t e = 0; e < g.edges.size(); ++e) {
            _adj[g.edges[e].a].push_back(uint32_t(e));
            _adj[g.edges[e].b].push_back(uint32_t(e));
        }
        if (style == RouteStyle::Tour) {
            std::vector<std::vector<Tour::Arc>> arcs(g.nodes.size());
            for (size_t n = 0; n < g.nodes.size(); ++n)
                for (uint32_t e : _adj[n]) {
                    const uint32_t m = other(e, uint32_t(n));
                    arcs[n].push_back({m, glm::length(g.nodes[m] - g.nodes[n])});
                }
            _tour = std::make_unique<Tour>(g.nodes, std::move(arcs));
        }
        // Start on a random edge whose ends both continue (avoid dead ends).
        std::vector<uint32_t> good;
        for (size_t e = 0; e < g.edges.size(); ++e)
            if (_adj[g.edges[e].a].size() > 1 && _adj[g.edges[e].b].size() > 1) good.push_back(uint32_t(e));
        uint32_t e0 = good.empty() ? uint32_t(_rng.range(0, int64_t(g.edges.size()) - 1))
                                   : good[size_t(_rng.range(0, int64_t(good.size()) - 1))];
        bool flip = _rng.chance(0.5);
        push(flip ? g.edges[e0].b : g.edges[e0].a, e0);
        push(flip ? g.edges[e0].a : g.edges[e0].b, e0);
    }
    // Makes sure the route extends at least `s` metres.
    void ensure(double s) {
        while (_cum.back() < s) extend();
    }
    size_t segments() const { return _pts.size() - 1; }
    const glm::dvec2& point(size_t i) const { return _pts[i]; }
    double cum(size_t i) const { return _cum[i]; }
    glm::dvec2 at(double s) {
        ensure(s);
        size_t i = size_t(std::upper_bound(_cum.begin(), _cum.end(), s) - _cum.begin());
        i = std::clamp<size_t>(i, 1, _pts.size() - 1);
        double len = _cum[i] - _cum[i - 1];
        double f = len > 0 ? (s - _cum[i - 1]) / len : 0.0;
        return glm::mix(_pts[i - 1], _pts[i], std::clamp(f, 0.0, 1.0));
    }
    double segHeading(size_t i) const { return headingOf(_pts[i + 1] - _pts[i]); }

private:
    void push(uint32_t node, uint32_t edge) {
        if (!_pts.empty()) _cum.push_back(_cum.back() + glm::length(_g.nodes[node] - _pts.back()));
        else _cum.push_back(0.0);
        _pts.push_back(_g.nodes[node]);
        _nodes.push_back(node);
        _edges.push_back(edge);
    }
    void extend() {
        uint32_t n = _nodes.back(), prev = _nodes[_nodes.size() - 2], inEdge = _edges.back();
        glm::dvec2 inDir = _g.nodes[n] - _g.nodes[prev];
        double inH = headingOf(inDir);
        std::vector<uint32_t> cand;
        std::vector<double> weight;
        for (uint32_t e : _adj[n]) {
            if (e == inEdge) continue;
            uint32_t m = _g.edges[e].a == n ? _g.edges[e].b : _g.edges[e].a;
            double turn = std::abs(wrapAngle(headingOf(_g.nodes[m] - _g.nodes[n]) - inH));
            double w = turn < 0.5 ? 3.0 : 1.0;
            if (_adj[m].size() <= 1) w *= 0.05;  // avoid dead ends
            cand.push_back(e);
            weight.push_back(w);
        }
        if (cand.empty()) {  // dead end: U-turn
            push(prev, inEdge);
            return;
        }
        if (_tour) {
            std::vector<size_t> allowed;
            for (size_t i = 0; i < _adj[n].size(); ++i)
                if (_adj[n][i] != inEdge) allowed.push_back(i);
            const uint32_t e = _adj[n][_tour->step(n, allowed, _rng)];
            push(other(e, n), e);
            return;
        }
        double total = 0;
        for (double w : weight) total += w;
        double r = _rng.uniform() * total;
        size_t pick = cand.size() - 1;
        for (size_t i = 0; i < cand.size(); ++i) {
            if (r < weight[i]) {
                pick = i;
                break;
            }
            r -= weight[i];
        }
        uint32_t e = cand[pick];
        push(_g.edges[e].a == n ? _g.edges[e].b : _g.edges[e].a, e);
    }

    uint32_t other(uint32_t e, uint32_t n) const { return _g.edges[e].a == n ? _g.edges[e].b : _g.edges[e].a; }

    const StreetGraph& _g;
    Rng _rng;
    std::unique_ptr<Tour> _tour;  // RouteStyle::Tour
    std::vector<std::vector<uint32_t>> _adj;
    std::vector<glm::dvec2> _pts;
    std::vector<double> _cum;
    std::vector<uint32_t> _nodes, _edges;
};

double segDistance(const glm::dvec2& p, const glm::dvec2& a, const glm::dvec2& b, double* tOut = nullptr) {
    glm::dvec2 ab = b - a;
    double l2 = glm::dot(ab, ab);
    double t = l2 > 0 ? std::clamp(glm::dot(p - a, ab) / l2, 0.0, 1.0) : 0.0;
    if (tOut) *tOut = t;
    return glm::length(p - (a + t * ab));
}

std::string fmtNum(double v) {
    char buf[64];
    std::snprintf(buf, sizeof(buf), "%.6g", v);
    return buf;
}

}  // namespace

// An enum's name table (alike in shape to roadClassName in street_graph.cpp: kept, one per enum).
const char* pathKindName(PathKind k) {
    switch (k) {
        case PathKind::Walk: return "walk";
        case PathKind::Car: return "car";
        case PathKind::Fly: return "fly";
    }
    return "?";
}

double defaultSpeed(PathKind k) { return k == PathKind::Walk ? 1.4 : 14.0; }

Result<PathKind> parsePathKind(const std::string& s) {
    if (s == "walk") return PathKind::Walk;
    if (s == "car") return PathKind::Car;
    if (s == "fly") return PathKind::Fly;
    return Status::error("path kind '" + s + "' unknown; expected one of: walk, car, fly");
}

const char* routeStyleName(RouteStyle s) { return s == RouteStyle::Tour ? "tour" : "wander"; }

Result<RouteStyle> parseRouteStyle(const std::string& s) {
    if (s == "tour") return RouteStyle::Tour;
    if (s == "wander") return RouteStyle::Wander;
    return Status::error("route '" + s + "' unknown; expected one of: tour, wander");
}

Status validatePathOptions(const PathOptions& o) {
    auto bad = [](const char* name, double v, const std::string& range) {
        return Status::error(std::string("path option ") + name + " = " + fmtNum(v) + " out of range " + range);
    };
    namespace R = path_range;
    if (!R::duration.contains(o.duration)) return bad("duration", o.duration, R::duration.text() + " s");
    if (!R::dt.contains(o.dt)) return bad("dt", o.dt, R::dt.text() + " s");
    if (!R::speed.contains(o.maxSpeed)) return bad("speed", o.maxSpeed, R::speed.text() + " m/s");
    if (!(o.maxYawRate > 0 && o.maxYawRate <= 4 * kPi))
        return bad("yaw rate", o.maxYawRate, "(0, 720] deg/s (in rad/s)");
    if (!(o.accel > 0) || !(o.decel > 0)) return bad("accel/decel", std::min(o.accel, o.decel), "> 0 m/s^2");
    if (!R::flyHeight.contains(o.flyHeight)) return bad("fly height", o.flyHeight, R::flyHeight.text() + " m");
    if (!(o.flyPitch > -kPi / 2 && o.flyPitch < kPi / 2)) return bad("fly pitch", o.flyPitch, "(-90, 90) deg");
    if (!R::runUp.contains(o.runUp)) return bad("run-up", o.runUp, R::runUp.text() + " s");
    if ((o.duration + o.runUp) / o.dt > 1e7)
        return bad("(duration + run-up)/dt", (o.duration + o.runUp) / o.dt, "<= 1e7 samples");
    return Status::ok();
}

Camera Path::camera(size_t i, const Camera& base) const {
    VISTA_CHECK(i < samples.size());
    Camera c = base;
    c.eye = samples[i].position;
    c.heading = samples[i].heading;
    c.pitch = samples[i].pitch;
    c.time = samples[i].t;
    return c;
}

PathMotion pathMotion(const Path& path, const std::vector<size_t>& frames) {
    PathMotion m;
    std::vector<double> metres, degrees;
    for (size_t k = 1; k < frames.size(); ++k) {
        VISTA_CHECK(frames[k] < path.samples.size() && frames[k - 1] < path.samples.size());
        const PathSample& a = path.samples[frames[k - 1]];
        const PathSample& b = path.samples[frames[k]];
        metres.push_back(glm::length(b.position - a.position));
        const double dh = wrapAngle(b.heading - a.heading), dp = b.pitch - a.pitch;
        degrees.push_back(radToDeg(std::sqrt(dh * dh + dp * dp)));
    }
    if (metres.empty()) return m;
    m.frames = frames.size();
    m.metresMedian = median(metres);
    m.metresMax = *std::max_element(metres.begin(), metres.end());
    m.degreesMedian = median(degrees);
    m.degreesMax = *std::max_element(degrees.begin(), degrees.end());
    return m;
}

std::vector<size_t> Path::spread(size_t n) const {
    std::vector<size_t> out;
    if (samples.empty() || n == 0) return out;
    for (size_t i = 0; i < n; ++i)
        out.push_back(n == 1 ? 0 : size_t(std::llround(double(i) * double(samples.size() - 1) / double(n - 1))));
    return out;
}

std::vector<size_t> Path::runs(size_t n, size_t k) const {
    std::vector<size_t> out;
    if (samples.empty() || n == 0) return out;
    k = std::clamp<size_t>(k, 1, n);
    const size_t S = samples.size();
    for (size_t r = 0; r < k; ++r) {
        const size_t len = n / k + (r < n % k ? 1 : 0);
        const size_t room = S > len ? S - len : 0;  // last possible start
        const size_t start = k == 1 ? 0 : size_t(std::llround(double(r) * double(room) / double(k - 1)));
        for (size_t i = 0; i < len; ++i) out.push_back(std::min(S - 1, start + i));
    }
    return out;
}

double distanceToStreets(const StreetGraph& g, const glm::dvec2& p, int* edge) {
    double best = -1;
    if (edge) *edge = -1;
    for (size_t e = 0; e < g.edges.size(); ++e) {
        double d = segDistance(p, g.nodes[g.edges[e].a], g.nodes[g.edges[e].b]);
        if (best < 0 || d < best) {
            best = d;
            if (edge) *edge = int(e);
        }
    }
    return best;
}

namespace {

// The car: a LaneRoute through the lane model, steered along the lane centre.
Result<Path> driveCar(const StreetGraph& g, const CityParams& params, const PathOptions& o) {
    std::vector<Block> blocks;
    if (params.sidewalk_m > 0.01) blocks = extractBlocks(g, params, nullptr);
    const LaneModel lanes = buildLaneModel(g, params, params.sidewalk_m > 0.01 ? &blocks : nullptr);
    auto made = LaneRoute::create(lanes, o.seed, o.leftHandTraffic, o.route);
    if (!made) return made.status();
    LaneRoute& route = made.value();
    glm::dvec2 pos = route.point(0);
    double h = route.segHeading(0);
    double v = 0.0;
    double sp = 0.0;  // progress along the route (arc length of the closest point)
    size_t seg = 0;
    const double w = o.maxYawRate;
    const DriveClock clock(o);
    const double dt = clock.dt;
    const glm::dvec2 origin(params.origin_x, params.origin_y);
    const double brake = kBrakeShare * o.decel;

    Path path;
    path.samples.reserve(clock.samples);
    path.lanes.reserve(clock.samples);
    for (size_t j = 0; j < clock.steps(); ++j) {
        // Progress: the closest route point a few metres ahead.
        const double horizon = v * v / (2.0 * brake) + 2.0 * v * dt + 3.0;
        route.ensure(sp + horizon + kProgressWindow + 1.0);
        double bestD = 1e300, bestT = 0.0;
        size_t bestSeg = seg;
        for (size_t k = seg; k < route.segments() && (k == seg || route.cum(k) <= sp + kProgressWindow); ++k) {
            double t;
            const double d = segDistance(pos, route.point(k), route.point(k + 1), &t);
            if (d < bestD - 1e-9) bestD = d, bestSeg = k, bestT = t;
        }
        seg = bestSeg;
        sp = std::max(sp, route.cum(seg) + bestT * (route.cum(seg + 1) - route.cum(seg)));

        if (clock.kept(j)) {
            PathSample s;
            s.t = double(clock.index(j)) * o.dt;
            s.position = glm::dvec3(pos + origin, terrainHeight(params, pos) + o.eyeHeight());
            s.heading = wrapAngle(h);
            path.samples.push_back(s);
            path.lanes.push_back(route.position(pos, seg));
        }

        // Steering: the centre line's curvature ahead plus the lateral and
        // heading errors (positive right of the centre line / clockwise of it).
        const glm::dvec2 a = route.point(seg), b = route.point(seg + 1);
        const double ref = route.segHeading(seg);
        const glm::dvec2 foot = a + bestT * (b - a), right(std::cos(ref), -std::sin(ref));
        const double lateral = glm::dot(pos - foot, right), psi = wrapAngle(h - ref);
        const double kappa = route.curvature(bestT < 0.5 ? seg : seg + 1);
        const double rate = v * (kappa - kLateralGain * lateral - kHeadingGain * psi);
        h = wrapAngle(h + std::clamp(rate * dt, -w * dt, w * dt));

        // Speed: below kCarYawShare x yaw limit / curvature at every vertex
        // within braking distance, braking at kBrakeShare of the limit.
        double vt = o.maxSpeed;
        for (size_t k = seg; k < route.vertices() && route.cum(k) <= sp + horizon; ++k) {
            const double c = std::abs(route.curvature(k));
            if (c < 1e-9) continue;
            const double vl = std::min(o.maxSpeed, kCarYawShare * w / c);
            vt = std::min(vt, std::sqrt(vl * vl + 2.0 * brake * std::max(0.0, route.cum(k) - sp)));
        }
        v += std::clamp(vt - v, -o.decel * dt, o.accel * dt);
        v = std::clamp(v, 0.0, o.maxSpeed);
        pos += v * dt * glm::dvec2(std::sin(h), std::cos(h));
    }
    return path;
}

}  // namespace

Result<Path> generatePath(const StreetGraph& g, const CityParams& params, const PathOptions& o) {
    VISTA_RETURN_IF_ERROR(validatePathOptions(o));
    std::string lanesMissing = std::string("a ") + pathKindName(o.kind) + " path does not drive in lanes";
    if (g.edges.empty()) return Status::error("cannot make a path: the city has no streets (street graph has 0 edges)");
    for (const auto& e : g.edges)
        if (e.a >= g.nodes.size() || e.b >= g.nodes.size())
            return Status::error("cannot make a path: street graph edge refers to a missing node");
    if (o.kind == PathKind::Car) {
        // A city whose lanes form no network a car can keep driving (a few
        // dead-end streets too short to turn in, one-way dead ends) still gets
        // a car path: along the street centre lines, as walk paths go, and
        // without lane positions (saveLanePositionsCsv then refuses).
        auto car = driveCar(g, params, o);
        if (car) return car;
        lanesMissing = car.status().message();
    }

    Route route(g, o.seed, o.route);
    glm::dvec2 pos = route.point(0);
    double h = route.segHeading(0);
    double v = 0.0;
    double sp = 0.0;  // progress along the route (arc length of the closest point)
    size_t seg = 0;
    const double w = o.maxYawRate;
    const DriveClock clock(o);
    const double dt = clock.dt;
    const glm::dvec2 origin(params.origin_x, params.origin_y);

    Path path;
    path.lanesMissing = lanesMissing;
    path.samples.reserve(clock.samples);
    for (size_t j = 0; j < clock.steps(); ++j) {
        if (clock.kept(j)) {
            PathSample s;
            s.t = double(clock.index(j)) * o.dt;
            double ground = terrainHeight(params, pos);
            s.position = glm::dvec3(pos + origin, ground + o.eyeHeight());
            s.heading = wrapAngle(h);
            s.pitch = o.kind == PathKind::Fly ? o.flyPitch : 0.0;
            path.samples.push_back(s);
        }

        // Progress: closest point on the next few route segments.
        route.ensure(sp + 200.0);
        double bestD = 1e300;
        size_t bestSeg = seg;
        double bestS = sp;
        for (size_t k = seg; k < std::min(route.segments(), seg + 4); ++k) {
            double t;
            double d = segDistance(pos, route.point(k), route.point(k + 1), &t);
            if (d < bestD - 1e-9) {
                bestD = d;
                bestSeg = k;
                bestS = route.cum(k) + t * (route.cum(k + 1) - route.cum(k));
            }
        }
        seg = bestSeg;
        sp = std::max(sp, bestS);

        // Steering: pure pursuit of a point ahead, yaw rate clamped.
        double look = std::max(3.0, 0.6 * v + 2.0);
        glm::dvec2 target = route.at(sp + look);
        double err = glm::length(target - pos) > 1e-6 ? wrapAngle(headingOf(target - pos) - h) : 0.0;
        double dh = std::clamp(err, -w * dt, w * dt);
        h = wrapAngle(h + dh);

        // Speed: slow down for the sharpest turn within braking distance.
        double horizon = v * v / (2.0 * o.decel) + look + 8.0;
        double turn = 0.0;
        route.ensure(sp + horizon + 1.0);
        for (size_t k = seg; k < route.segments() && route.cum(k) < sp + horizon; ++k) {
            if (route.cum(k + 1) - route.cum(k) < 1e-9) continue;
            turn = std::max(turn, std::abs(wrapAngle(route.segHeading(k) - h)));
        }
        double vt = o.maxSpeed;
        if (turn > 0.26)
            vt = std::clamp(w * kTurnRadius * (kPi / 2) / turn, std::min(kMinSpeed, o.maxSpeed), o.maxSpeed);
        vt = std::min(vt, o.maxSpeed * std::max(0.15, std::cos(std::min(std::abs(err), kPi / 2))));
        vt = std::min(vt, o.maxSpeed);
        v += std::clamp(vt - v, -o.decel * dt, o.accel * dt);
        v = std::clamp(v, 0.0, o.maxSpeed);
        pos += v * dt * glm::dvec2(std::sin(h), std::cos(h));
    }
    return path;
}

Status savePathCsv(const Path& path, const std::string& file) {
    std::string out = "t_s,x_m,y_m,z_m,heading_deg,pitch_deg\n";
    char buf[256];
    for (const auto& s : path.samples) {
        std::snprintf(buf, sizeof(buf), "%.6f,%.4f,%.4f,%.4f,%.6f,%.6f\n", s.t, s.position.x, s.position.y,
                      s.position.z, s.heading * 180.0 / kPi, s.pitch * 180.0 / kPi);
        out += buf;
    }
    return writeFileAtomic(file, out);
}

Status saveLanePositionsCsv(const Path& path, const std::string& file) {
    if (path.lanes.size() != path.samples.size() || path.lanes.empty())
        return Status::error("lane positions: the path has none (" + path.lanesMissing + ")");
    std::string out = "t_s,road_id,lane_id,s_m,t_offset_m\n";
    char buf[160];
    for (size_t i = 0; i < path.samples.size(); ++i) {
        const LanePosition& l = path.lanes[i];
        std::snprintf(buf, sizeof(buf), "%.6f,%llu,%d,%.4f,%.4f\n", path.samples[i].t, (unsigned long long)l.road,
                      l.lane, l.s, l.tOffset);
        out += buf;
    }
    return writeFileAtomic(file, out);
}

Result<Path> loadPathCsv(const std::string& file) {
    auto text = readInputFile("path file", file, kMaxPathCsvBytes);
    if (!text) return text.status();
    // A UTF-8 byte order mark (spreadsheet exports) is not part of the header.
    size_t pos = text->compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
    const std::string where = "path file '" + echoText(file) + "' line ";
    const char* const fieldNames[6] = {"t_s", "x_m", "y_m", "z_m", "heading_deg", "pitch_deg"};
    // Coordinates a renderer and a ray caster can represent: on Earth
    // (|x|, |y| <= 2e7 m, as the city origin), |z| <= 1e5 m, bounded time and heading.
    const double limits[6] = {1e9, 2e7, 2e7, 1e5, 36000.0, 90.0};
    Path path;
    int lineNo = 0;
    while (pos < text->size()) {
        size_t eol = text->find('\n', pos);
        if (eol == std::string::npos) eol = text->size();
        std::string line = text->substr(pos, eol - pos);
        pos = eol + 1;
        ++lineNo;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.empty() || line[0] == '#') continue;
        if (lineNo == 1 && line.rfind("t_s", 0) == 0) continue;  // header
        std::vector<std::string> fields;
        for (size_t a = 0;;) {
            const size_t comma = line.find(',', a);
            std::string f = line.substr(a, comma == std::string::npos ? std::string::npos : comma - a);
            const size_t b = f.find_first_not_of(" \t"), e = f.find_last_not_of(" \t");
            fields.push_back(b == std::string::npos ? std::string() : f.substr(b, e - b + 1));
            if (comma == std::string::npos || fields.size() > 6) break;
            a = comma + 1;
        }
        if (fields.size() != 6)
            return Status::error(where + std::to_string(lineNo) + ": expected 6 comma-separated fields " +
                                 "(t_s,x_m,y_m,z_m,heading_deg,pitch_deg), found " +
                                 (fields.size() > 6 ? std::string("more") : std::to_string(fields.size())));
        double v[6];
        for (int k = 0; k < 6; ++k) {
            auto r = parseRealText(
                where + std::to_string(lineNo) + ": field " + std::to_string(k + 1) + " (" + fieldNames[k] + ")",
                fields[size_t(k)], -limits[k], limits[k]);
            if (!r) return r.status();
            v[k] = *r;
        }
        if (!path.samples.empty() && !(v[0] > path.samples.back().t))
            return Status::error(where + std::to_string(lineNo) + ": time " + fmtNum(v[0]) + " s does not increase");
        if (std::abs(v[5]) >= 90.0)
            return Status::error(where + std::to_string(lineNo) + ": pitch " + fmtNum(v[5]) +
                                 " deg out of range (-90, 90)");
        PathSample s;
        s.t = v[0];
        s.position = {v[1], v[2], v[3]};
        s.heading = v[4] * kPi / 180.0;
        s.pitch = v[5] * kPi / 180.0;
        path.samples.push_back(s);
    }
    if (path.samples.empty()) return Status::error("path file '" + file + "' has no samples");
    return path;
}

}  // namespace vista
