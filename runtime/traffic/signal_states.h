// What each traffic-light head of the city shows at a time, from SUMO's
// traffic-light states (a traffic directory's signals.xml) and the network's
// link of every OpenDRIVE signal (SumoNet::signalLinks).
//
// Contract:
// - A head is an OpenDRIVE <signal id> of the city (the LaneModel::signals
//   index, which is also the instance index of the head's label). Its links
//   are the junction links netconvert marks with that id; its lamp at time t
//   is the state of those links in the last <tlsState> of their light at or
//   before t: Green when any link is green ('G', 'g'), else Amber when any is
//   yellow ('y', 'Y'), else RedAmber when any is red-yellow ('u'), else Red
//   when any is red or stop ('r', 'R', 's'), else Off ('o', 'O': off or
//   blinking).
//   A head without links, a time before its light's first record and a link
//   index beyond the state string give Off.
// - readSignalStates() streams signals.xml (expat); a missing, truncated or
//   malformed file, a <tlsState> without time, id or state, a time that
//   goes back for a light, or a light the network does not have is an error
//   naming the file and the line. Pure, thread-safe; lampAt() is const and
//   thread-safe, O(log records of the light).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "foundation/status.h"
#include "runtime/traffic/sumo_net.h"

namespace vista {

enum class LampState : uint8_t { Off = 0, Red, RedAmber, Amber, Green };

// "off", "red", "red-amber", "amber", "green".
const char* lampStateName(LampState s);

// The lamp of one light's links given SUMO's letters (see the contract).
LampState lampOfLetters(const std::string& letters);

class SignalStates {
public:
    // The lamp of head `signalId` at time `t` (seconds of the traffic's clock).
    LampState lampAt(uint32_t signalId, double t) const;
    // The SUMO light and link indices of a head (empty: the head has no link).
    std::vector<SumoSignalLink> linksOf(uint32_t signalId) const;
    size_t lightCount() const { return _lights.size(); }

private:
    friend Result<SignalStates> readSignalStates(const SumoNet& net, const std::string& signalsPath);
    struct Record {
        double time;
        std::string state;
    };
    std::vector<std::string> _lights;           // SUMO light ids (SumoNet::trafficLights)
    std::vector<std::vector<Record>> _records;  // per light, by time
    std::vector<SumoSignalLink> _links;         // sorted by signalId
};

Result<SignalStates> readSignalStates(const SumoNet& net, const std::string& signalsPath);

// readSumoNet(DIR/city.net.xml), then readSignalStates(DIR/signals.xml).
Result<SignalStates> loadSignalStates(const std::string& trafficDir);

}  // namespace vista
