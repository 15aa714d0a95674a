#include "runtime/traffic/junction_conflicts.h"

#include <expat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <sstream>
#include <unordered_map>

#include "runtime/traffic/net_lane_tags.h"

namespace vista {

namespace {

using Point = std::pair<double, double>;

// A lane's centre line with its cumulative lengths.
struct Line {
    Polyline2 pts;
    std::vector<double> at;  // at[i]: length from the first vertex to vertex i

    explicit Line(Polyline2 p) : pts(std::move(p)) {
        at.assign(pts.size(), 0.0);
        for (size_t i = 1; i < pts.size(); ++i)
            at[i] = at[i - 1] + std::hypot(pts[i].first - pts[i - 1].first, pts[i].second - pts[i - 1].second);
    }
    double length() const { return at.empty() ? 0.0 : at.back(); }
    // The point `s` along the line; beyond its ends, straight on along the
    // first or the last segment.
    Point pointAt(double s) const {
        size_t i = 1;
        while (i + 1 < pts.size() && at[i] < s) ++i;
        const double len = at[i] - at[i - 1];
        const double t = len > 0.0 ? (s - at[i - 1]) / len : 0.0;
        return {pts[i - 1].first + t * (pts[i].first - pts[i - 1].first),
                pts[i - 1].second + t * (pts[i].second - pts[i - 1].second)};
    }
};

double cross(const Point& o, const Point& a, const Point& b) {
    return (a.first - o.first) * (b.second - o.second) - (a.second - o.second) * (b.first - o.first);
}

// Where segments ab and cd meet: the fractions along each, false when apart
// (parallel segments count as apart).
bool segmentsMeet(const Point& a, const Point& b, const Point& c, const Point& d, double* tab, double* tcd) {
    const double rx = b.first - a.first, ry = b.second - a.second;
    const double sx = d.first - c.first, sy = d.second - c.second;
    const double den = rx * sy - ry * sx;
    if (std::fabs(den) < 1e-12) return false;
    const double qx = c.first - a.first, qy = c.second - a.second;
    const double t = (qx * sy - qy * sx) / den, u = (qx * ry - qy * rx) / den;
    if (t < 0.0 || t > 1.0 || u < 0.0 || u > 1.0) return false;
    *tab = t;
    *tcd = u;
    return true;
}

double pointSegmentDistance(const Point& p, const Point& a, const Point& b) {
    const double dx = b.first - a.first, dy = b.second - a.second;
    const double len2 = dx * dx + dy * dy;
    double t = len2 > 0.0 ? ((p.first - a.first) * dx + (p.second - a.second) * dy) / len2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    return std::hypot(p.first - a.first - t * dx, p.second - a.second - t * dy);
}

double segmentDistance(const Point& a, const Point& b, const Point& c, const Point& d) {
    double t = 0, u = 0;
    if (segmentsMeet(a, b, c, d, &t, &u)) return 0.0;
    return std::min({pointSegmentDistance(a, c, d), pointSegmentDistance(b, c, d), pointSegmentDistance(c, a, b),
                     pointSegmentDistance(d, a, b)});
}

// Whether the rectangle `corners` (in order) comes within `reach` of the line.
bool rectangleNear(const Point (&corners)[4], const Line& line, double reach) {
    bool inside = true;  // the line's first vertex inside the rectangle
    for (int k = 0; k < 4; ++k) inside = inside && cross(corners[k], corners[(k + 1) % 4], line.pts[0]) >= 0.0;
    if (inside) return true;
    for (int k = 0; k < 4; ++k)
        for (size_t i = 1; i < line.pts.size(); ++i)
            if (segmentDistance(corners[k], corners[(k + 1) % 4], line.pts[i - 1], line.pts[i]) < reach) return true;
    return false;
}

// The crossing of the two centre lines farthest along `foe`, or -1.
double lastCrossingAlong(const Line& ego, const Line& foe) {
    double best = -1.0;
    for (size_t j = 1; j < foe.pts.size(); ++j)
        for (size_t i = 1; i < ego.pts.size(); ++i) {
            double t = 0, u = 0;
            if (segmentsMeet(foe.pts[j - 1], foe.pts[j], ego.pts[i - 1], ego.pts[i], &t, &u))
                best = std::max(best, foe.at[j - 1] + t * (foe.at[j] - foe.at[j - 1]));
        }
    return best;
}

Polyline2 parseShape(const char* shape) {
    Polyline2 pts;
    std::istringstream in(shape);
    for (std::string p; in >> p;) {
        double x = 0, y = 0;
        if (std::sscanf(p.c_str(), "%lf,%lf", &x, &y) >= 2) pts.push_back({x, y});
    }
    return pts;
}

std::vector<std::string> words(const char* list) {
    std::vector<std::string> out;
    std::istringstream in(list ? list : "");
    for (std::string w; in >> w;) out.push_back(w);
    return out;
}

bool permits(const std::vector<std::string>& allow, bool hasAllow, const std::vector<std::string>& disallow,
             const std::string& cls) {
    auto has = [](const std::vector<std::string>& l, const std::string& w) {
        return std::find(l.begin(), l.end(), w) != l.end();
    };
    if (hasAllow) return has(allow, cls) || has(allow, "all");
    return !has(disallow, cls) && !has(disallow, "all");
}

struct InternalLane {
    Line line{{}};
    double width = 3.2;           // SUMO's default lane width
    double lengthFactor = 1.0;    // the lane's length over its shape's length
    std::vector<size_t> classes;  // indices into the classes it allows
};

// The foe pairs (ego lane id, foe lane id) of the junctions' requests and of
// the internal junctions.
struct JunctionReader {
    XML_Parser parser = nullptr;
    std::vector<std::pair<std::string, std::string>> pairs;
    std::vector<std::string> intLanes;  // of the <junction> being read
    std::vector<Polyline2> crossings;   // the pedestrian crossings' lane shapes
    bool inCrossing = false;            // inside an <edge function="crossing">
    bool sawRoot = false;
    std::string error;

    static const char* attr(const XML_Char** atts, const char* name) {
        for (int i = 0; atts[i]; i += 2)
            if (std::strcmp(atts[i], name) == 0) return atts[i + 1];
        return nullptr;
    }
    void start(const char* name, const XML_Char** atts) {
        if (!sawRoot) {
            sawRoot = true;
            if (std::strcmp(name, "net") != 0) {
                error = std::string("the root element is <") + name + ">, not <net>";
                XML_StopParser(parser, XML_FALSE);
            }
            return;
        }
        if (std::strcmp(name, "edge") == 0) {
            const char* function = attr(atts, "function");
            inCrossing = function && std::strcmp(function, "crossing") == 0;
        } else if (std::strcmp(name, "lane") == 0 && inCrossing) {
            if (const char* shape = attr(atts, "shape")) crossings.push_back(parseShape(shape));
        } else if (std::strcmp(name, "junction") == 0) {
            inCrossing = false;
            intLanes = words(attr(atts, "intLanes"));
            const char* type = attr(atts, "type");
            if (type && std::strcmp(type, "internal") == 0) {
                for (const std::string& in : words(attr(atts, "incLanes")))
                    if (!in.empty() && in[0] == ':') {
                        for (const std::string& foe : intLanes) pairs.push_back({in, foe});
                        break;
                    }
                intLanes.clear();
            }
        } else if (std::strcmp(name, "request") == 0 && !intLanes.empty()) {
            const char *index = attr(atts, "index"), *foes = attr(atts, "foes");
            if (!index || !foes) return;
            const long i = std::strtol(index, nullptr, 10);
            const size_t n = std::strlen(foes);
            if (i < 0 || size_t(i) >= intLanes.size()) return;
            for (size_t j = 0; j < n && j < intLanes.size(); ++j)
                if (foes[n - 1 - j] == '1' && j != size_t(i)) pairs.push_back({intLanes[size_t(i)], intLanes[j]});
        }
    }
};

Result<JunctionReader> readJunctions(const std::string& netPath, const std::string& text) {
    JunctionReader r;
    r.parser = XML_ParserCreate(nullptr);
    std::unique_ptr<XML_ParserStruct, void (*)(XML_Parser)> guard(r.parser, &XML_ParserFree);
    XML_SetUserData(r.parser, &r);
    XML_SetStartElementHandler(
        r.parser, [](void* u, const XML_Char* n, const XML_Char** a) { static_cast<JunctionReader*>(u)->start(n, a); });
    if (XML_Parse(r.parser, text.data(), int(text.size()), 1) == XML_STATUS_ERROR || !r.error.empty()) {
        const std::string why = r.error.empty() ? XML_ErrorString(XML_GetErrorCode(r.parser)) : r.error;
        return Status::error("SUMO network '" + netPath + "', line " +
                             std::to_string(XML_GetCurrentLineNumber(r.parser)) + ": " + why);
    }
    r.parser = nullptr;
    return r;
}

bool samePoint(const Point& a, const Point& b) { return std::hypot(a.first - b.first, a.second - b.second) < 0.1; }

// The smallest width w for which SUMO's past-the-crossing test, back >
// k * max(0, crossing - w / 2) + w (lane positions, k the length factor),
// needs the back at least k * (crossing + half) along the lane.
double widthForClearance(double crossing, double half, double k) {
    auto threshold = [&](double w) { return k * std::max(0.0, crossing - 0.5 * w) + w; };
    const double need = k * (crossing + half);
    double lo = 0.0, hi = kMaxConflictWidthM;
    if (threshold(hi) < need) return hi;
    for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        (threshold(mid) >= need ? hi : lo) = mid;
    }
    return hi;
}

std::string withWidth(std::string tag, double width) {
    char value[32];
    std::snprintf(value, sizeof value, "%.2f", width);
    const std::string key = " width=\"";
    const size_t at = tag.find(key);
    if (at == std::string::npos) return tag + key + value + "\"";
    const size_t begin = at + key.size(), stop = tag.find('"', begin);
    tag.replace(begin, stop - begin, value);
    return tag;
}

}  // namespace

double conflictHalfWidth(const Polyline2& ego, const Polyline2& foe, double egoWidthM, double foeLengthM,
                         double foeWidthM) {
    if (ego.size() < 2 || foe.size() < 2) return 0.0;
    const Line e(ego), f(foe);
    const double crossing = lastCrossingAlong(e, f);
    if (crossing < 0.0) return 0.0;
    const double reach = 0.5 * egoWidthM, side = 0.5 * foeWidthM;
    for (double h = 0.0; crossing + h <= f.length(); h += kConflictStepM) {
        const Point back = f.pointAt(crossing + h), front = f.pointAt(crossing + h + foeLengthM);
        const double dx = front.first - back.first, dy = front.second - back.second, len = std::hypot(dx, dy);
        if (len <= 0.0) continue;
        const double nx = -dy / len * side, ny = dx / len * side;
        // Counter-clockwise: back right, front right, front left, back left.
        const Point corners[4] = {{back.first - nx, back.second - ny},
                                  {front.first - nx, front.second - ny},
                                  {front.first + nx, front.second + ny},
                                  {back.first + nx, back.second + ny}};
        if (!rectangleNear(corners, e, reach)) return h;
    }
    return f.length() - crossing;
}

Result<size_t> widenConflictLanes(const std::string& netPath, const std::vector<ConflictClass>& classes) {
    std::unordered_map<std::string, size_t> index;  // lane id -> scan order
    std::vector<InternalLane> lanes;
    auto net = scanInternalLanes(netPath, [&](const LaneTag& tag) -> Result<bool> {
        InternalLane lane;
        if (const char* shape = tag.attribute("shape")) lane.line = Line(parseShape(shape));
        if (const char* width = tag.attribute("width")) lane.width = std::atof(width);
        if (const char* length = tag.attribute("length"); length && lane.line.length() > 0.0)
            lane.lengthFactor = std::atof(length) / lane.line.length();
        const char* allow = tag.attribute("allow");
        const std::vector<std::string> allowed = words(allow), denied = words(tag.attribute("disallow"));
        for (size_t c = 0; c < classes.size(); ++c)
            if (permits(allowed, allow != nullptr, denied, classes[c].sumoClass)) lane.classes.push_back(c);
        if (const char* id = tag.attribute("id")) index[id] = lanes.size();
        lanes.push_back(std::move(lane));
        return true;
    });
    if (!net) return net.status();
    auto junctions = readJunctions(netPath, net->text);
    if (!junctions) return junctions.status();

    std::vector<double> widths(lanes.size());
    for (size_t i = 0; i < lanes.size(); ++i) widths[i] = lanes[i].width;
    for (const auto& [egoId, foeId] : junctions->pairs) {
        auto ei = index.find(egoId), fi = index.find(foeId);
        if (ei == index.end() || fi == index.end()) continue;
        const InternalLane &ego = lanes[ei->second], &foe = lanes[fi->second];
        if (ego.line.pts.size() < 2 || foe.line.pts.size() < 2 || ego.classes.empty()) continue;
        if (samePoint(ego.line.pts.front(), foe.line.pts.front()) ||
            samePoint(ego.line.pts.back(), foe.line.pts.back()))
            continue;
        double egoWidth = 0.0;
        for (size_t c : ego.classes) egoWidth = std::max(egoWidth, classes[c].widthM);
        const double crossing = lastCrossingAlong(ego.line, foe.line);
        if (crossing < 0.0) continue;
        for (size_t c : foe.classes) {
            const double half =
                conflictHalfWidth(ego.line.pts, foe.line.pts, egoWidth, classes[c].lengthM, classes[c].widthM);
            double& w = widths[ei->second];
            w = std::max(w, widthForClearance(crossing, half, foe.lengthFactor));
        }
    }
    size_t widened = 0;
    std::vector<bool> changed(lanes.size());
    for (size_t i = 0; i < lanes.size(); ++i) {
        widths[i] = std::ceil(widths[i] * 100.0 - 1e-6) / 100.0;
        // SUMO places a vehicle lane on a pedestrian crossing at its
        // crossing point less half its width, clamped to the crossing's
        // start: kept within, pedestrians and vehicles see each other where
        // they are, whatever the width.
        for (const Polyline2& crossing : junctions->crossings) {
            if (crossing.size() < 2 || lanes[i].line.pts.size() < 2) continue;
            const double at = lastCrossingAlong(lanes[i].line, Line(crossing));
            if (at >= 0.0) widths[i] = std::min(widths[i], std::floor(2.0 * at * 100.0) / 100.0);
        }
        changed[i] = widths[i] > lanes[i].width + 1e-9;
        widened += changed[i] ? 1 : 0;
    }
    VISTA_RETURN_IF_ERROR(rewriteLaneTags(
        netPath, *net, [&](size_t i, const std::string& tag) { return changed[i] ? withWidth(tag, widths[i]) : tag; }));
    return widened;
}

}  // namespace vista
