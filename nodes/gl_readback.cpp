// Depth read-back, rows flipped and converted in one pass (gl_readback.h).
#include "nodes/gl_readback.h"

#include <algorithm>
#include <cstring>

#include <osg/GL>

namespace vista {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "readColorTopDown assumes a little-endian machine");

void readColorTopDown(int x, int y, int width, int height, std::vector<uint32_t>& scratch, uint8_t* out) {
    const size_t W = size_t(std::max(0, width)), H = size_t(std::max(0, height)), n = W * H;
    scratch.resize(n);
    if (n == 0) return;
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(x, y, GLsizei(W), GLsizei(H), GL_BGRA, GL_UNSIGNED_INT_8_8_8_8_REV, scratch.data());
    for (size_t row = 0; row < H; ++row) {
        const uint32_t* in = scratch.data() + (H - 1 - row) * W;  // GL rows bottom-up
        uint8_t* o = out + row * W * 4;
        for (size_t i = 0; i < W; ++i) {
            const uint32_t p = in[i];  // 0xAARRGGBB
            // Bytes R, G, B, A in memory: the value 0xAABBGGRR on a little-endian machine.
            const uint32_t q = (p & 0xFF00FF00u) | ((p >> 16) & 0xFFu) | ((p & 0xFFu) << 16);
            std::memcpy(o + 4 * i, &q, 4);
        }
    }
}

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
