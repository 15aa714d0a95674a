// BakeParams: every parameter that changes a bake's result, grouped by step
// (docs/reference/bake.md; `vista bake --help` for ranges and defaults).
//
// canonical() is the text stored in the baked file (vista.bake_params) and
// hashed into each cell result's config hash: two bakes with equal text give
// the same bytes. Its text is a file format: extend it, never reorder it.
#pragma once
#include <cstdint>
#include <string>

#include "foundation/status.h"

#include "bake/appearance.h"
#include "bake/depth_mesh.h"
#include "bake/far_set.h"
#include "bake/ldi_sampling.h"
#include "bake/placement.h"
#include "bake/view_cells.h"

namespace vista {

// What a bake attaches per view cell: point impostors (thesis ch. 5) or
// textured depth meshes (Chen et al. 2003; bake/depth_mesh.h).
enum class BakeRepresentation { Points, Mesh };
// "points" / "mesh"; parse: an unknown name -> error naming the allowed values.
const char* representationName(BakeRepresentation r);
Result<BakeRepresentation> parseRepresentation(const std::string& name);

struct BakeParams {
    ViewCellParams cells;
    FarSetParams far;
    SamplingParams sampling;
    AppearanceParams appearance;
    BakeRepresentation representation = BakeRepresentation::Points;
    DepthMeshParams mesh;  // representation Mesh only
    PlacementParams
        placement;      // representation Points only (bake/placement.h); off by default here, on in `vista bake`
    uint64_t seed = 1;  // the city's seed (set from the city file by the driver)
    std::string canonical() const;
};

}  // namespace vista
