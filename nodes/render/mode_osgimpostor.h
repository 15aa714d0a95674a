// `osgimpostor`: stock osgSim::Impostor (an osg::LOD that caches a sprite of
// its children) on every city tile — what an OSG user would reach for today.
//
// Threshold: each tile's impostor threshold is nearD + r, where nearD =
// ModeOptions::fixedNearDistance() and r = the tile's bounding radius. OSG
// draws the real geometry while the eye is within max(threshold, sqrt(2) r)
// of the tile's bound centre and a sprite only beyond. City tiles are 250 m
// squares, so r >= 177 m and the geometry range is at least 277 m at the
// default 100 m: on a small city (a few hundred metres across) the eye is
// within that range of almost every tile on every frame, the mode draws real
// geometry and its image equals `full` (the 99 dB PSNR cap). That is why
// osgimpostor "reached 99 dB" on small cities: not a good impostor, no
// impostor. Sprites appear only on cities larger than the threshold
// (tested: no sprite and the image of `full` when every tile is within the
// threshold; sprites and a different image when a tile lies beyond).
// Notes per frame: "impostors: S sprites, G geometry" (tiles not culled).
// Set-up: "impostors" (wrapping the tiles). Viewer: the same graph.
#pragma once
#include <memory>

#include "nodes/render/render_mode.h"

namespace vista {

Result<std::unique_ptr<RenderMode>> makeOsgImpostorMode(ModeContext& ctx);

}  // namespace vista
