// The files of a rig run (rig_dataset.h).
#include "runtime/engine/rig_dataset.h"

#include <cstdio>
#include <cstring>

namespace vista {

namespace {

template <class T>
void put(std::string& s, T v) {
    static_assert(sizeof(T) == 4, "4-byte values");
    char b[4];
    std::memcpy(b, &v, 4);  // little-endian host (x86-64, AArch64)
    s.append(b, 4);
}

// OpenCV camera frame (x right, y down, z forward) as columns of body axes (x forward, y left, z up).
glm::dmat3 cvInBody() {
    glm::dmat3 m(0.0);
    m[0] = {0.0, -1.0, 0.0};  // cv x (right) = -body y
    m[1] = {0.0, 0.0, -1.0};  // cv y (down) = -body z
    m[2] = {1.0, 0.0, 0.0};   // cv z (forward) = body x
    return m;
}

RowMajor4 rows(const glm::dmat3& r, const glm::dvec3& t) {
    RowMajor4 m{};
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) m[size_t(i)][size_t(j)] = r[j][i];
        m[size_t(i)][3] = t[i];
    }
    m[3] = {0.0, 0.0, 0.0, 1.0};
    return m;
}

std::string line(const char* name, const double (&v)[12]) {
    std::string s = name;
    s += ':';
    char b[32];
    for (double x : v) {
        std::snprintf(b, sizeof b, " %.12e", x);
        s += b;
    }
    return s + "\n";
}

}  // namespace

std::string floBytes(const float* flow, int width, int height) {
    std::string s;
    s.reserve(12 + size_t(width) * size_t(height) * 8);
    put(s, 202021.25f);
    put(s, int32_t(width));
    put(s, int32_t(height));
    const size_t at = s.size(), n = size_t(width) * size_t(height) * 2;
    s.resize(at + n * 4);
    std::memcpy(&s[at], flow, n * 4);
    return s;
}

std::string velodyneBytes(const LidarSweep& sweep) {
    std::string s;
    s.reserve(sweep.points.size() * 16);
    for (const LidarPoint& p : sweep.points)
        put(s, p.sensor.x), put(s, p.sensor.y), put(s, p.sensor.z), put(s, p.intensity);
    return s;
}

std::string lidarLabelBytes(const LidarSweep& sweep) {
    std::string s;
    s.reserve(sweep.points.size() * 4);
    for (const LidarPoint& p : sweep.points) put(s, uint32_t(p.semantic));
    return s;
}

std::string lidarInstanceBytes(const LidarSweep& sweep) {
    std::string s;
    s.reserve(sweep.points.size() * 4);
    for (const LidarPoint& p : sweep.points) put(s, p.instance);
    return s;
}

RowMajor4 poseToWorld(const RigPose& pose, const glm::dvec3& offset) {
    return rows(pose.rotation, pose.position - offset);
}

RowMajor4 cameraToWorld(const RigPose& pose, const glm::dvec3& offset) {
    return rows(pose.rotation * cvInBody(), pose.position - offset);
}

std::string kittiCalib(const Rig& rig) {
    const RigCamera* ref = nullptr;
    for (const RigCamera& c : rig.cameras)
        if (!c.model.fisheye()) {
            ref = &c;
            break;
        }
    if (!ref) return "";
    // Everything in the vehicle frame; the reference camera's cv frame: Rref^T (p - tref).
    const glm::dmat3 refRot = mountRotation(ref->mount) * cvInBody();
    const glm::dvec3 refPos = ref->mount.position;
    std::string out;
    for (size_t k = 0; k < rig.cameras.size(); ++k) {
        const RigCamera& c = rig.cameras[k];
        if (c.model.fisheye()) continue;
        const glm::dmat3 rot = mountRotation(c.mount) * cvInBody();
        // ref cv -> vehicle -> camera k cv.
        const glm::dmat3 R = glm::transpose(rot) * refRot;
        const glm::dvec3 t = glm::transpose(rot) * (refPos - c.mount.position);
        const CameraModel& m = c.model;
        const double K[3][3] = {{m.fx, 0, m.cx}, {0, m.fy, m.cy}, {0, 0, 1}};
        double P[12];
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 4; ++j) {
                double v = 0;
                for (int l = 0; l < 3; ++l) v += K[i][l] * (j < 3 ? R[j][l] : t[l]);
                P[i * 4 + j] = v;
            }
        out += line(("P" + std::to_string(k)).c_str(), P);
    }
    if (!rig.lidars.empty()) {
        const RigLidar& l = rig.lidars.front();
        // lidar body -> vehicle -> reference cv.
        const glm::dmat3 R = glm::transpose(refRot) * mountRotation(l.mount);
        const glm::dvec3 t = glm::transpose(refRot) * (l.mount.position - refPos);
        double T[12];
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j) T[i * 4 + j] = R[j][i];
            T[i * 4 + 3] = t[i];
        }
        out += line("Tr_velo_to_cam", T);
    }
    return out;
}

}  // namespace vista
