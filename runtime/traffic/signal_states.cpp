#include "runtime/traffic/signal_states.h"

#include <expat.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <memory>
#include <unordered_map>

#include "foundation/atomic_file.h"
#include "runtime/traffic/xml_feed.h"

namespace vista {

namespace {

const char* attr(const XML_Char** atts, const char* name) {
    for (int i = 0; atts[i]; i += 2)
        if (std::strcmp(atts[i], name) == 0) return atts[i + 1];
    return nullptr;
}

struct Reader {
    XML_Parser parser = nullptr;
    const std::unordered_map<std::string, uint32_t>* lightIndex = nullptr;
    std::vector<std::vector<std::pair<double, std::string>>>* records = nullptr;
    bool sawRoot = false;
    std::string error;

    void fail(const std::string& why) {
        if (error.empty()) error = "line " + std::to_string(XML_GetCurrentLineNumber(parser)) + ": " + why;
        XML_StopParser(parser, XML_FALSE);
    }
    void start(const char* name, const XML_Char** atts) {
        if (!sawRoot) {
            sawRoot = true;
            if (std::strcmp(name, "tlsStates") != 0)
                return fail(std::string("the root element is <") + name + ">, not <tlsStates>");
            return;
        }
        if (std::strcmp(name, "tlsState") != 0) return;
        const char *time = attr(atts, "time"), *id = attr(atts, "id"), *state = attr(atts, "state");
        if (!time || !id || !state) return fail("a <tlsState> lacks time, id or state");
        char* end = nullptr;
        const double t = std::strtod(time, &end);
        if (end == time || *end != '\0' || !(t >= 0.0)) return fail(std::string("time=\"") + time + "\" is not a time");
        auto light = lightIndex->find(id);
        if (light == lightIndex->end())
            return fail(std::string("the traffic light '") + id + "' is not in the network");
        auto& list = (*records)[light->second];
        if (!list.empty() && t < list.back().first)
            return fail(std::string("the records of traffic light '") + id + "' go back in time at " + time);
        list.push_back({t, state});
    }
};

}  // namespace

const char* lampStateName(LampState s) {
    switch (s) {
        case LampState::Red: return "red";
        case LampState::RedAmber: return "red-amber";
        case LampState::Amber: return "amber";
        case LampState::Green: return "green";
        case LampState::Off: break;
    }
    return "off";
}

LampState lampOfLetters(const std::string& letters) {
    LampState best = LampState::Off;
    for (char c : letters) {
        LampState s = LampState::Off;
        if (c == 'G' || c == 'g') s = LampState::Green;
        else if (c == 'y' || c == 'Y') s = LampState::Amber;
        else if (c == 'u') s = LampState::RedAmber;
        else if (c == 'r' || c == 'R' || c == 's') s = LampState::Red;
        best = std::max(best, s);
    }
    return best;
}

std::vector<SumoSignalLink> SignalStates::linksOf(uint32_t signalId) const {
    auto lo = std::lower_bound(_links.begin(), _links.end(), signalId,
                               [](const SumoSignalLink& l, uint32_t id) { return l.signalId < id; });
    std::vector<SumoSignalLink> out;
    for (; lo != _links.end() && lo->signalId == signalId; ++lo) out.push_back(*lo);
    return out;
}

LampState SignalStates::lampAt(uint32_t signalId, double t) const {
    std::string letters;
    for (const SumoSignalLink& l : linksOf(signalId)) {
        const auto& list = _records[l.light];
        // The last record at or before t.
        auto after =
            std::upper_bound(list.begin(), list.end(), t, [](double v, const Record& r) { return v < r.time; });
        if (after == list.begin()) continue;
        const std::string& state = std::prev(after)->state;
        if (l.linkIndex >= 0 && size_t(l.linkIndex) < state.size()) letters += state[size_t(l.linkIndex)];
    }
    return lampOfLetters(letters);
}

Result<SignalStates> readSignalStates(const SumoNet& net, const std::string& signalsPath) {
    std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(signalsPath.c_str(), "rb"), &std::fclose);
    if (!f) return Status::error("cannot read the traffic-light states '" + signalsPath + "': " + errnoText());
    std::unordered_map<std::string, uint32_t> lightIndex;
    for (size_t i = 0; i < net.trafficLights.size(); ++i) lightIndex[net.trafficLights[i]] = uint32_t(i);
    std::vector<std::vector<std::pair<double, std::string>>> records(net.trafficLights.size());
    Reader r;
    r.parser = XML_ParserCreate(nullptr);
    std::unique_ptr<XML_ParserStruct, void (*)(XML_Parser)> guard(r.parser, &XML_ParserFree);
    r.lightIndex = &lightIndex;
    r.records = &records;
    XML_SetUserData(r.parser, &r);
    XML_SetStartElementHandler(
        r.parser, [](void* u, const XML_Char* n, const XML_Char** a) { static_cast<Reader*>(u)->start(n, a); });
    if (Status st = feedXml(r.parser, f.get(), r.error, "traffic-light states", signalsPath); !st.isOk()) return st;
    if (!r.sawRoot) return Status::error("traffic-light states '" + signalsPath + "' is empty");
    SignalStates s;
    s._lights = net.trafficLights;
    s._records.resize(records.size());
    for (size_t i = 0; i < records.size(); ++i)
        for (auto& [t, state] : records[i]) s._records[i].push_back({t, std::move(state)});
    s._links = net.signalLinks;
    std::stable_sort(s._links.begin(), s._links.end(),
                     [](const SumoSignalLink& a, const SumoSignalLink& b) { return a.signalId < b.signalId; });
    return s;
}

Result<SignalStates> loadSignalStates(const std::string& trafficDir) {
    const std::filesystem::path dir(trafficDir);
    auto net = readSumoNet((dir / "city.net.xml").string());
    if (!net) return net.status();
    return readSignalStates(*net, (dir / "signals.xml").string());
}

}  // namespace vista
