#include "runtime/traffic/sumo_net.h"

#include <expat.h>

#include <algorithm>
#include <tuple>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <sstream>
#include <unordered_map>

#include "foundation/atomic_file.h"
#include "runtime/traffic/xml_feed.h"

namespace vista {

namespace {

struct ClassName {
    const char* name;
    uint32_t bit;
};
constexpr ClassName kClassNames[] = {
    {"passenger", kClassPassenger}, {"delivery", kClassDelivery}, {"bus", kClassBus},
    {"truck", kClassTruck},         {"bicycle", kClassBicycle},   {"pedestrian", kClassPedestrian},
};

uint32_t classesOf(const char* list) {
    uint32_t bits = 0;
    std::istringstream in(list);
    for (std::string word; in >> word;) {
        if (word == "all") return kAllTrafficClasses;
        for (const ClassName& c : kClassNames)
            if (word == c.name) bits |= c.bit;
    }
    return bits;
}

const char* attr(const XML_Char** atts, const char* name) {
    for (int i = 0; atts[i]; i += 2)
        if (std::strcmp(atts[i], name) == 0) return atts[i + 1];
    return nullptr;
}

struct Reader {
    XML_Parser parser = nullptr;
    SumoNet net;
    std::unordered_map<std::string, uint32_t> edgeIndex;
    struct PendingConnection {
        std::string from, to;
        int fromLane, toLane;
        std::string via;
    };
    std::vector<PendingConnection> pending;
    std::unordered_map<std::string, std::pair<uint32_t, int>> laneIndex;  // lane id -> (edge, lane index)
    std::unordered_map<std::string, std::vector<uint32_t>> laneSignals;   // internal lane id -> signal ids
    struct PendingLink {
        std::string via, tl;
        int linkIndex;
    };
    std::vector<PendingLink> pendingLinks;
    std::string currentLane;  // the <lane> being read (its <param>s follow)
    bool sawRoot = false;
    int edgeDepth = -1, depth = 0;
    std::string error;

    void fail(const std::string& why) {
        if (error.empty()) error = "line " + std::to_string(XML_GetCurrentLineNumber(parser)) + ": " + why;
        XML_StopParser(parser, XML_FALSE);
    }

    void start(const char* name, const XML_Char** atts) {
        ++depth;
        if (!sawRoot) {
            if (std::strcmp(name, "net") != 0)
                return fail(std::string("the root element is <") + name + ">, not <net>");
            sawRoot = true;
            return;
        }
        if (std::strcmp(name, "location") == 0) {
            const char* off = attr(atts, "netOffset");
            if (off && std::sscanf(off, "%lf,%lf", &net.offsetX, &net.offsetY) != 2)
                return fail(std::string("<location netOffset=\"") + off + "\"> is not 'x,y'");
        } else if (std::strcmp(name, "edge") == 0 && depth == 2) {
            const char* id = attr(atts, "id");
            if (!id) return fail("an <edge> has no id");
            SumoEdge e;
            e.id = id;
            if (const char* f = attr(atts, "function")) e.function = f;
            edgeIndex[e.id] = uint32_t(net.edges.size());
            net.edges.push_back(std::move(e));
            edgeDepth = depth;
        } else if (std::strcmp(name, "lane") == 0 && edgeDepth >= 0 && depth == edgeDepth + 1) {
            SumoLane l;
            if (const char* i = attr(atts, "index")) l.index = std::atoi(i);
            if (const char* len = attr(atts, "length")) l.length = std::atof(len);
            l.allow = sumoPermissions(attr(atts, "allow"), attr(atts, "disallow"));
            SumoEdge& e = net.edges.back();
            if (const char* id = attr(atts, "id")) {
                currentLane = id;
                laneIndex[currentLane] = {uint32_t(net.edges.size() - 1), l.index};
            }
            if (e.lanes.empty())
                if (const char* shape = attr(atts, "shape")) middleOf(shape, &e.x, &e.y);
            e.lanes.push_back(l);
        } else if (std::strcmp(name, "connection") == 0 && depth == 2) {
            const char *from = attr(atts, "from"), *to = attr(atts, "to");
            const char *fl = attr(atts, "fromLane"), *tl = attr(atts, "toLane");
            if (!from || !to || !fl || !tl) return fail("a <connection> lacks from, to, fromLane or toLane");
            const char *via = attr(atts, "via"), *light = attr(atts, "tl"), *index = attr(atts, "linkIndex");
            pending.push_back({from, to, std::atoi(fl), std::atoi(tl), via ? via : ""});
            if (via && light && index) pendingLinks.push_back({via, light, std::atoi(index)});
        } else if (std::strcmp(name, "param") == 0 && edgeDepth >= 0 && depth == edgeDepth + 2 &&
                   !currentLane.empty()) {
            const char *key = attr(atts, "key"), *value = attr(atts, "value");
            if (key && value && std::strcmp(key, "signalID") == 0) {
                char* end = nullptr;
                const unsigned long id = std::strtoul(value, &end, 10);
                if (end == value || *end != '\0' || id > 0xffffffffull)
                    return fail(std::string("<param key=\"signalID\" value=\"") + value +
                                "\"> is not an unsigned integer");
                laneSignals[currentLane].push_back(uint32_t(id));
            }
        } else if (std::strcmp(name, "tlLogic") == 0 && depth == 2) {
            if (const char* id = attr(atts, "id")) net.trafficLights.push_back(id);
        }
    }
    void end() {
        if (edgeDepth >= 0 && depth == edgeDepth + 1) currentLane.clear();
        if (depth == edgeDepth) edgeDepth = -1;
        --depth;
    }

    // The vertex in the middle of a shape "x,y x,y ..." (by count: the edge's
    // position is only used to keep trips apart).
    static void middleOf(const char* shape, double* x, double* y) {
        std::vector<std::pair<double, double>> pts;
        std::istringstream in(shape);
        for (std::string p; in >> p;) {
            double a = 0, b = 0;
            if (std::sscanf(p.c_str(), "%lf,%lf", &a, &b) >= 2) pts.push_back({a, b});
        }
        if (pts.empty()) return;
        *x = pts[pts.size() / 2].first;
        *y = pts[pts.size() / 2].second;
    }
};

}  // namespace

uint32_t sumoPermissions(const char* allow, const char* disallow) {
    if (allow) return classesOf(allow);
    if (disallow) return kAllTrafficClasses & ~classesOf(disallow);
    return kAllTrafficClasses;
}

Result<SumoNet> readSumoNet(const std::string& path) {
    std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
    if (!f) return Status::error("cannot read the SUMO network '" + path + "': " + errnoText());
    Reader r;
    r.parser = XML_ParserCreate(nullptr);
    std::unique_ptr<XML_ParserStruct, void (*)(XML_Parser)> guard(r.parser, &XML_ParserFree);
    XML_SetUserData(r.parser, &r);
    XML_SetElementHandler(
        r.parser, [](void* u, const XML_Char* n, const XML_Char** a) { static_cast<Reader*>(u)->start(n, a); },
        [](void* u, const XML_Char*) { static_cast<Reader*>(u)->end(); });
    if (Status st = feedXml(r.parser, f.get(), r.error, "SUMO network", path); !st.isOk()) return st;
    if (!r.sawRoot) return Status::error("SUMO network '" + path + "' is empty");
    for (const auto& c : r.pending) {
        auto from = r.edgeIndex.find(c.from), to = r.edgeIndex.find(c.to);
        if (from == r.edgeIndex.end() || to == r.edgeIndex.end())
            return Status::error("SUMO network '" + path + "': a <connection> names the unknown edge '" +
                                 (from == r.edgeIndex.end() ? c.from : c.to) + "'");
        SumoConnection conn{from->second, to->second, c.fromLane, c.toLane};
        if (!c.via.empty()) {
            auto via = r.laneIndex.find(c.via);
            if (via == r.laneIndex.end())
                return Status::error("SUMO network '" + path + "': a <connection> names the unknown via lane '" +
                                     c.via + "'");
            conn.viaEdge = via->second.first;
            conn.viaLane = via->second.second;
        }
        r.net.connections.push_back(conn);
    }
    std::unordered_map<std::string, uint32_t> lightIndex;
    for (size_t i = 0; i < r.net.trafficLights.size(); ++i) lightIndex[r.net.trafficLights[i]] = uint32_t(i);
    for (const auto& l : r.pendingLinks) {
        auto signals = r.laneSignals.find(l.via);
        if (signals == r.laneSignals.end()) continue;
        auto light = lightIndex.find(l.tl);
        if (light == lightIndex.end())
            return Status::error("SUMO network '" + path + "': a <connection> names the unknown traffic light '" +
                                 l.tl + "'");
        for (uint32_t id : signals->second) r.net.signalLinks.push_back({id, light->second, l.linkIndex});
    }
    auto key = [](const SumoSignalLink& a) { return std::make_tuple(a.signalId, a.light, a.linkIndex); };
    std::sort(r.net.signalLinks.begin(), r.net.signalLinks.end(),
              [&](const SumoSignalLink& a, const SumoSignalLink& b) { return key(a) < key(b); });
    r.net.signalLinks.erase(
        std::unique(r.net.signalLinks.begin(), r.net.signalLinks.end(),
                    [&](const SumoSignalLink& a, const SumoSignalLink& b) { return key(a) == key(b); }),
        r.net.signalLinks.end());
    return std::move(r.net);
}

}  // namespace vista
