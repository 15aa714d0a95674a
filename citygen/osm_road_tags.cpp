// OSM road tag parsing; contract in osm_road_tags.h.
#include "citygen/osm_road_tags.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <tuple>
#include <utility>

#include <nlohmann/json.hpp>

#include "citygen/osm_buildings.h"

namespace vista {

namespace {

constexpr float kMph = 1.609344f, kKnot = 1.852f;

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
    return s;
}

// A plain non-negative decimal at the start of `s` ("50", "50.5"); advances `s`.
bool leadingNumber(std::string_view& s, double& v) {
    size_t p = 0;
    bool dot = false, any = false;
    while (p < s.size() && p < 24) {
        const char c = s[p];
        if (c >= '0' && c <= '9') any = true;
        else if (c == '.' && !dot) dot = true;
        else break;
        ++p;
    }
    if (!any || (p < s.size() && ((s[p] >= '0' && s[p] <= '9') || s[p] == '.'))) return false;
    auto r = std::from_chars(s.data(), s.data() + p, v);
    if (r.ec != std::errc() || r.ptr != s.data() + p || !std::isfinite(v)) return false;
    s.remove_prefix(p);
    return true;
}

// A limit within [kMinMaxspeedKmh, kMaxMaxspeedKmh]; anything else is no usable value.
std::optional<float> plausibleSpeed(double kmh) {
    if (!(kmh >= kMinMaxspeedKmh && kmh <= kMaxMaxspeedKmh)) return std::nullopt;
    return float(kmh);
}

struct CountrySpeeds {
    const char* code;
    float urban, rural, trunk, motorway;  // km/h; 0 = no single default
};
// Default limits of the countries with a common national rule (OSM wiki "Default speed limits").
constexpr CountrySpeeds kCountries[] = {
    {"AT", 50, 100, 100, 130},
    {"BE", 50, 90, 120, 120},
    {"CH", 50, 80, 100, 120},
    {"CZ", 50, 90, 110, 130},
    {"DE", 50, 100, 0, kMaxspeedNoneKmh},
    {"DK", 50, 80, 0, 130},
    {"ES", 50, 90, 0, 120},
    {"FI", 50, 80, 0, 120},
    {"FR", 50, 80, 110, 130},
    {"GB", 30 * kMph, 60 * kMph, 70 * kMph, 70 * kMph},
    {"HU", 50, 90, 110, 130},
    {"IE", 50, 80, 100, 120},
    {"IT", 50, 90, 110, 130},
    {"NL", 50, 80, 100, 130},
    {"NO", 50, 80, 0, 90},
    {"PL", 50, 90, 0, 140},
    {"PT", 50, 90, 100, 120},
    {"RO", 50, 90, 0, 130},
    {"RU", 60, 90, 0, 110},
    {"SE", 50, 70, 0, 110},
    {"SI", 50, 90, 110, 130},
    {"SK", 50, 90, 0, 130},
    {"UA", 50, 90, 0, 130},
};

bool isTurnValue(std::string_view v) {
    static const char* kValues[] = {"none",           "through",      "left",        "slight_left", "sharp_left",
                                    "right",          "slight_right", "sharp_right", "reverse",     "merge_to_left",
                                    "merge_to_right", "slide_left",   "slide_right"};
    for (const char* k : kValues)
        if (v == k) return true;
    return false;
}

// The usable value of an optional tag, counting a present but unusable one as a fallback.
template <class T, class Parse>
std::optional<T> readTag(const OsmTagLookup& tag, const char* key, Parse parse, OsmTagUse& use) {
    const char* v = tag(key);
    if (!v) return std::nullopt;
    std::optional<T> r = parse(std::string_view(v));
    if (!r) ++use.fallback;
    return r;
}

}  // namespace

std::optional<int> parseOsmLaneCount(std::string_view text) {
    const std::string_view s = trim(text);
    if (s.empty() || s.size() > 6) return std::nullopt;
    int v = 0;
    auto r = std::from_chars(s.data(), s.data() + s.size(), v);
    if (r.ec != std::errc() || r.ptr != s.data() + s.size() || s.front() == '+' || v < 1 || v > kMaxLanesTotal)
        return std::nullopt;
    return v;
}

std::optional<int> parseOsmDirectionLaneCount(std::string_view text) {
    auto v = parseOsmLaneCount(text);
    if (v && *v > kMaxLanesPerDirection) return std::nullopt;
    return v;
}

std::optional<OsmOneway> parseOsmOneway(std::string_view text) {
    const std::string_view s = trim(text);
    if (s == "yes" || s == "true" || s == "1") return OsmOneway::Forward;
    if (s == "-1" || s == "reverse") return OsmOneway::Backward;
    if (s == "no" || s == "false" || s == "0") return OsmOneway::No;
    return std::nullopt;
}

std::optional<float> osmCountrySpeed(std::string_view country, std::string_view zone) {
    for (const auto& c : kCountries) {
        if (country != c.code) continue;
        float v = 0;
        if (zone == "urban") v = c.urban;
        else if (zone == "rural") v = c.rural;
        else if (zone == "trunk") v = c.trunk;
        else if (zone == "motorway") v = c.motorway;
        if (v > 0) return v;
        return std::nullopt;
    }
    return std::nullopt;
}

std::optional<float> parseOsmMaxspeed(std::string_view text) {
    std::string_view s = trim(text);
    if (s == "none") return kMaxspeedNoneKmh;
    if (s == "walk") return kMaxspeedWalkKmh;
    if (const size_t colon = s.find(':'); colon != std::string_view::npos) {
        const std::string_view cc = s.substr(0, colon), zone = s.substr(colon + 1);
        if (cc.size() != 2 || !std::all_of(cc.begin(), cc.end(), [](char c) { return c >= 'A' && c <= 'Z'; }))
            return std::nullopt;
        if (zone == "living_street" || zone == "walk") return kMaxspeedWalkKmh;
        if (zone == "bicycle_road") return 30.0f;
        if (cc == "GB") {
            if (zone == "nsl_single") return 60 * kMph;
            if (zone == "nsl_dual") return 70 * kMph;
            if (zone == "nsl_restricted") return 30 * kMph;
        }
        if (zone.substr(0, 4) == "zone") {
            std::string_view n = zone.substr(4);
            if (!n.empty() && n.front() == ':') n.remove_prefix(1);
            double v = 0;
            if (!leadingNumber(n, v) || !n.empty()) return std::nullopt;
            return plausibleSpeed(cc == "GB" ? v * kMph : v);
        }
        return osmCountrySpeed(cc, zone);
    }
    double v = 0;
    if (!leadingNumber(s, v)) return std::nullopt;
    s = trim(s);
    if (s.empty() || s == "km/h" || s == "kmh" || s == "kph") return plausibleSpeed(v);
    if (s == "mph") return plausibleSpeed(v * kMph);
    if (s == "knots") return plausibleSpeed(v * kKnot);
    return std::nullopt;
}

std::optional<OsmTurnLanes> parseOsmTurnLanes(std::string_view text) {
    if (text.size() > 512 || trim(text).empty()) return std::nullopt;
    OsmTurnLanes out;
    size_t start = 0;
    while (true) {
        const size_t bar = text.find('|', start);
        const std::string_view lane =
            text.substr(start, bar == std::string_view::npos ? std::string_view::npos : bar - start);
        if (++out.lanes > kMaxLanesPerDirection) return std::nullopt;
        if (out.lanes > 1) out.value += '|';
        if (!trim(lane).empty()) {
            size_t vs = 0;
            while (true) {
                const size_t semi = lane.find(';', vs);
                const std::string_view v =
                    trim(lane.substr(vs, semi == std::string_view::npos ? std::string_view::npos : semi - vs));
                if (!isTurnValue(v)) return std::nullopt;
                if (vs > 0) out.value += ';';
                out.value += v;
                if (semi == std::string_view::npos) break;
                vs = semi + 1;
            }
        }
        if (bar == std::string_view::npos) break;
        start = bar + 1;
    }
    return out;
}

OsmRoadTags OsmRoadTags::reversed() const {
    OsmRoadTags r = *this;
    std::swap(r.lanesForward, r.lanesBackward);
    std::swap(r.turnForward, r.turnBackward);
    return r;
}

namespace {

// The way's direction: the oneway tag, else implied by motorways and roundabouts.
OsmOneway readOneway(const OsmTagLookup& tag, OsmRoadTagStats& st) {
    if (auto o = readTag<OsmOneway>(
            tag, "oneway", [](std::string_view v) { return parseOsmOneway(v); }, st.oneway)) {
        ++st.oneway.used;
        return *o;
    }
    const char* hw = tag("highway");
    const char* junction = tag("junction");
    if ((hw && std::string_view(hw) == "motorway") ||
        (junction && (std::string_view(junction) == "roundabout" || std::string_view(junction) == "circular"))) {
        ++st.onewayImplied;
        return OsmOneway::Forward;
    }
    return OsmOneway::No;
}

// The speed limit and the carriageway width, each counted as used or defaulted.
void readSpeedAndWidth(const OsmTagLookup& tag, OsmRoadTagStats& st, OsmRoadTags& t) {
    if (auto v = readTag<float>(
            tag, "maxspeed", [](std::string_view s) { return parseOsmMaxspeed(s); }, st.maxspeed)) {
        t.maxspeedKmh = *v;
        ++st.maxspeed.used;
    } else {
        ++st.defaultMaxspeed;
    }
    auto width = [](std::string_view s) -> std::optional<float> {
        const double w = parseOsmLength(s);
        if (!(w >= kMinOsmRoadWidth_m && w <= kMaxOsmRoadWidth_m)) return std::nullopt;
        return float(w);
    };
    if (auto w = readTag<float>(tag, "width", width, st.width)) {
        t.width = *w;
        ++st.width.used;
    } else {
        ++st.defaultWidth;
    }
}

}  // namespace

OsmRoadTags readOsmRoadTags(const OsmTagLookup& tag, RoadClass cls, OsmRoadTagStats& st) {
    ++st.ways;
    OsmRoadTags t;
    auto laneCount = [](std::string_view v) { return parseOsmLaneCount(v); };
    auto directionCount = [](std::string_view v) { return parseOsmDirectionLaneCount(v); };
    auto turns = [](std::string_view v) { return parseOsmTurnLanes(v); };
    auto total = readTag<int>(tag, "lanes", laneCount, st.lanes);
    const auto fwdTag = readTag<int>(tag, "lanes:forward", directionCount, st.lanesForward);
    const auto bwdTag = readTag<int>(tag, "lanes:backward", directionCount, st.lanesBackward);
    const auto turnTag = readTag<OsmTurnLanes>(tag, "turn:lanes", turns, st.turnLanes);
    const auto turnFwd = readTag<OsmTurnLanes>(tag, "turn:lanes:forward", turns, st.turnLanesForward);
    const auto turnBwd = readTag<OsmTurnLanes>(tag, "turn:lanes:backward", turns, st.turnLanesBackward);

    const OsmOneway oneway = readOneway(tag, st);

    // Lane counts, in the way's direction.
    bool fromTags = false;
    auto use = [&](const std::optional<int>& v, OsmTagUse& u) {
        if (v) {
            ++u.used;
            fromTags = true;
        }
    };
    auto unused = [&](const std::optional<int>& v, OsmTagUse& u) {
        if (v) ++u.fallback;
    };
    // `lanes` set aside: beyond one direction's count on a one-way road
    // (implausible), or contradicting the directional counts (inconsistent).
    auto dropTotal = [&](bool inconsistent) {
        ++st.lanes.fallback;
        if (inconsistent) ++st.lanesInconsistent;
        total.reset();
    };
    if (oneway != OsmOneway::No) {
        const bool fwd = oneway == OsmOneway::Forward;
        const auto& dirTag = fwd ? fwdTag : bwdTag;
        const auto& otherTag = fwd ? bwdTag : fwdTag;
        use(dirTag, fwd ? st.lanesForward : st.lanesBackward);
        unused(otherTag, fwd ? st.lanesBackward : st.lanesForward);
        if (total && *total > kMaxLanesPerDirection) dropTotal(false);
        else if (total && dirTag && *total != *dirTag) dropTotal(true);
        // Turn lanes: the directional tag first, then turn:lanes; a differing second value is not used.
        const auto& dirTurn = fwd ? turnFwd : turnBwd;
        const auto& otherTurn = fwd ? turnBwd : turnFwd;
        OsmTagUse& dirTurnUse = fwd ? st.turnLanesForward : st.turnLanesBackward;
        if (otherTurn) ++(fwd ? st.turnLanesBackward : st.turnLanesForward).fallback;
        int n = dirTag ? *dirTag : total ? *total : 0;
        const OsmTurnLanes* turn = nullptr;
        for (auto [cand, u] : {std::pair{&dirTurn, &dirTurnUse}, std::pair{&turnTag, &st.turnLanes}}) {
            if (!*cand) continue;
            const bool fits = turn ? (*cand)->value == turn->value : (n == 0 || (*cand)->lanes == n);
            if (!fits) {
                ++u->fallback;
                continue;
            }
            ++u->used;
            if (!turn) turn = &**cand;
        }
        if (turn && n == 0) {
            n = turn->lanes;
            fromTags = true;
        }
        if (n == 0) n = std::max(1, (roadLanes(cls) + 1) / 2);
        t.lanesForward = fwd ? n : 0;
        t.lanesBackward = fwd ? 0 : n;
        (fwd ? t.turnForward : t.turnBackward) = turn ? turn->value : "";
        t.lanes = n;
    } else {
        if (turnTag) ++st.turnLanes.fallback;  // ambiguous on a two-way road
        use(fwdTag, st.lanesForward);
        use(bwdTag, st.lanesBackward);
        int f = fwdTag ? *fwdTag : 0, b = bwdTag ? *bwdTag : 0;
        if (!f && turnFwd) {
            f = turnFwd->lanes;
            fromTags = true;
        }
        if (!b && turnBwd) {
            b = turnBwd->lanes;
            fromTags = true;
        }
        // The total must be forward + backward when both are known, and leave
        // the other direction 1 .. kMaxLanesPerDirection lanes when one is.
        if (total && (f || b)) {
            const int other = *total - (f ? f : b);
            if (f && b ? *total != f + b : (other < 1 || other > kMaxLanesPerDirection)) dropTotal(true);
        }
        if (f || b) {
            // One direction known: the other from the total, else the derived split.
            const int n = std::max(total ? *total : roadLanes(cls), 2);
            if (!f) f = total ? *total - b : (n + 1) / 2;
            if (!b) b = total ? *total - f : n / 2;
            t.lanesForward = f;
            t.lanesBackward = b;
            for (auto [turn, count, out, u] : {std::tuple{&turnFwd, f, &t.turnForward, &st.turnLanesForward},
                                               std::tuple{&turnBwd, b, &t.turnBackward, &st.turnLanesBackward}}) {
                if (!*turn) continue;
                if ((*turn)->lanes == count) {
                    *out = (*turn)->value;
                    ++u->used;
                } else ++u->fallback;
            }
            t.lanes = total ? *total : std::min(f + b, kMaxLanesTotal);
        } else {
            t.lanes = total ? *total : 0;
        }
    }
    if (total) {
        ++st.lanes.used;
        fromTags = true;
    }
    if (!fromTags) ++st.defaultLanes;
    readSpeedAndWidth(tag, st, t);
    return t;
}

void applyOsmRoadTags(const OsmRoadTags& t, StreetEdge& e) {
    if (t.lanes > 0) e.lanes = uint8_t(std::clamp(t.lanes, 1, 2 * kMaxLanesPerDirection));
    e.lanesForward = int8_t(std::clamp(t.lanesForward, -1, kMaxLanesPerDirection));
    e.lanesBackward = int8_t(std::clamp(t.lanesBackward, -1, kMaxLanesPerDirection));
    e.maxspeedKmh = t.maxspeedKmh;
    if (t.width > 0) e.width = t.width;
    e.turnForward = t.turnForward;
    e.turnBackward = t.turnBackward;
}

std::string osmRoadTagStatsJson(const OsmRoadTagStats& s) {
    auto use = [](const OsmTagUse& u) { return nlohmann::ordered_json{{"used", u.used}, {"fallback", u.fallback}}; };
    nlohmann::ordered_json tags;
    tags["lanes"] = use(s.lanes);
    tags["lanes"]["inconsistent"] = s.lanesInconsistent;
    tags["lanes:forward"] = use(s.lanesForward);
    tags["lanes:backward"] = use(s.lanesBackward);
    tags["oneway"] = use(s.oneway);
    tags["oneway"]["implied"] = s.onewayImplied;
    tags["turn:lanes"] = use(s.turnLanes);
    tags["turn:lanes:forward"] = use(s.turnLanesForward);
    tags["turn:lanes:backward"] = use(s.turnLanesBackward);
    tags["maxspeed"] = use(s.maxspeed);
    tags["width"] = use(s.width);
    nlohmann::ordered_json j;
    j["ways"] = s.ways;
    j["tags"] = std::move(tags);
    j["class_default"] = {{"lanes", s.defaultLanes}, {"maxspeed", s.defaultMaxspeed}, {"width", s.defaultWidth}};
    j["edges"] = {
        {"matched", s.edgesMatched}, {"unmatched", s.edgesUnmatched}, {"merged_one_ways", s.edgesMergedOneWays}};
    return j.dump();
}

}  // namespace vista
