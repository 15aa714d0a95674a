// `osglod`: the lossy conventional peer — what an OSG user would do without
// vista: stock osg::LOD per chunk with osgUtil::Simplifier-reduced far
// versions, plus small-feature culling. Timed and scored against `full` like
// every other mode.
//
// Chunks: the city re-chunked exactly as hybrid's near field
// (ModeContext::nearField, kNearChunkSize = 40 m). Each chunk becomes its
// transform -> osg::LOD (centre and radius r = the chunk's bounding sphere,
// distance d from the eye to that centre) with three levels, nearD =
// ModeOptions::fixedNearDistance() (--near, 100 m when auto):
//   level 0  the chunk itself, every triangle         d <  nearD + r
//   level 1  Simplifier, sample ratio 0.25             nearD + r <= d < 4 nearD + r
//   level 2  Simplifier, sample ratio 0.0625           d >= 4 nearD + r
// (trees: impostors on levels 1 and 2, below)
// so every chunk with a point within nearD of the eye is drawn exactly (as
// in hybrid's near field) and only chunks wholly beyond it are simplified.
// Before simplifying, vertices at the same position are welded (colours
// averaged): the city's faces are flat-shaded (no shared vertices) and the
// Simplifier never collapses an edge touching a mesh boundary, so unwelded it
// removes nothing; welded, it still stops near half the triangles (the
// meshes stay open: walls stand on the ground without a bottom face, chunks
// cut the ground), and level 2 is then barely smaller than level 1.
// Instanced trees keep their instances; from level kOsgLodTreeImpostorLevel
// on they are drawn as impostors (citygen/tree_impostor.h: 3 vertical + 1
// horizontal quad textured from an atlas baked once per prototype,
// alpha-tested; runtime/scene/tree_impostor_graph.h), on the levels before
// it with their prototype simplified once per level. Chunks of an unknown
// layout stay whole at every distance.
// Small-feature culling: the graph hangs under a nested osg::Camera whose
// cull settings add SMALL_FEATURE_CULLING at 2 pixels (nodes whose bounding
// sphere projects smaller are not drawn); everything else as the renderer.
// Set-up: "chunking" (shared) and "simplify" (every far version, parallel
// over chunks, and the tree impostors' atlases; the result does not depend
// on the thread count).
// Viewer: the same graph, infinite far plane.
#pragma once
#include <memory>

#include "nodes/render/render_mode.h"

namespace vista {

constexpr double kOsgLodRatio1 = 0.25, kOsgLodRatio2 = 0.0625;  // Simplifier sample ratios of levels 1, 2
constexpr double kOsgLodFarFactor = 4.0;                        // level 2 from kOsgLodFarFactor * nearD + r
constexpr float kOsgLodSmallFeaturePixels = 2.0f;
constexpr int kOsgLodTreeImpostorLevel =
    1;  // trees are impostors on levels >= this (1 or 2; 1 measured better: fewer triangles, closer to full)

Result<std::unique_ptr<RenderMode>> makeOsgLodMode(ModeContext& ctx);

}  // namespace vista
