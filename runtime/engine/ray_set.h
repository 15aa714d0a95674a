// RaySet: the primary rays one far-field frame cast, as a file, so that the
// ray stage can be timed against raw Embree on exactly those rays
// (tests/bench/bench_raw_rays.cpp, docs/measurements/raw-rays.md).
//
// A set is the camera, the haze ray limit, where the rays start and the traced pixel list
// (FarField::lastTraced(): ascending indices y * width + x); the rays follow
// from them bit for bit (primaryRays(), far_field_rays.h), so a file costs 4
// bytes per ray.
//
// File ("VRAYSET1", little-endian): magic, u32 version 2, u32 frame, u32
// width, u32 height, f64 eye x y z, heading, pitch, roll, fovY, zNear,
// hazeFar, tnear, u64 count, count x u32 pixel, u64 hashBytes64 of everything
// before it (foundation/hash.h). decodeRaySet() never trusts the bytes: a
// wrong magic or version, a size outside 1..8192, a non-finite camera value,
// fovY outside (0, pi), zNear <= 0, hazeFar or tnear < 0, a count beyond the bytes or
// the image, a pixel out of the image or not ascending, a hash mismatch or
// trailing bytes are a Status naming `what`, the field, the value and the
// allowed range. writeRaySet() is atomic (foundation/atomic_file.h) and
// checks the set with the same rules (VISTA_CHECK: a bad set is a bug).
// Pure functions; thread-safe.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "foundation/status.h"
#include "runtime/scene/camera.h"

namespace vista {

struct RaySet {
    uint32_t frame = 0;            // the bench frame it came from
    Camera camera;                 // eye (world), angles, fovY, size, zNear
    double hazeFar = 0;            // > 0: rays stop at this eye-plane depth (haze); 0 = no limit
    double tnear = 0;              // where the rays start (metres; FarField::lastRayStart)
    std::vector<uint32_t> pixels;  // traced pixels, ascending, each < width * height
};

std::string encodeRaySet(const RaySet& s);
Result<RaySet> decodeRaySet(const std::string& bytes, const std::string& what);
Status writeRaySet(const std::string& path, const RaySet& s);
Result<RaySet> readRaySet(const std::string& path);

}  // namespace vista
