// libFuzzer target: an OpenStreetMap XML extract (vista gen --osm).
// Accepted extracts give a planar street graph of bounded extent.
#include <cstdlib>

#include "citygen/params.h"
#include "citygen/street_graph.h"
#include "citygen/streets.h"
#include "tests/fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size > 200000) return 0;  // keep one input's work bounded
    vista::CityParams params;
    auto g = vista::importOsm(vista::fuzz::inputFile(".osm", data, size), params);
    if (g && !vista::checkPlanarGraph(g->streets, 0.0)) std::abort();
    return 0;
}
