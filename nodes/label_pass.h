// Label pass: the state that draws ground-truth labels (instance id, semantic
// class, metric eye depth) instead of colours, over the same chunk geometry
// as the colour pass (NearFieldScene::labelChunks shares the colour chunks'
// vertex arrays and transforms, so both passes rasterise the same pixels).
//
// Outputs of a fragment (two colour attachments of the label FBO,
// OffscreenRenderer::renderLabels):
//   attachment 0 (RGBA8): the instance id (citygen/labels.h), bytes
//                         little endian in R, G, B, A (exact);
//   attachment 1 (RGBA32F): R = eye depth in metres (distance along the
//                         optical axis, -z in eye space, interpolated
//                         perspective-correctly, float), G = semantic class.
// Cleared to 0 (sky: id 0, class 0, depth 0 = nothing drawn).
// Shaders: GLSL 1.30 (integer vertex attributes); positions go through
// ftransform() (meshes) and the instanced trees' own transform, exactly as the
// colour pass, so the depth test picks the same surfaces.
// Vertex attributes: kLabelAttrib (per-vertex id, meshes), kLabelClassAttrib
// (per-vertex class), kTreeIdAttrib (per-instance id, trees), instance matrix
// columns kInstanceAttrib0..+3 (runtime/scene/scene_graph.h).
#pragma once
#include <osg/StateSet>
#include <osg/ref_ptr>

namespace vista {

// State of the label pass's root (mesh program, no blending, back faces culled).
osg::ref_ptr<osg::StateSet> labelRootState();
// State of the instanced tree label geometries (instanced program + divisors);
// one per NearFieldScene, shared by its tree geometries.
osg::ref_ptr<osg::StateSet> labelTreeState();

}  // namespace vista
