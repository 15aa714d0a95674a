// Depth read-back shared by the bench's renderer (render/offscreen.cpp) and
// the viewer's far-field node (far_field_node.cpp), so both faces read the
// near field the same way and at the same cost.
//
// Contract: needs a current GL context; reads the W x H window rectangle at
// (x, y) of the current read buffer into `out` (resized to W*H), row 0 at
// the top, window-space depth in [0, 1] (1 = nothing drawn). `scratch` is
// caller-owned reuse storage. The depth is read as normalised 32-bit
// integers and converted while the rows are flipped, in one pass: on
// llvmpipe (24-bit depth) that read is about 5x faster than GL_FLOAT, and
// u / (2^32 - 1) is the GL_FLOAT value within float rounding (1 stays 1).
#pragma once
#include <cstdint>
#include <vector>

namespace vista {

void readDepthTopDown(int x, int y, int width, int height, std::vector<uint32_t>& scratch, std::vector<float>& out);

}  // namespace vista
