// Colour and depth read-back shared by the bench's renderer
// (render/offscreen.cpp), the viewer's far-field and reflection nodes and its
// screenshots, so every face reads the frame the same way and at the same cost.
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

// Colour: the same rectangle into `out` (W*H*4 bytes, RGBA, row 0 at the
// top). Read as GL_BGRA / GL_UNSIGNED_INT_8_8_8_8_REV, the window's own
// layout on llvmpipe (and the usual fast path of GPU drivers): 0.13 ms against
// 0.54 ms for GL_RGBA at 640x480 here; red and blue are swapped back while the
// rows are flipped, in one pass.
void readColorTopDown(int x, int y, int width, int height, std::vector<uint32_t>& scratch, uint8_t* out);
void readDepthTopDown(int x, int y, int width, int height, std::vector<uint32_t>& scratch, std::vector<float>& out);

}  // namespace vista
