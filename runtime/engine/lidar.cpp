#include "runtime/engine/lidar.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <tbb/parallel_for.h>

#include "citygen/labels.h"
#include "foundation/units.h"
#include "runtime/engine/far_field_stages.h"
#include "runtime/engine/ground_truth.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/scene/camera.h"

namespace vista {

namespace {

Status bad(const char* field, double value, const char* range) {
    char v[64];
    std::snprintf(v, sizeof(v), "%.6g", value);
    return Status::error(std::string("lidar ") + field + " = " + v + " is outside " + range);
}

// Columns cast per task: a few packets of every beam.
constexpr size_t kColumnsPerTask = 16;

}  // namespace

Status validateLidarSpec(const LidarSpec& s) {
    if (s.elevationDeg.empty() || s.elevationDeg.size() > size_t(kMaxLidarBeams))
        return bad("beams", double(s.elevationDeg.size()), "1 .. 256");
    for (double e : s.elevationDeg)
        if (!(e >= -90.0 && e <= 90.0)) return bad("beam elevation (degrees)", e, "[-90, 90]");
    if (!(s.columns >= 1 && s.columns <= 65536)) return bad("columns", s.columns, "1 .. 65536");
    if (!(s.minRange >= 0.0 && s.minRange < 10000.0)) return bad("min_range (m)", s.minRange, "[0, 10000)");
    if (!(s.maxRange > s.minRange && s.maxRange <= 10000.0))
        return bad("max_range (m)", s.maxRange, "(min_range, 10000]");
    if (!(s.rotationHz > 0.0 && s.rotationHz <= 100.0)) return bad("rotation_hz", s.rotationHz, "(0, 100]");
    if (!std::isfinite(s.startAzimuthDeg)) return bad("start_azimuth (degrees)", s.startAzimuthDeg, "finite values");
    return Status::ok();
}

std::vector<double> evenBeamTable(int beams, double lowDeg, double highDeg) {
    std::vector<double> t;
    for (int b = 0; b < beams; ++b) t.push_back(beams == 1 ? lowDeg : lowDeg + (highDeg - lowDeg) * b / (beams - 1));
    return t;
}

float lidarReflectivity(uint8_t semanticClass) {
    switch (SemanticClass(semanticClass)) {
        case SemanticClass::TrafficSign: return 0.95f;  // retro-reflective sheeting
        case SemanticClass::LaneMarking: return 0.7f;   // paint with glass beads
        case SemanticClass::TrafficLight: return 0.3f;
        case SemanticClass::StreetLight: return 0.35f;
        case SemanticClass::Road: return 0.12f;  // asphalt
        case SemanticClass::Sidewalk: return 0.3f;
        case SemanticClass::Terrain: return 0.25f;
        case SemanticClass::Grass: return 0.4f;
        case SemanticClass::BuildingWall: return 0.35f;
        case SemanticClass::Window: return 0.08f;  // glass returns little
        case SemanticClass::Roof: return 0.2f;
        case SemanticClass::TreeTrunk: return 0.3f;
        case SemanticClass::TreeLeaves: return 0.45f;
        case SemanticClass::Car:
        case SemanticClass::Van:
        case SemanticClass::Bus:
        case SemanticClass::Truck:
        case SemanticClass::Vehicle: return 0.5f;     // painted metal and glass
        case SemanticClass::Bicycle:                  // a thin frame and its rider
        case SemanticClass::Pedestrian: return 0.3f;  // clothes
        default: return 0.2f;
    }
}

glm::dmat3 lidarToWorld(const LidarPose& pose) {
    Camera c;
    c.heading = pose.heading;
    c.pitch = pose.pitch;
    c.roll = pose.roll;
    return glm::dmat3(c.forward(), -c.right(), c.up());  // columns: sensor x, y, z in the world
}

namespace {

// Casts columns [begin, end) of a sweep into `all` / `kept` (parallel over column blocks).
struct SweepCaster {
    const SceneModel& city;
    const RayScene& rays;
    const LidarSpec& spec;
    const LidarPoseAt& poseAt;
    double t0;
    std::vector<double> cosEl, sinEl;
    std::vector<LidarPoint> all;
    std::vector<uint8_t> kept;

    SweepCaster(const SceneModel& c, const RayScene& r, const LidarSpec& s, const LidarPoseAt& p, double t)
        : city(c), rays(r), spec(s), poseAt(p), t0(t) {
        const size_t beams = spec.elevationDeg.size();
        // Beam directions in the sensor frame at azimuth 0 (elevation only).
        cosEl.resize(beams), sinEl.resize(beams);
        for (size_t b = 0; b < beams; ++b) {
            cosEl[b] = std::cos(spec.elevationDeg[b] * kPi / 180.0);
            sinEl[b] = std::sin(spec.elevationDeg[b] * kPi / 180.0);
        }
        all.resize(beams * size_t(spec.columns));
        kept.assign(all.size(), 0);
    }
    // The time of column c since the sweep's start.
    double columnTime(size_t c) const { return double(c) / (double(spec.columns) * spec.rotationHz); }

    void cast(size_t begin, size_t end, int threads) {
        const size_t beams = spec.elevationDeg.size(), columns = size_t(spec.columns);
        const double spin = spec.clockwise ? -1.0 : 1.0;
        const glm::dvec3 frame = rays.frameOrigin();
        inArena(threads, [&] {
            tbb::parallel_for(tbb::blocked_range<size_t>(begin, end, kColumnsPerTask), [&](const auto& br) {
                const size_t n = (br.end() - br.begin()) * beams;
                std::vector<glm::vec3> org(n), dir(n);
                std::vector<glm::dvec3> sensorDir(n);
                std::vector<double> when(n);
                std::vector<RayHit> hit(n);
                size_t k = 0;
                for (size_t c = br.begin(); c < br.end(); ++c) {
                    const double t = columnTime(c);
                    const LidarPose pose = poseAt(t0 + t);
                    const glm::dmat3 R = lidarToWorld(pose);
                    const double az = (spec.startAzimuthDeg + spin * 360.0 * double(c) / double(columns)) * kPi / 180.0;
                    for (size_t b = 0; b < beams; ++b, ++k) {
                        sensorDir[k] = {cosEl[b] * std::cos(az), cosEl[b] * std::sin(az), sinEl[b]};
                        org[k] = glm::vec3(pose.position - frame);
                        dir[k] = glm::vec3(glm::normalize(R * sensorDir[k]));
                        when[k] = t;
                    }
                }
                rays.intersectMany(org.data(), dir.data(), int(n), hit.data(), float(spec.maxRange));
                const size_t first = br.begin() * beams;
                for (size_t i = 0; i < n; ++i) {
                    const RayHit& h = hit[i];
                    if (!h.hit || double(h.t) < spec.minRange || double(h.t) > spec.maxRange) continue;
                    const PixelLabel label = rayLabel(city, rays, h);
                    LidarPoint& p = all[first + i];
                    p.range = h.t;
                    p.sensor = glm::vec3(sensorDir[i] * double(h.t));
                    p.time = float(when[i]);
                    p.beam = uint16_t(i % beams);
                    p.semantic = label.cls;
                    p.instance = label.id;
                    const float len = glm::length(h.normal);
                    const float cosine = len > 0 ? std::abs(glm::dot(h.normal, dir[i])) / len : 1.0f;
                    p.intensity = std::clamp(lidarReflectivity(label.cls) * cosine, 0.0f, 1.0f);
                    kept[first + i] = 1;
                }
            });
        });
    }

    LidarSweep finish() {
        LidarSweep out;
        out.rays = all.size();
        out.points.reserve(out.rays);
        for (size_t i = 0; i < out.rays; ++i)
            if (kept[i]) out.points.push_back(all[i]);
        out.misses = out.rays - out.points.size();
        return out;
    }
};

}  // namespace

LidarSweep castLidarSweep(const SceneModel& city, const RayScene& rays, const LidarSpec& spec,
                          const LidarPoseAt& poseAt, double t0, int threads) {
    SweepCaster caster(city, rays, spec, poseAt, t0);
    caster.cast(0, size_t(spec.columns), threads);
    return caster.finish();
}

Result<LidarSweep> castLidarSweep(const SceneModel& city, const RayScene& rays, const LidarSpec& spec,
                                  const LidarPoseAt& poseAt, double t0, const LidarMovers& movers, int threads) {
    SweepCaster caster(city, rays, spec, poseAt, t0);
    const size_t columns = size_t(spec.columns);
    if (!movers.place) {
        caster.cast(0, columns, threads);
        return caster.finish();
    }
    VISTA_CHECK(movers.stepS > 0);
    const size_t perSlice = std::max<size_t>(1, size_t(std::floor(movers.stepS * double(columns) * spec.rotationHz)));
    for (size_t begin = 0; begin < columns; begin += perSlice) {
        const size_t end = std::min(columns, begin + perSlice);
        VISTA_RETURN_IF_ERROR(movers.place(t0 + 0.5 * (caster.columnTime(begin) + caster.columnTime(end - 1))));
        caster.cast(begin, end, threads);
    }
    return caster.finish();
}

}  // namespace vista
