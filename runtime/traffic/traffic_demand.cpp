#include "runtime/traffic/traffic_demand.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <vector>

#include "foundation/rng.h"

namespace vista {

namespace {

constexpr AgentTypeInfo kTypes[kAgentTypeCount] = {
    {"car", "passenger", kClassPassenger, 4.5, 1.8, 1.5, 50.0 / 3.6 * 2.0},
    {"van", "delivery", kClassDelivery, 5.6, 2.0, 2.4, 100.0 / 3.6},
    {"bus", "bus", kClassBus, 12.0, 2.5, 3.2, 80.0 / 3.6},
    {"truck", "truck", kClassTruck, 8.5, 2.5, 3.4, 80.0 / 3.6},
    {"bicycle", "bicycle", kClassBicycle, 1.8, 0.65, 1.7, 20.0 / 3.6},
    {"pedestrian", "pedestrian", kClassPedestrian, 0.25, 0.55, 1.75, 1.5},
};

// Random streams of the demand (third key of Rng): one per draw kind.
enum : uint64_t {
    kTypeStream = 0x7472,
    kTripStream = 0x7470,
    kDepartStream = 0x7464,
    kWalkStream = 0x7477,
    kWalkDepartStream = 0x7764
};

// A departure time as the file writes it (centiseconds), so the order the
// file lists agents in is the order of the written times.
double centis(double t) { return std::round(t * 100.0) / 100.0; }

// The members of the largest strongly connected component of the graph with
// `adj` (Tarjan, iterative). Nodes are 0..n-1.
std::vector<uint32_t> largestScc(const std::vector<std::vector<uint32_t>>& adj) {
    const uint32_t n = uint32_t(adj.size());
    std::vector<int64_t> index(n, -1), low(n, 0);
    std::vector<char> onStack(n, 0);
    std::vector<uint32_t> stack, best;
    int64_t next = 0;
    struct Frame {
        uint32_t v;
        size_t edge;
    };
    for (uint32_t root = 0; root < n; ++root) {
        if (index[root] >= 0) continue;
        std::vector<Frame> call{{root, 0}};
        index[root] = low[root] = next++;
        stack.push_back(root);
        onStack[root] = 1;
        while (!call.empty()) {
            Frame& f = call.back();
            if (f.edge < adj[f.v].size()) {
                const uint32_t w = adj[f.v][f.edge++];
                if (index[w] < 0) {
                    index[w] = low[w] = next++;
                    stack.push_back(w);
                    onStack[w] = 1;
                    call.push_back({w, 0});
                } else if (onStack[w]) {
                    low[f.v] = std::min(low[f.v], index[w]);
                }
                continue;
            }
            const uint32_t v = f.v;
            call.pop_back();
            if (!call.empty()) low[call.back().v] = std::min(low[call.back().v], low[v]);
            if (low[v] == index[v]) {
                std::vector<uint32_t> comp;
                for (;;) {
                    const uint32_t w = stack.back();
                    stack.pop_back();
                    onStack[w] = 0;
                    comp.push_back(w);
                    if (w == v) break;
                }
                if (comp.size() > best.size()) best = std::move(comp);
            }
        }
    }
    std::sort(best.begin(), best.end());
    return best;
}

bool laneAllows(const SumoEdge& e, int lane, uint32_t cls) {
    for (const SumoLane& l : e.lanes)
        if (l.index == lane) return (l.allow & cls) != 0;
    return false;
}

double edgeLength(const SumoEdge& e) {
    double len = 0.0;
    for (const SumoLane& l : e.lanes) len = std::max(len, l.length);
    return len;
}

// The edges where trips of class `cls` may start and end: normal edges of the
// largest connected part for that class, long enough to depart on.
// Vehicles: strongly connected over the directed connections; pedestrians:
// connected over every edge they may walk, both ways.
std::vector<uint32_t> tripEdges(const SumoNet& net, uint32_t cls) {
    const bool walk = cls == kClassPedestrian;
    const uint32_t n = uint32_t(net.edges.size());
    std::vector<std::vector<uint32_t>> adj(n);
    for (const SumoConnection& c : net.connections) {
        const SumoEdge &a = net.edges[c.from], &b = net.edges[c.to];
        if (!walk && (!a.normal() || !b.normal())) continue;
        if (!laneAllows(a, c.fromLane, cls) || !laneAllows(b, c.toLane, cls)) continue;
        if (!walk && c.viaEdge >= 0 && !laneAllows(net.edges[size_t(c.viaEdge)], c.viaLane, cls)) continue;
        adj[c.from].push_back(c.to);
        if (walk) adj[c.to].push_back(c.from);
    }
    for (auto& a : adj) {
        std::sort(a.begin(), a.end());
        a.erase(std::unique(a.begin(), a.end()), a.end());
    }
    std::vector<uint32_t> out;
    for (uint32_t e : largestScc(adj)) {
        const SumoEdge& edge = net.edges[e];
        if (edge.normal() && (edge.allow() & cls) && edgeLength(edge) >= kMinTripEdgeM) out.push_back(e);
    }
    return out;
}

double networkSpan(const SumoNet& net) {
    double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
    for (const SumoEdge& e : net.edges) {
        if (!e.normal()) continue;
        x0 = std::min(x0, e.x), x1 = std::max(x1, e.x), y0 = std::min(y0, e.y), y1 = std::max(y1, e.y);
    }
    return x1 >= x0 ? std::max(x1 - x0, y1 - y0) : 0.0;
}

// A (from, to) pair of `edges`: the first of kTripTries draws whose distance
// lies in [lo, hi], else the draw closest to that band.
std::pair<uint32_t, uint32_t> drawTrip(const SumoNet& net, const std::vector<uint32_t>& edges, Rng& rng, double lo,
                                       double hi) {
    std::pair<uint32_t, uint32_t> best{edges[0], edges[0]};
    double bestMiss = 1e300;
    for (int t = 0; t < kTripTries; ++t) {
        const uint32_t a = edges[size_t(rng.range(0, int64_t(edges.size()) - 1))];
        const uint32_t b = edges[size_t(rng.range(0, int64_t(edges.size()) - 1))];
        if (a == b && edges.size() > 1) continue;
        const double d = std::hypot(net.edges[a].x - net.edges[b].x, net.edges[a].y - net.edges[b].y);
        const double miss = d < lo ? lo - d : (d > hi ? d - hi : 0.0);
        if (miss < bestMiss) bestMiss = miss, best = {a, b};
        if (miss == 0.0) break;
    }
    return best;
}

std::string xmlEscape(const std::string& s) {
    std::string out;
    for (char c : s) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            default: out += c;
        }
    }
    return out;
}

std::string fixed2(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.2f", v);
    return buf;
}

// A vehicle type takes part where its trip edges (its connected part, through
// the junction turns open to it) are at least kMinNetworkShare of the cars'.
bool typeHasNetwork(const std::array<std::vector<uint32_t>, kAgentTypeCount>& edges, AgentType t) {
    const size_t own = edges[size_t(t)].size(), cars = edges[size_t(AgentType::Car)].size();
    return own >= 2 && double(own) >= kMinNetworkShare * double(cars);
}

struct Entry {
    double depart;
    int order;  // vehicles before pedestrians at equal times, then by index
    std::string text;
};

}  // namespace

const AgentTypeInfo& agentTypeInfo(AgentType t) { return kTypes[int(t)]; }

bool agentTypeFromId(const std::string& id, AgentType* t) {
    for (int i = 0; i < kAgentTypeCount; ++i)
        if (id == kTypes[i].id) {
            *t = AgentType(i);
            return true;
        }
    return false;
}

Result<std::string> makeDemandXml(const SumoNet& net, const TrafficDemandOptions& opt, TrafficDemandCounts* counts) {
    TrafficDemandCounts local;
    TrafficDemandCounts& n = counts ? *counts : local;
    n = {};
    std::array<std::vector<uint32_t>, kAgentTypeCount> edges;
    for (int t = 0; t < kAgentTypeCount; ++t) {
        const bool needed = AgentType(t) == AgentType::Pedestrian ? opt.pedestrians > 0 : opt.vehicles > 0;
        if (needed) edges[size_t(t)] = tripEdges(net, kTypes[t].classBit);
    }
    if (opt.vehicles > 0 && edges[size_t(AgentType::Car)].size() < 2)
        return Status::error(
            "the SUMO network has no connected roads for cars (netconvert found no driving lanes "
            "linked through junctions in the city's OpenDRIVE): give --vehicles 0");
    if (opt.pedestrians > 0 && edges[size_t(AgentType::Pedestrian)].size() < 2)
        return Status::error(
            "the SUMO network has no connected sidewalks (the city's OpenDRIVE has no sidewalk "
            "lanes netconvert could link): give --pedestrians 0");
    const double span = networkSpan(net);
    std::vector<Entry> entries;
    for (int i = 0; i < opt.vehicles; ++i) {
        Rng typeRng(opt.seed, uint64_t(i), kTypeStream);
        const double u = typeRng.uniform();
        int t = 0;
        for (double acc = kDefaultMix[0]; t < 4 && u >= acc; acc += kDefaultMix[size_t(++t)]) {}
        if (!typeHasNetwork(edges, AgentType(t))) t = int(AgentType::Car), ++n.substituted;
        ++n.byType[size_t(t)];
        Rng tripRng(opt.seed, uint64_t(i), kTripStream);
        const auto [from, to] = drawTrip(net, edges[size_t(t)], tripRng, span / 3.0, 1e300);
        const double vslot = opt.durationS / opt.vehicles;
        const double depart = centis((i + Rng(opt.seed, uint64_t(i), kDepartStream).uniform()) * vslot);
        entries.push_back({depart, i,
                           "    <trip id=\"veh" + std::to_string(i) + "\" type=\"" + kTypes[t].id + "\" depart=\"" +
                               fixed2(depart) + "\" from=\"" + xmlEscape(net.edges[from].id) + "\" to=\"" +
                               xmlEscape(net.edges[to].id) +
                               "\" departLane=\"best\" departPos=\"base\" departSpeed=\"max\"/>\n"});
    }
    const auto& walkEdges = edges[size_t(AgentType::Pedestrian)];
    for (int i = 0; i < opt.pedestrians; ++i) {
        ++n.byType[size_t(AgentType::Pedestrian)];
        Rng walkRng(opt.seed, uint64_t(i), kWalkStream);
        const auto [from, to] = drawTrip(net, walkEdges, walkRng, 80.0, 600.0);
        const double pslot = opt.durationS / opt.pedestrians;
        const double depart = centis((i + Rng(opt.seed, uint64_t(i), kWalkDepartStream).uniform()) * pslot);
        entries.push_back({depart, opt.vehicles + i,
                           "    <person id=\"ped" + std::to_string(i) + "\" type=\"pedestrian\" depart=\"" +
                               fixed2(depart) + "\">\n        <walk from=\"" + xmlEscape(net.edges[from].id) +
                               "\" to=\"" + xmlEscape(net.edges[to].id) + "\"/>\n    </person>\n"});
    }
    std::stable_sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
        return a.depart != b.depart ? a.depart < b.depart : a.order < b.order;
    });
    std::string xml = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<!-- vista traffic demand: seed " +
                      std::to_string(opt.seed) + ", " + std::to_string(opt.vehicles) + " vehicles, " +
                      std::to_string(opt.pedestrians) + " pedestrians over " + fixed2(opt.durationS) +
                      " s -->\n<routes>\n";
    for (const AgentTypeInfo& t : kTypes)
        xml += "    <vType id=\"" + std::string(t.id) + "\" vClass=\"" + t.sumoClass + "\" length=\"" +
               fixed2(t.length) + "\" width=\"" + fixed2(t.width) + "\" height=\"" + fixed2(t.height) +
               "\" maxSpeed=\"" + fixed2(t.maxSpeed) + "\"/>\n";
    for (const Entry& e : entries) xml += e.text;
    xml += "</routes>\n";
    return xml;
}

}  // namespace vista
