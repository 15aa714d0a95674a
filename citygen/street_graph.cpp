// STUB: replaced by the streets work.
#include "citygen/street_graph.h"
namespace vista {
const char* roadClassName(RoadClass c) { return c == RoadClass::Highway ? "highway" : c == RoadClass::Arterial ? "arterial" : "local"; }
double roadWidth(RoadClass c) { return c == RoadClass::Highway ? 18.0 : c == RoadClass::Arterial ? 12.0 : 7.0; }
int roadLanes(RoadClass c) { return c == RoadClass::Highway ? 4 : c == RoadClass::Arterial ? 3 : 2; }
std::vector<int> StreetGraph::degrees() const { std::vector<int> d(nodes.size()); for (auto& e : edges) { d[e.a]++; d[e.b]++; } return d; }
Status checkPlanarGraph(const StreetGraph&, double) { return Status::ok(); }
std::string streetGraphToJson(const StreetGraph&) { return "{}"; }
Result<StreetGraph> streetGraphFromJson(const std::string&) { return StreetGraph(); }
std::string streetGraphToGeoJson(const StreetGraph&, double, double) { return "{}"; }
}
