#include "runtime/traffic/junction_lanes.h"

#include "runtime/traffic/net_lane_tags.h"

namespace vista {

Result<size_t> forbidJunctionLaneChanges(const std::string& netPath) {
    auto net = scanInternalLanes(netPath, [](const LaneTag& lane) -> Result<bool> {
        return !lane.attribute("changeLeft") && !lane.attribute("changeRight");
    });
    if (!net) return net.status();
    // The marks go at the end of each <lane ...> start tag (before "/>" or
    // ">"), so the tag still begins with its id as netconvert wrote it.
    static const char kMark[] = " changeLeft=\"ignoring\" changeRight=\"ignoring\"";
    VISTA_RETURN_IF_ERROR(rewriteLaneTags(netPath, *net, [](size_t, const std::string& tag) { return tag + kMark; }));
    return net->tags.size();
}

}  // namespace vista
