// The OSG side of tree impostors (citygen/tree_impostor.h): the quads of one
// prototype as shared arrays, its atlas as an inline RGBA texture, and an
// instanced draw of them with the per-instance matrix columns of the city
// file's instanced trees (scene_graph.h: kInstanceAttrib0 .. +3, divisor 1).
//
// Geometry names: kTreeImpostorGeometryPrefix + prototype index. State (one
// StateSet per prototype, shared by all its draws): the program
// "vista.instanced_tree_impostors" (instancing as the trees' program; the
// fragment stage samples the atlas, discards alpha < kImpostorAlphaRef / 255
// (alpha test, no blending: draw order does not matter) and applies the haze
// uniforms of scene_graph.h, which are 0 = no haze unless a renderer sets
// them), the atlas on unit 0 (linear, mipmapped, clamped; the image stored
// inline in .osgb, so files are self-contained and their bytes deterministic),
// face culling off (quads are seen from both sides).
// Only OSG-side rooms (nodes/, bake/, the vista tool) include this header.
#pragma once
#include <osg/Array>
#include <osg/Geometry>
#include <osg/PrimitiveSet>
#include <osg/StateSet>
#include <osg/ref_ptr>

#include "citygen/tree_impostor.h"

namespace vista {

constexpr const char* kTreeImpostorGeometryPrefix = "tree_impostor_";
constexpr const char* kTreeImpostorProgramName = "vista.instanced_tree_impostors";

struct TreeImpostorArrays {
    osg::ref_ptr<osg::Vec3Array> verts, normals;
    osg::ref_ptr<osg::Vec2Array> texcoords;
    osg::ref_ptr<osg::Vec4ubArray> colors;  // white, one per vertex (stock viewers' colour binding)
    osg::ref_ptr<osg::DrawElementsUInt> triangles;
    osg::ref_ptr<osg::StateSet> state;
    osg::BoundingBox bounds;  // of the quads, prototype frame
    bool empty() const { return !triangles || triangles->empty(); }
};

// The arrays and state of one prototype's impostor (empty impostor: empty arrays).
TreeImpostorArrays makeTreeImpostorArrays(const TreeImpostor& impostor);

// One instanced draw of `arrays` named kTreeImpostorGeometryPrefix +
// `prototype`, with `instances` instances whose matrix columns are cols[0..3]
// (Vec4Arrays of at least `instances` entries, shared, not copied) and the
// given initial bound (tile frame). Null when the impostor is empty.
osg::ref_ptr<osg::Geometry> instancedTreeImpostor(const TreeImpostorArrays& arrays, unsigned prototype,
                                                  osg::Array* const cols[4], unsigned instances,
                                                  const osg::BoundingBox& bound);

// True when `name` is an impostor geometry's name; `prototype` gets its index.
bool isTreeImpostorName(const std::string& name, long* prototype = nullptr);

}  // namespace vista
