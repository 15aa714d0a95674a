// image_psnr: luma PSNR (dB, capped at 99) between two PNG images of equal
// size, and the fraction of pixels whose channels differ by more than 8.
// Used by docs/tools/before_after.sh to compare two builds' images of the same
// frames directly. Usage: image_psnr A.png B.png  -> prints "psnr_db fraction".
// Exit code 2 on unreadable files or different sizes.
#include <cstdio>

#include "runtime/engine/image.h"
#include "runtime/engine/metrics.h"

int main(int argc, char** argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: image_psnr A.png B.png\n");
        return 2;
    }
    auto a = vista::readPng(argv[1]), b = vista::readPng(argv[2]);
    if (!a || !b) {
        std::fprintf(stderr, "image_psnr: %s\n", (!a ? a.status() : b.status()).message().c_str());
        return 2;
    }
    if (a->width != b->width || a->height != b->height) {
        std::fprintf(stderr, "image_psnr: sizes differ (%dx%d vs %dx%d)\n", a->width, a->height, b->width, b->height);
        return 2;
    }
    std::printf("%.3f %.6f\n", vista::lumaPsnr(*a, *b), vista::fractionDiffering(*a, *b, 8));
    return 0;
}
