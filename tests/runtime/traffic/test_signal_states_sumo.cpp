// The traffic-light heads of a generated city show SUMO's states: after a
// SUMO run on the city's OpenDRIVE, every traffic-light <signal> of the .xodr
// has junction links in the network, and at every switch of a light the
// head's lamp (SignalStates) is red when SUMO has all of the head's links red
// and green when SUMO has one of them green. The links and states are read
// here a second way (line by line from the files, no XML reader) so that the
// mapping is checked, not restated. The same run keeps SUMO's collision
// records (collisions.xml, without its wall-clock date), and the manifest's
// collision_events count them.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "citygen/blocks.h"
#include "citygen/generate.h"
#include "citygen/opendrive.h"
#include "foundation/progress.h"
#include "runtime/traffic/signal_states.h"
#include "runtime/traffic/traffic_run.h"
#include "tests/common/sumo_city.h"
#include "tests/common/temp_dir.h"

using namespace vista;
using vista::test::TempDir;

namespace {

std::vector<std::string> lines(const std::string& path) {
    std::ifstream in(path);
    std::vector<std::string> out;
    for (std::string l; std::getline(in, l);) out.push_back(l);
    return out;
}

}  // namespace

TEST(SignalStatesSumo, HeadsShowTheStateSumoHadForTheirLinks) {
    VISTA_SKIP_WITHOUT_SUMO();
    auto made = test::xodrCity(test::sumoCityParams());
    ASSERT_TRUE(made) << made.status().message();
    const std::string* xodr = &made->xodr;
    TempDir tmp("vista_signal_states_sumo");
    TrafficOptions opt;
    opt.demand.vehicles = 40;
    opt.demand.pedestrians = 40;
    opt.demand.durationS = 150.0;
    opt.demand.seed = 2;
    Progress quiet;
    ASSERT_TRUE(makeTraffic(*xodr, opt, tmp.file("t"), quiet, nullptr));
    {
        std::ifstream in(tmp.file("t/collisions.xml"));
        ASSERT_TRUE(in) << "no collisions.xml";
        std::stringstream text;
        text << in.rdbuf();
        const std::string coll = text.str();
        EXPECT_NE(coll.find("<collisions"), std::string::npos);
        EXPECT_EQ(coll.find("generated on"), std::string::npos);
        int records = 0;
        for (size_t at = coll.find("<collision "); at != std::string::npos; at = coll.find("<collision ", at + 1))
            ++records;
        std::ifstream jin(tmp.file("t/traffic.json"));
        std::stringstream jtext;
        jtext << jin.rdbuf();
        const std::string manifest = jtext.str();
        std::smatch m;
        ASSERT_TRUE(std::regex_search(manifest, m, std::regex("\"collision_events\": \\{\\s*\"total\": ([0-9]+)")))
            << manifest;
        EXPECT_EQ(std::stoi(m[1]), records);
        EXPECT_NE(manifest.find("\"collisions\": \"collisions.xml\""), std::string::npos);
    }
    auto states = loadSignalStates(tmp.file("t"));
    ASSERT_TRUE(states) << states.status().message();

    // The traffic lights of the .xodr.
    std::set<uint32_t> heads;
    const std::regex light("<signal [^>]*id=\"([0-9]+)\"[^>]*dynamic=\"yes\"");
    for (std::sregex_iterator it(xodr->begin(), xodr->end(), light), end; it != end; ++it)
        heads.insert(uint32_t(std::stoul((*it)[1])));
    ASSERT_FALSE(heads.empty()) << "the city has no traffic lights";

    // The network line by line: the internal lane each signal id marks, the
    // (light, link index) of the connection through that lane.
    std::map<std::string, std::set<uint32_t>> laneSignals;
    std::map<uint32_t, std::set<std::pair<std::string, int>>> headLinks;
    std::vector<std::tuple<std::string, std::string, int>> vias;
    const std::regex laneRe("<lane id=\"([^\"]+)\""), paramRe("<param key=\"signalID\" value=\"([0-9]+)\""),
        viaRe("via=\"([^\"]+)\" tl=\"([^\"]+)\" linkIndex=\"([0-9]+)\"");
    std::string lane;
    for (const std::string& l : lines(tmp.file("t/city.net.xml"))) {
        std::smatch m;
        if (std::regex_search(l, m, laneRe)) lane = m[1];
        else if (std::regex_search(l, m, paramRe)) laneSignals[lane].insert(uint32_t(std::stoul(m[1])));
        else if (std::regex_search(l, m, viaRe)) vias.emplace_back(m[1], m[2], std::stoi(m[3]));
    }
    for (const auto& [via, tl, index] : vias)
        for (uint32_t s : laneSignals[via]) headLinks[s].insert({tl, index});
    for (uint32_t h : heads) {
        ASSERT_FALSE(headLinks[h].empty()) << "traffic light " << h << " controls no link in the network";
        std::set<std::pair<std::string, int>> got;
        for (const SumoSignalLink& l : states->linksOf(h)) got.insert({std::string(), l.linkIndex});
        EXPECT_EQ(got.size(), headLinks[h].size()) << "traffic light " << h;
    }

    // Every switch: SUMO's letters of the head's links against the lamp.
    const std::regex stateRe("<tlsState time=\"([0-9.]+)\" id=\"([^\"]+)\"[^>]*state=\"([^\"]+)\"");
    size_t reds = 0, greens = 0;
    for (const std::string& l : lines(tmp.file("t/signals.xml"))) {
        std::smatch m;
        if (!std::regex_search(l, m, stateRe)) continue;
        const double t = std::stod(m[1]);
        const std::string tl = m[2], state = m[3];
        for (uint32_t h : heads) {
            bool mine = false, allRed = true, anyGreen = false;
            for (const auto& [light, index] : headLinks[h]) {
                if (light != tl) continue;
                mine = true;
                const char c = state.at(size_t(index));
                allRed = allRed && c == 'r';
                anyGreen = anyGreen || c == 'G' || c == 'g';
            }
            if (!mine) continue;
            // Half a step after the switch (the record holds until the next).
            const LampState lamp = states->lampAt(h, t + 0.25);
            if (allRed) {
                ++reds;
                EXPECT_EQ(lamp, LampState::Red) << "head " << h << " at " << t << " s: SUMO has " << state;
            }
            if (anyGreen) {
                ++greens;
                EXPECT_EQ(lamp, LampState::Green) << "head " << h << " at " << t << " s: SUMO has " << state;
            }
        }
    }
    EXPECT_GT(reds, 0u);
    EXPECT_GT(greens, 0u);
}
