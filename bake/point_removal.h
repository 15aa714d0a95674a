// Removal of redundant LDI samples (thesis 5.3.2; step 6 of docs/reference/bake.md
// "Pipeline").
//
// A sample of camera k is removed when another camera m samples the same
// surface there (a sample of m's pixel lies within 2 footprints with a
// similar normal) with a smaller footprint (1 % tie band, lower camera index
// wins) that is also sufficient: m's two pixel steps, moved onto the surface
// plane (exact derivative of the ray-plane intersection) and projected into
// the target view (looking along the sampling-plane normal) from the cell
// point nearest to the sample and from the 8 cell corners, span a lattice
// whose triangulation edges (reduced basis, plus the shorter diagonal with
// the sqrt2 factor) are at most one output pixel / fp (+1 % for rounding).
// Deterministic (each sample decided on its own); thread-safe.
#pragma once
#include <cstdint>
#include <vector>

#include "bake/ldi_sampling.h"

namespace vista {

// keep[i] = 0 for samples sampled better and sufficiently by another camera;
// all 1 when p.removeRedundant is off. `only` (optional, one per sample):
// samples with only[i] == 0 get keep 0 without being examined (the others
// are decided as without it: every sample of the LDI can still be the better one).
std::vector<uint8_t> removeRedundant(const LdiResult& ldi, const SamplingSetup& s, const Box3& cell,
                                     const SamplingParams& p, const std::vector<uint8_t>* only = nullptr);

}  // namespace vista
