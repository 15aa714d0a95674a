// Baked lighting: the effects of a scene that change prelit colours at
// generation, computed once with Embree rays into the whole generated city
// (buildings, ground, trees as occluders) and stored in the vertex colours, so
// the rasteriser, the ray caster, the cache and the impostors show them alike
// and no frame pays for them.
//   sun_shadows        soft shadows: `samples` rays per point towards a sun
//                      disc of `softness_deg` angular diameter;
//   ambient_occlusion  the ambient term scaled by 1 - strength * (occluded
//                      share of `samples` cosine-distributed rays within radius_m);
//   night              pools of warm light under the street lights
//                      (smooth falloff to light_radius_m, no occlusion).
// Surfaces are refined where the light changes: an edge is halved while the
// light at its ends or at its midpoint differs by more than a tolerance and
// it is longer than the effect's resolution_m (edges longer than 8x the
// finest resolution, at least 4 m, are halved anyway so no shadow falls
// between vertices unseen). Refinement decides per edge from its end points,
// normal and colours only, so coincident edges of neighbouring faces split
// alike (no cracks). Tree prototypes are shared by many instances: trees cast
// shadows and occlude but are not relit. Lamps and, at night, windows (lit or
// dark) keep their colours.
//
// Contract: deterministic (sample patterns derive from quantised positions,
// never from thread count or timing); colours stay finite bytes; returns an
// error Status only when the ray scene cannot be built. calledFor() says
// whether the city declares anything this pass does (else bakeLighting()
// returns at once and changes nothing).
#pragma once
#include <cstddef>
#include <cstdint>

#include "citygen/city.h"
#include "foundation/progress.h"
#include "foundation/status.h"

namespace vista {

struct BakedLightingStats {
    bool ran = false;
    double seconds = 0;                              // whole pass
    double sceneSeconds = 0;                         // of which: building the occluder ray scene
    size_t trianglesBefore = 0, trianglesAfter = 0;  // tile meshes (refinement growth)
    uint64_t rays = 0;                               // shadow + occlusion rays cast
};

bool bakedLightingCalledFor(const CityParams& params);
Status bakeLighting(City& city, Progress* progress, BakedLightingStats& stats);

}  // namespace vista
