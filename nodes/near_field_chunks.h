// Near-field chunker: the city re-chunked into small square chunks so that
// the near/far split (NearFarSplit, the hybrid mode) can draw exactly the
// geometry within the near distance.
//
// Near field granularity: the city's 250 m tiles are far coarser than a 100 m
// near distance, so the chunker re-chunks the loaded scene into square chunks
// (kNearChunkSize metres, by triangle centroid; triangles larger than a chunk
// go to a per-tile "large" chunk; trees by trunk position, drawn with the
// city file's own instanced state set). A chunk holds one tile's triangles
// (all materials, in the tile's order: one draw call) and keeps the tile's
// origin, so its vertices are the loaded floats bit for bit and a chunked
// draw (in drawOrder) shows the loaded graph's pixels — except where two
// coplanar surfaces of different chunks tie in the depth buffer (far away,
// e.g. road over ground seen from high above), where the draw order decides
// which shows: a few pixels of a frame (tested: street views identical,
// elevated >= 50 dB).
//
// Contract: buildNearFieldScene() keeps the vertices, colours and state of the
// graph it is given. Chunks and objects are index-aligned: chunks[i] is drawn
// iff objects[i] is selected. Pure (builds new nodes; the input graph is not
// modified); the output does not depend on timing or threads.
#pragma once
#include <cstdint>
#include <vector>

#include <osg/Group>
#include <osg/Node>
#include <osg/StateSet>

#include "runtime/engine/adaptive_split.h"

namespace vista {

constexpr double kNearChunkSize = 40.0;  // metres

// The city re-chunked for a fine near/far split: chunks[i] is drawn iff
// objects[i] is selected. rootState = the city root's state set.
struct NearFieldScene {
    osg::ref_ptr<osg::StateSet> rootState;
    std::vector<osg::ref_ptr<osg::Node>> chunks;
    std::vector<SplitObject> objects;
    // Every chunk index once, in the loaded graph's draw order (per tile: its
    // large triangles, then its squares); `full` draws in this order. Chunk
    // indices themselves put a tile's squares first (distance ties of a
    // triangle budget then pick the squares around the eye).
    std::vector<uint32_t> drawOrder;
    // Index-aligned with chunks: the child index, in the city root, of the
    // tile (or unknown node) the chunk was cut from; -1 when the scene is not
    // a group. The baked modes hide a view cell's replaced tiles chunk by
    // chunk with it (ViewCellSwitch::setNearChunks).
    std::vector<int32_t> chunkTile;
    uint64_t triangles = 0;
    // Built with labels only (else empty / null): labelChunks[i] is the label
    // twin of chunks[i] (nodes/label_pass.h: the same vertex arrays, primitive
    // sets and transform, drawn with the label programs under labelRootState);
    // an unknown node layout gets an empty group.
    osg::ref_ptr<osg::StateSet> labelRootState;
    std::vector<osg::ref_ptr<osg::Node>> labelChunks;
};
// Builds chunks from a scene graph written by buildCityScene()/loaded by
// loadCityFile(). Unknown node layouts are kept as single chunks (bounds from
// OSG), so any scene works, only more coarsely.
// labels: also build the label twins (a city file with vista.labels; other
// files get id 0 and the class of their geometry's material name).
NearFieldScene buildNearFieldScene(osg::Node* cityScene, double chunkSize = kNearChunkSize, bool labels = false);

}  // namespace vista
