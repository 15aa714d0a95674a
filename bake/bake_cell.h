// Baking one view cell: for each street end, far-field selection
// (bake/far_set.h), sampling plane and cameras (bake/sampling_plane.h), LDI
// sampling (bake/ldi_sampling.h), redundant-point removal
// (bake/point_removal.h), appearance (bake/appearance.h), in that order.
//
// Contract: bakeCell() depends only on (city, cell, params) and in.plan,
// itself a function of (city, params) — not on thread
// count, timing (apart from the *Ms fields) or the other cells — so cells can
// be baked in any order, on any machine, and merged. An end whose far field
// is too small, whose set-up is ill-defined (cell touching the far field) or
// that yields no visible point gets no impostor and a note saying why.
// Thread-safe on a const BakeInput; runs its own loops in parallel (TBB).
#pragma once
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "bake/bake_params.h"
#include "bake/cell_result.h"
#include "foundation/status.h"

namespace vista {

struct BakeInput {
    const SceneModel* city = nullptr;
    std::vector<SceneTile> tiles;  // bakeTiles(city)
    // Placement by cost (points, p.placement.byCost): the whole city's ray
    // scene and the hit -> tile lookup; null when not asked for or when the
    // scene could not be built (then every end is baked, with a note).
    std::shared_ptr<const RayScene> cityRays;
    TileLookup tileLookup;
    // The storage-budget plan (p.placement.budgetMb > 0; planPlacement, set
    // by the caller): bakeCell then follows it instead of estimating the end.
    std::shared_ptr<const PlacementPlan> plan;
    std::vector<ViewCell> cells;       // one per street edge that is not degenerate
    std::vector<SkippedCell> skipped;  // the degenerate edges
};
BakeInput prepareBake(const SceneModel& city, const BakeParams& p);

// The whole city's placement under p.placement.budgetMb (bake/placement.h):
// every cell's street ends with a large enough far field, estimated in
// parallel (TBB; `done` counts finished cells), then ranked. Needs
// in.cityRays (else an empty plan). Deterministic: depends on (city, params).
PlacementPlan planPlacement(const BakeInput& in, const BakeParams& p, std::atomic<size_t>* done = nullptr);

// Dispatches on p.representation: point impostors (impostors) or textured
// depth meshes (meshes; bakeMeshEnd per street end, same far sets).
CellResult bakeCell(const BakeInput& in, const ViewCell& cell, const BakeParams& p);

// The textured depth mesh of one far field (soup in the frame, cell box in
// the frame): image from the cell box centre (bake/depth_mesh.h), fills
// r.mesh and r.stats (not frame, tiles or ids). Error only for a bad soup.
Status bakeMeshEnd(const TriangleSoup& soup, const Box3& cellBox, const BakeParams& p, MeshResult& r);

// Steps 1-6 for one far field (soup and cell box in the impostor frame):
// fills r.data and r.stats (not the frame, tiles or ids). `entity` keys the
// random streams. Error only for an ill-defined set-up or a bad soup.
// `keepVisible` (optional): marks the LDI samples (all of them, before the
// redundancy removal, which then examines only the marked ones) to keep;
// the others count as dropped invisible points.
Status bakeImpostor(const TriangleSoup& soup, const Box3& cellBox, const BakeParams& p, uint64_t entity,
                    ImpostorResult& r,
                    const std::function<std::vector<uint8_t>(const std::vector<glm::vec3>&)>& keepVisible = {});

}  // namespace vista
