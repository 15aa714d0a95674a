// Image metrics: luma PSNR against a reference, fraction of differing pixels,
// difference images, box downsampling for supersampled references.
//
// Luma is Y = 0.299 R + 0.587 G + 0.114 B on 8-bit values (Chen et al.).
// PSNR = 10 log10(255^2 / MSE(Y)) in dB; identical images (MSE = 0) report the
// finite cap kPsnrCapDb (99 dB), so medians and CSV files stay finite.
// Alpha is ignored everywhere. Images must have equal sizes (a contract
// violation otherwise: VISTA_CHECK). Pure functions; thread-safe.
#pragma once
#include "runtime/engine/image.h"

namespace vista {

constexpr double kPsnrCapDb = 99.0;

double lumaOf(const uint8_t* rgba);
// Mean squared luma difference.
double lumaMse(const Image& a, const Image& b);
// Luma PSNR in dB, capped at kPsnrCapDb.
double lumaPsnr(const Image& a, const Image& b);
// Fraction (0..1) of pixels whose max per-channel |difference| exceeds `threshold` (0..255).
double fractionDiffering(const Image& a, const Image& b, int threshold = 8);
// Visual difference: |luma a - luma b| scaled by `gain`, shown as red on a
// darkened grey copy of `b` (where the images agree).
Image differenceImage(const Image& a, const Image& b, double gain = 4.0);
// Box-filter downsampling by an integer factor k (width and height must be multiples of k).
Image downsampleBox(const Image& src, int k);
// Averages images of equal size (a supersampled reference from jittered renders).
Image averageImages(const std::vector<Image>& images);

}  // namespace vista
