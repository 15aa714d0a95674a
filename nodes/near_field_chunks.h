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
// Kinds: every chunk counts its triangles by kind (NearKind: ground, facade,
// window recess jambs, window glass, parked cars, trees, other), so a frame can
// say where its near-field triangles go.
//
// Coarse level (coarse = true): a chunk with recessed windows also gets a
// flattened twin (citygen/recess_flatten.h: glass on the facade plane, jambs
// dropped) whose every point lies within coarseError[i] metres of the chunk's
// surface; the hybrid draws it where that deviation projects to at most its
// screen-space error bound (screenDeviationPx).
//
// Contract: buildNearFieldScene() keeps the vertices, colours and state of the
// graph it is given. Chunks and objects are index-aligned: chunks[i] is drawn
// iff objects[i] is selected. Pure (builds new nodes; the input graph is not
// modified); the output does not depend on timing or threads.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <osg/Group>
#include <osg/Node>
#include <osg/StateSet>

#include "runtime/engine/adaptive_split.h"

namespace vista {

constexpr double kNearChunkSize = 40.0;  // metres

// Kinds of near-field triangles (by the city's materials; Recess = the jambs
// of recessed windows, Window = glass).
enum class NearKind : uint8_t { Ground, Facade, Recess, Window, Car, Tree, Other, Count };
constexpr size_t kNearKindCount = size_t(NearKind::Count);
const char* nearKindName(NearKind kind);  // "ground", "facade", "recess", "window", "car", "tree", "other"
using NearKindCounts = std::array<uint64_t, kNearKindCount>;

// The largest screen-space displacement, in pixels, of a point moved by at
// most `deviation` metres when the point is at least `distance` metres from
// the eye of a pinhole camera (vertical field of view fovY radians, width x
// height pixels): deviation * f / (distance * cos^2 a), f = the focal length
// in pixels, a = the angle of the frame's corner from the optical axis (the
// first-order bound |d(u,v)| <= f |dp| r / z^2 over the frustum). +inf for
// distance <= 0.
double screenDeviationPx(double deviation, double distance, double fovY, int width, int height);

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
    // Index-aligned with chunks: each chunk's triangles by kind.
    std::vector<NearKindCounts> chunkKinds;
    // Built with coarse = true (else empty): index-aligned with chunks, the
    // flattened twin (null: the chunk has nothing to flatten), its triangles
    // and its deviation from the chunk in metres (its deepest recess).
    std::vector<osg::ref_ptr<osg::Node>> coarseChunks;
    std::vector<uint64_t> coarseTriangles;
    std::vector<float> coarseError;
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
// coarse: also build the flattened twins (coarseChunks).
NearFieldScene buildNearFieldScene(osg::Node* cityScene, double chunkSize = kNearChunkSize, bool labels = false,
                                   bool coarse = false);

}  // namespace vista
