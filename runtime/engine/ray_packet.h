// The lanes of an Embree 8-wide packet, set up one way for every caller:
// RayScene::intersectMany and the raw timing of tests/bench/bench_raw_rays.cpp
// (so "raw" differs from the wrapper only by what the wrapper adds).
// Lane k < m takes ray base + k: org[i], dir[i], tnear, tfar tfars[i] (or
// `tfar` when tfars is null), no hit yet; lanes m..7 repeat ray `base` and
// are invalid (valid[k] = 0). Contract: 1 <= m <= 8; rays base .. base+m-1
// exist. Engine-internal (includes Embree); pure.
#pragma once
#include <cstddef>

#include <embree3/rtcore.h>
#include <glm/glm.hpp>

namespace vista {

inline void fillPacket8(RTCRayHit8& rh, int* valid, const glm::vec3* org, const glm::vec3* dir, const float* tfars,
                        float tfar, size_t base, int m, float tnear = 0.0f) {
    for (int k = 0; k < 8; ++k) {
        const size_t i = base + size_t(k < m ? k : 0);
        valid[k] = k < m ? -1 : 0;
        rh.ray.org_x[k] = org[i].x;
        rh.ray.org_y[k] = org[i].y;
        rh.ray.org_z[k] = org[i].z;
        rh.ray.dir_x[k] = dir[i].x;
        rh.ray.dir_y[k] = dir[i].y;
        rh.ray.dir_z[k] = dir[i].z;
        rh.ray.tnear[k] = tnear;
        rh.ray.tfar[k] = tfars ? tfars[i] : tfar;
        rh.ray.time[k] = 0.0f;
        rh.ray.mask[k] = 0xFFFFFFFFu;
        rh.ray.id[k] = unsigned(k);
        rh.ray.flags[k] = 0;
        rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
}

}  // namespace vista
