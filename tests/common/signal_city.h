// A hand-made street graph with every kind of signal of the lane model
// (citygen/lanes.h): a crossing of four arterials (traffic lights), east of
// it a junction of two arterials and two locals (stop signs on the locals)
// and north of it a tee of an arterial and two locals (yield signs on the
// locals); 400 m city, 100 m tiles, hills so that the poles stand on the
// terrain. Header-only, for the citygen and the pipeline tests.
#pragma once
#include "citygen/params.h"
#include "citygen/street_graph.h"

namespace vista::test {

inline StreetGraph signalStreets() {
    StreetGraph g;
    g.nodes = {{0, 0},   {-150, 0},  {0, 110},    {0, -150},   {110, 0},
               {190, 0}, {110, 120}, {110, -150}, {-120, 110}, {60, 110}};
    g.edges = {{0, 1, RoadClass::Arterial, 13.0f, 4}, {0, 2, RoadClass::Arterial, 13.0f, 4},
               {0, 3, RoadClass::Arterial, 13.0f, 4}, {0, 4, RoadClass::Arterial, 13.0f, 4},
               {4, 5, RoadClass::Arterial, 13.0f, 4}, {4, 6, RoadClass::Local, 7.5f, 2},
               {4, 7, RoadClass::Local, 7.5f, 2},     {2, 8, RoadClass::Local, 7.5f, 2},
               {2, 9, RoadClass::Local, 7.5f, 2}};
    return g;
}

inline CityParams signalCityParams() {
    CityParams p;
    p.size_m = 400;
    p.tile_size_m = 100;
    p.seed = 7;
    p.hills_amplitude_m = 4;
    p.hills_wavelength_m = 300;
    return p;
}

}  // namespace vista::test
