#include "runtime/traffic/junction_turns.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "foundation/units.h"
#include "runtime/traffic/net_lane_tags.h"

namespace vista {

namespace {

constexpr double kTurningVertexRad = 1e-3;

std::vector<std::pair<double, double>> parseShape(const char* shape) {
    std::vector<std::pair<double, double>> pts;
    std::istringstream in(shape);
    for (std::string p; in >> p;) {
        double x = 0, y = 0;
        if (std::sscanf(p.c_str(), "%lf,%lf", &x, &y) >= 2) pts.push_back({x, y});
    }
    return pts;
}

std::vector<std::string> words(const std::string& list) {
    std::vector<std::string> out;
    std::istringstream in(list);
    for (std::string w; in >> w;) out.push_back(w);
    return out;
}

bool contains(const std::vector<std::string>& list, const std::string& word) {
    for (const std::string& w : list)
        if (w == word) return true;
    return false;
}

// The start tag of an internal lane rewritten without the classes in
// `remove`: its allow list loses them, or its disallow list (added before
// the tag's end when absent) gains them; the rest of the tag keeps its bytes.
std::string withoutClasses(std::string tag, const std::vector<std::string>& remove) {
    auto valueAt = [&](const char* name, size_t* begin, size_t* stop) {
        const std::string key = std::string(" ") + name + "=\"";
        const size_t at = tag.find(key);
        if (at == std::string::npos) return false;
        *begin = at + key.size();
        *stop = tag.find('"', *begin);
        return *stop != std::string::npos;
    };
    size_t b = 0, s = 0;
    if (valueAt("allow", &b, &s)) {
        std::string kept;
        for (const std::string& w : words(tag.substr(b, s - b)))
            if (!contains(remove, w)) kept += (kept.empty() ? "" : " ") + w;
        tag.replace(b, s - b, kept);
    } else if (valueAt("disallow", &b, &s)) {
        std::string list = tag.substr(b, s - b);
        for (const std::string& w : remove) list += (list.empty() ? "" : " ") + w;
        tag.replace(b, s - b, list);
    } else {
        std::string list;
        for (const std::string& w : remove) list += (list.empty() ? "" : " ") + w;
        tag += " disallow=\"" + list + "\"";
    }
    return tag;
}

}  // namespace

double turnRadius(const std::vector<std::pair<double, double>>& shape) {
    struct Seg {
        double length, heading;
    };
    std::vector<Seg> segs;
    for (size_t i = 1; i < shape.size(); ++i) {
        const double dx = shape[i].first - shape[i - 1].first, dy = shape[i].second - shape[i - 1].second;
        const double len = std::hypot(dx, dy);
        if (len > 1e-6) segs.push_back({len, std::atan2(dy, dx)});
    }
    // The bend runs from the first to the last vertex where the heading
    // turns; the straight parts before and after it do not count.
    double turn = 0.0;
    size_t first = 0, last = 0;
    for (size_t i = 1; i < segs.size(); ++i) {
        const double d = wrapAngle(segs[i].heading - segs[i - 1].heading);
        turn += d;
        if (std::fabs(d) > kTurningVertexRad) {
            if (first == 0) first = i;
            last = i;
        }
    }
    if (std::fabs(turn) < degToRad(kMinTurnDeg) || first == 0) return std::numeric_limits<double>::infinity();
    double bent = 0.0;
    for (size_t i = first; i < last; ++i) bent += segs[i].length;
    return bent / std::fabs(turn);
}

double turningNeedM(double lengthM) {
    // The sagitta R (1 - cos(L / 2R)) falls as R grows (for L / 2R below pi,
    // where the chord of length L exists); bisect for kMaxBoxCutM.
    auto cut = [&](double r) { return r * (1.0 - std::cos(std::min(kPi, lengthM / (2.0 * r)))); };
    double lo = lengthM / (2.0 * kPi), hi = lengthM * lengthM;
    if (cut(lo) <= kMaxBoxCutM) return 0.0;
    if (hi < 1.0) hi = 1.0;
    for (int i = 0; i < 100; ++i) {
        const double mid = 0.5 * (lo + hi);
        (cut(mid) > kMaxBoxCutM ? lo : hi) = mid;
    }
    return hi;
}

Result<std::vector<size_t>> restrictTightTurns(const std::string& netPath, const std::vector<TurnClass>& classes) {
    std::vector<double> needs;
    for (const TurnClass& c : classes) needs.push_back(turningNeedM(c.lengthM));
    std::vector<size_t> closed(classes.size(), 0);
    std::vector<std::vector<std::string>> removed;  // per kept lane, the classes it loses
    auto net = scanInternalLanes(netPath, [&](const LaneTag& lane) -> Result<bool> {
        const char* shape = lane.attribute("shape");
        if (!shape) return false;
        const double radius = turnRadius(parseShape(shape));
        const char *allow = lane.attribute("allow"), *disallow = lane.attribute("disallow");
        const std::vector<std::string> allowed = allow ? words(allow) : std::vector<std::string>{};
        const std::vector<std::string> denied = disallow ? words(disallow) : std::vector<std::string>{};
        std::vector<std::string> remove;
        for (size_t c = 0; c < classes.size(); ++c) {
            const std::string& cls = classes[c].sumoClass;
            if (!(needs[c] > radius)) continue;
            const bool permitted =
                allow ? (contains(allowed, cls) || contains(allowed, "all")) : !contains(denied, cls);
            if (!permitted) continue;
            if (allow && !contains(allowed, cls))
                return Status::error("an internal lane allows 'all': its classes cannot be listed");
            remove.push_back(cls);
            ++closed[c];
        }
        if (remove.empty()) return false;
        removed.push_back(std::move(remove));
        return true;
    });
    if (!net) return net.status();
    VISTA_RETURN_IF_ERROR(rewriteLaneTags(
        netPath, *net, [&](size_t i, const std::string& tag) { return withoutClasses(tag, removed[i]); }));
    return closed;
}

}  // namespace vista
