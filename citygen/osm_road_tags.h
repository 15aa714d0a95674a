// OSM road tags: the lane, direction, turn-lane, speed limit and width tags
// of highway=* ways, read by importOsm() (streets.h) into the StreetEdge
// fields lanes, lanesForward, lanesBackward, turnForward, turnBackward,
// maxspeedKmh and width (street_graph.h), with counts for `vista gen --stats`.
//
// Contract (docs/reference/streets.md "Road tags from OSM"):
// - oneway: yes / true / 1 -> one-way along the way, -1 / reverse -> one-way
//   against it, no / false / 0 -> two-way; without a valid value,
//   highway=motorway and junction=roundabout / circular are one-way along the
//   way, everything else two-way. Other values count as fallbacks.
// - Lane counts are positive integers ("2"; not "2;3", "2.5", "0") within
//   plausible ranges: 1..kMaxLanesPerDirection for lanes:forward /
//   lanes:backward (and for `lanes` on a one-way road), 1..kMaxLanesTotal for
//   `lanes`; a value beyond its range is not used (a fallback, never clamped).
//   One-way: the travel direction gets lanes:forward (lanes:backward against
//   the way), else lanes, else the lane count of the turn:lanes value, else
//   ceil(class lanes / 2); the other direction 0. Two-way: lanes:forward and
//   lanes:backward, else the count of turn:lanes:forward / :backward, else
//   lanes minus the other direction; a direction still unknown takes the
//   derived split (forward ceil(n/2), backward floor(n/2), n = max(lanes, 2),
//   lanes the class total when `lanes` is not used); without any
//   directional tag both stay -1 (derived by the lane model).
//   Inconsistent lane tags: the directional counts win (they say which way
//   each lane runs). `lanes` is not used when it differs from them: on a
//   one-way road from the travel direction's count, on a two-way road from
//   forward + backward when both are known, or when it leaves the other
//   direction fewer than 1 or more than kMaxLanesPerDirection lanes. Such a
//   way counts as a lanes fallback and in lanesInconsistent.
//   `lanes` (OsmRoadTags) is the used total, else the sum of the directions,
//   else the class default (0), so it always agrees with the lanes written.
// - turn:lanes (one-way roads), turn:lanes:forward / :backward: lanes
//   separated by '|', each empty or ';'-separated values of none, through,
//   left, slight_left, sharp_left, right, slight_right, sharp_right, reverse,
//   merge_to_left, merge_to_right, slide_left, slide_right; kept (whitespace
//   around values removed) only when its lane count equals that direction's
//   lane count. turn:lanes on a two-way road is ambiguous and not used.
// - maxspeed: a number in km/h, with "km/h", "kmh", "kph", "mph" or "knots";
//   "none" -> kMaxspeedNoneKmh, "walk" -> kMaxspeedWalkKmh; country defaults
//   "CC:urban", "CC:rural", "CC:trunk", "CC:motorway" for the countries of
//   osmCountrySpeed(), "CC:living_street" / "CC:walk" (walking pace),
//   "CC:zoneNN" / "CC:zone:NN" (NN km/h, mph in GB), "CC:bicycle_road" (30),
//   "GB:nsl_single" / "GB:nsl_dual" / "GB:nsl_restricted" (60 / 70 / 30 mph).
//   A limit outside [kMinMaxspeedKmh, kMaxMaxspeedKmh] (after the unit) is
//   implausible and not used, as are "signals", "variable", several values
//   and anything else: the class default (0), counted as a fallback.
// - width: a length as parseOsmLength() (osm_buildings.h) reads it, used as
//   the carriageway width when in [kMinOsmRoadWidth_m, kMaxOsmRoadWidth_m].
// Every tag present but not used (unparsable, out of range, contradicting the
// direction or the lane count) counts as a fallback; never an error.
// Deterministic and pure; thread-safe.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "citygen/street_graph.h"

namespace vista {

constexpr int kMaxLanesPerDirection = 8;
constexpr int kMaxLanesTotal = 2 * kMaxLanesPerDirection;
constexpr float kMinMaxspeedKmh = 5.0f, kMaxMaxspeedKmh = 250.0f;
constexpr float kMaxspeedNoneKmh = 130.0f;  // "none": no limit; the common advisory speed
constexpr float kMaxspeedWalkKmh = 7.0f;    // "walk": walking pace
constexpr double kMinOsmRoadWidth_m = 1.0, kMaxOsmRoadWidth_m = 100.0;

enum class OsmOneway : int8_t { Backward = -1, No = 0, Forward = 1 };

// A lane count in 1..kMaxLanesTotal (the `lanes` tag); nullopt for anything else.
std::optional<int> parseOsmLaneCount(std::string_view text);
// A lane count in 1..kMaxLanesPerDirection (lanes:forward / lanes:backward).
std::optional<int> parseOsmDirectionLaneCount(std::string_view text);
// yes/true/1, -1/reverse, no/false/0; nullopt for anything else.
std::optional<OsmOneway> parseOsmOneway(std::string_view text);
// km/h within [kMinMaxspeedKmh, kMaxMaxspeedKmh]; nullopt when unusable or outside.
std::optional<float> parseOsmMaxspeed(std::string_view text);
// Default limit (km/h) of a country code ("DE") and zone ("urban", "rural",
// "trunk", "motorway"); nullopt when not known.
std::optional<float> osmCountrySpeed(std::string_view country, std::string_view zone);
// The canonical form of a turn:lanes value (whitespace around values
// removed) and its lane count (1..kMaxLanesPerDirection); nullopt when invalid
// or empty.
struct OsmTurnLanes {
    std::string value;
    int lanes = 0;
};
std::optional<OsmTurnLanes> parseOsmTurnLanes(std::string_view text);

// The road tags of one way, in the way's direction (fields as StreetEdge's).
struct OsmRoadTags {
    int lanes = 0;  // total; 0 = class default
    int lanesForward = -1, lanesBackward = -1;
    float maxspeedKmh = 0.0f;  // 0 = class default
    float width = 0.0f;        // carriageway metres; 0 = class default
    std::string turnForward, turnBackward;
    // The same tags for the opposite direction (forward and backward swapped).
    OsmRoadTags reversed() const;
    // One-way along the way (forward lanes only) / against it.
    bool onlyForward() const { return lanesForward > 0 && lanesBackward == 0; }
    bool onlyBackward() const { return lanesBackward > 0 && lanesForward == 0; }
};

// Ways that used each tag and those whose value was not used (fallback).
struct OsmTagUse {
    size_t used = 0, fallback = 0;
};
struct OsmRoadTagStats {
    size_t ways = 0;  // highway=* road ways read
    OsmTagUse lanes, lanesForward, lanesBackward, oneway, turnLanes, turnLanesForward, turnLanesBackward, maxspeed,
        width;
    size_t onewayImplied = 0;      // one-way from highway=motorway / junction=roundabout without a valid oneway tag
    size_t lanesInconsistent = 0;  // ways whose `lanes` contradicted their directional counts (not used)
    // Ways whose lane counts / speed limit / width are the class defaults.
    size_t defaultLanes = 0, defaultMaxspeed = 0, defaultWidth = 0;
    // Street edges after planarization: with the tags of a way, without a way
    // within the matching distance (class defaults), and edges where two
    // one-way ways in opposite directions merged (each gives its direction).
    size_t edgesMatched = 0, edgesUnmatched = 0, edgesMergedOneWays = 0;
};

// key -> value of the way's tag, or nullptr when absent.
using OsmTagLookup = std::function<const char*(const char* key)>;
// Reads the road tags of one way of class `cls`, adding to `stats`.
OsmRoadTags readOsmRoadTags(const OsmTagLookup& tag, RoadClass cls, OsmRoadTagStats& stats);

// Sets the fields of `e` from tags already in the edge's direction (a -> b).
void applyOsmRoadTags(const OsmRoadTags& t, StreetEdge& e);

// The counts as a JSON object (the "osm_roads" entry of vista gen --stats).
std::string osmRoadTagStatsJson(const OsmRoadTagStats& s);

}  // namespace vista
