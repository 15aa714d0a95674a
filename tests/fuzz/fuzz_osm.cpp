// libFuzzer target: an OpenStreetMap XML extract (vista gen --osm), streets and buildings.
// Accepted extracts give a planar street graph of bounded extent and building footprints
// that are simple, counter-clockwise, inside the city, with clockwise holes strictly inside;
// every street node lies inside the city square, every speed limit is the
// class default or within the plausible range.
#include <cmath>
#include <cstdlib>

#include "citygen/footprint_repair.h"
#include "citygen/osm_road_tags.h"
#include "citygen/params.h"
#include "citygen/polygon.h"
#include "citygen/street_graph.h"
#include "citygen/streets.h"
#include "tests/fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size > 200000) return 0;  // keep one input's work bounded
    vista::CityParams params;
    auto g = vista::importOsm(vista::fuzz::inputFile(".osm", data, size), params, true);
    if (g && !vista::checkPlanarGraph(g->streets, 0.0)) std::abort();
    if (g) {
        const double half = 0.5 * params.size_m;
        for (const auto& n : g->streets.nodes)  // roads are clipped to the city square
            if (!(std::abs(n.x) <= half + 1e-6 && std::abs(n.y) <= half + 1e-6)) std::abort();
        for (const auto& e : g->streets.edges)  // a speed limit is the class default (0) or plausible
            if (!(e.maxspeedKmh == 0.0f ||
                  (e.maxspeedKmh >= vista::kMinMaxspeedKmh && e.maxspeedKmh <= vista::kMaxMaxspeedKmh)))
                std::abort();
        for (const auto& f : g->buildings) {
            if (!vista::isSimpleRingExact(f.outer) || !(vista::signedArea(f.outer) > 0)) std::abort();
            for (const auto& p : f.outer)
                if (!(std::abs(p.x) <= half && std::abs(p.y) <= half)) std::abort();
            for (const auto& h : f.holes)
                if (!vista::isSimpleRingExact(h) || !(vista::signedArea(h) < 0) ||
                    !vista::ringStrictlyInside(h, f.outer))
                    std::abort();
        }
    }
    return 0;
}
