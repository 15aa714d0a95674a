// The start tags of a SUMO network's internal lanes, found and rewritten in
// place: the one scan behind forbidJunctionLaneChanges() (junction_lanes.h)
// and restrictTightTurns() (junction_turns.h).
//
// Contract:
// - scanInternalLanes() reads `netPath` whole and parses it (expat); for
//   every <lane> child of an internal <edge> (function="internal", a child of
//   the root <net>) it calls pick(lane) and keeps the tag when pick returns
//   true. A pick error stops the scan and is returned. The result holds the
//   file's text and the kept tags' byte ranges: from "<lane" to the end of
//   the start tag, before its "/>" or ">" (quoted values may hold either).
// - rewriteLaneTags() replaces each kept tag's range by rewrite(i, tagText)
//   (i: the tag's index in scan order) and replaces the file atomically;
//   every other byte stays as it was, so the result is deterministic.
// - A file that cannot be read, is empty, is not a SUMO network (root other
//   than <net>), is truncated or malformed is an error naming the file (and
//   the line); nothing is written then.
#pragma once
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "foundation/status.h"

namespace vista {

// One internal lane's start tag as the parser reads it.
class LaneTag {
public:
    explicit LaneTag(const char** atts) : _atts(atts) {}
    const char* attribute(const char* name) const;  // its value, or null when absent
private:
    const char** _atts;
};

struct LaneTagRange {
    size_t begin = 0, end = 0;  // byte offsets in NetLaneTags::text
};

struct NetLaneTags {
    std::string text;  // the whole network file
    std::vector<LaneTagRange> tags;
};

Result<NetLaneTags> scanInternalLanes(const std::string& netPath,
                                      const std::function<Result<bool>(const LaneTag&)>& pick);
Status rewriteLaneTags(const std::string& netPath, const NetLaneTags& net,
                       const std::function<std::string(size_t, const std::string&)>& rewrite);

}  // namespace vista
