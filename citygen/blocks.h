// Blocks and lots.
//
// extractBlocks(): the bounded faces of the planar street arrangement (CGAL
// Arrangement_2 on the graph's edges), each inset by half the adjacent
// street's width plus params.sidewalk_m; faces too small or too thin after the
// inset are dropped; faces cut by the city border are clipped to the square.
// Parks: params.park_fraction of blocks, preferring low density (seeded).
// subdivideLots(): recursive oriented-bounding-box splitting of every
// non-park block until lots reach ~params.lot_width_m frontage (bigger
// downtown), keeping street frontage where possible. Every lot lies inside its
// block. Both deterministic; both may use threads (output order is stable).
#pragma once
#include <vector>

#include "citygen/city.h"
#include "foundation/progress.h"

namespace vista {

std::vector<Block> extractBlocks(const StreetGraph& g, const CityParams& params, Progress* progress);
std::vector<Lot> subdivideLots(const std::vector<Block>& blocks, const CityParams& params, Progress* progress);

}  // namespace vista
