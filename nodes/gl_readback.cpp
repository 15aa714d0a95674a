// Depth read-back, rows flipped and converted in one pass (gl_readback.h).
#include "nodes/gl_readback.h"

#include <algorithm>

#include <osg/GL>

namespace vista {

void readDepthTopDown(int x, int y, int width, int height, std::vector<uint32_t>& scratch, std::vector<float>& out) {
    const size_t W = size_t(std::max(0, width)), H = size_t(std::max(0, height)), n = W * H;
    scratch.resize(n);
    out.resize(n);
    if (n == 0) return;
    glReadPixels(x, y, GLsizei(W), GLsizei(H), GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, scratch.data());
    constexpr float kScale = float(1.0 / 4294967295.0);
    for (size_t row = 0; row < H; ++row) {
        const uint32_t* in = scratch.data() + (H - 1 - row) * W;  // GL rows bottom-up
        float* o = out.data() + row * W;
        for (size_t i = 0; i < W; ++i) o[i] = std::min(1.0f, float(in[i]) * kScale);
    }
}

}  // namespace vista
