// Trees: procedural branching prototypes and their placement.
//
// makeTreePrototypes(): a few species (e.g. broadleaf, conifer, columnar) x
// several size variants; recursive branching with thin branches (real
// microgeometry) and leaf clusters; materials Trunk/Leaves via vertex colours
// (prelit); each prototype a few hundred to ~1500 triangles.
// placeTrees(): street trees along sidewalks every street_tree_spacing_m
// (skipping intersections and building footprints), park trees at
// park_tree_density (Poisson-disc-like, seeded per block). Instances only:
// prototypes are stored once. z follows the terrain.
#pragma once
#include <vector>

#include "citygen/city.h"
#include "citygen/lighting.h"
#include "foundation/progress.h"

namespace vista {

std::vector<TreePrototype> makeTreePrototypes(const CityParams& params, const Lighting& light);
std::vector<TreeInstance> placeTrees(const City& city, Progress* progress);

}  // namespace vista
