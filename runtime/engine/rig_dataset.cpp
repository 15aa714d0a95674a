// The files of a rig run (rig_dataset.h).
#include "runtime/engine/rig_dataset.h"

#include <algorithm>
#include <cstdio>
#include <cstring>

#include "citygen/labels.h"
#include "runtime/engine/boxes.h"

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

std::string semanticKittiLabelBytes(const LidarSweep& sweep) {
    std::string s;
    s.reserve(sweep.points.size() * 4);
    for (const LidarPoint& p : sweep.points)
        put(s, uint32_t(semanticKittiInstance(p.instance)) << 16 | uint32_t(semanticKittiClass(p.semantic)));
    return s;
}

std::string vistaLabelBytes(const LidarSweep& sweep) {
    std::string s;
    s.reserve(sweep.points.size() * 4);
    for (const LidarPoint& p : sweep.points) put(s, uint32_t(p.semantic));
    return s;
}

std::string lidarTimeBytes(const LidarSweep& sweep) {
    std::string s;
    s.reserve(sweep.points.size() * 4);
    for (const LidarPoint& p : sweep.points) put(s, p.time);
    return s;
}

namespace {

// SemanticKITTI's ids, names and BGR colours (semantic-kitti.yaml) for the classes vista writes.
struct SkClass {
    uint16_t id;
    const char* name;
    int b, g, r;
};
constexpr SkClass kSkClasses[] = {
    {0, "unlabeled", 0, 0, 0},       {10, "car", 245, 150, 100},          {13, "bus", 250, 80, 100},
    {18, "truck", 180, 30, 80},      {20, "other-vehicle", 255, 0, 0},    {30, "person", 30, 30, 255},
    {31, "bicyclist", 200, 40, 255}, {40, "road", 255, 0, 255},           {48, "sidewalk", 75, 0, 75},
    {50, "building", 0, 200, 255},   {60, "lane-marking", 170, 255, 150}, {70, "vegetation", 0, 175, 0},
    {71, "trunk", 0, 60, 135},       {72, "terrain", 80, 240, 150},       {80, "pole", 150, 240, 255},
    {81, "traffic-sign", 0, 0, 255}};
// By vista class (citygen/labels.h SemanticClass order).
constexpr uint16_t kVistaToSk[kSemanticClassCount] = {0,  72, 40, 60, 48, 72, 50, 50, 50, 71, 70,
                                                      80, 80, 81, 10, 20, 30, 10, 13, 18, 31};

}  // namespace

uint16_t semanticKittiClass(uint8_t vistaClass) {
    return vistaClass < kSemanticClassCount ? kVistaToSk[vistaClass] : 0;
}

uint16_t semanticKittiInstance(uint32_t id) {
    if (id == 0 || !isObjectKind(instanceKind(id))) return 0;
    return uint16_t((11u * uint64_t(instanceIndex(id)) + uint32_t(instanceKind(id))) % 65535u + 1u);
}

std::string semanticKittiYaml() {
    std::string s =
        "# SemanticKITTI label mapping of a vista rig run: labels/*.label hold these ids (lower 16 bits)\n"
        "# and the instance (upper 16 bits); keys as in the SemanticKITTI API's semantic-kitti.yaml.\n"
        "labels:\n";
    char b[96];
    for (const SkClass& c : kSkClasses) std::snprintf(b, sizeof b, "  %u: \"%s\"\n", unsigned(c.id), c.name), s += b;
    s += "color_map: # bgr\n";
    for (const SkClass& c : kSkClasses)
        std::snprintf(b, sizeof b, "  %u: [%d, %d, %d]\n", unsigned(c.id), c.b, c.g, c.r), s += b;
    s += "vista_to_semantic_kitti:\n";
    for (int i = 0; i < kSemanticClassCount; ++i)
        std::snprintf(b, sizeof b, "  %d: %u\n", i, unsigned(kVistaToSk[i])), s += b;
    s += "vista_classes:\n";
    for (int i = 0; i < kSemanticClassCount; ++i)
        std::snprintf(b, sizeof b, "  %d: \"%s\"\n", i, semanticClassName(SemanticClass(i))), s += b;
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

SensorMount kittiRectifiedMount(const Rig& rig) {
    VISTA_CHECK(!rig.cameras.empty());
    SensorMount m;
    m.position = rig.cameras.front().mount.position;
    m.yawDeg = rig.cameras.front().mount.yawDeg;
    return m;
}

namespace {

// Rows of a 3x4 [R | t] (R given column-major, as glm stores it).
void rowsOf(const glm::dmat3& R, const glm::dvec3& t, double (&out)[12]) {
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) out[i * 4 + j] = R[j][i];
        out[i * 4 + 3] = t[i];
    }
}

// Camera k's P: K [R | t] with [R | t] the rectified frame to camera k's OpenCV frame.
void projection(const RigCamera& c, const glm::dmat3& rectRot, const glm::dvec3& rectPos, double (&P)[12]) {
    const glm::dmat3 rot = mountRotation(c.mount) * cvInBody();
    double Rt[12];
    rowsOf(glm::transpose(rot) * rectRot, glm::transpose(rot) * (rectPos - c.mount.position), Rt);
    const CameraModel& m = c.model;
    const double K[3][3] = {{m.fx, 0, m.cx}, {0, m.fy, m.cy}, {0, 0, 1}};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 4; ++j) {
            double v = 0;
            for (int l = 0; l < 3; ++l) v += K[i][l] * Rt[l * 4 + j];
            P[i * 4 + j] = v;
        }
}

}  // namespace

std::string kittiCalib(const Rig& rig) {
    if (rig.cameras.empty()) return "";
    // Everything in the vehicle frame. Reference camera: camera 0; rectified frame: it, levelled.
    const SensorMount rect = kittiRectifiedMount(rig);
    const glm::dmat3 rectRot = mountRotation(rect) * cvInBody();
    const glm::dmat3 refRot = mountRotation(rig.cameras.front().mount) * cvInBody();
    const glm::dvec3 refPos = rect.position;
    std::string out;
    const size_t nP = std::max<size_t>(4, rig.cameras.size());
    std::string extraP;
    for (size_t k = 0; k < nP; ++k) {
        double P[12] = {};
        if (k < rig.cameras.size()) projection(rig.cameras[k], rectRot, refPos, P);
        (k < 4 ? out : extraP) += line(("P" + std::to_string(k)).c_str(), P);
    }
    {
        const glm::dmat3 R = glm::transpose(rectRot) * refRot;
        std::string r0 = "R0_rect:";
        char b[32];
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) std::snprintf(b, sizeof b, " %.12e", R[j][i]), r0 += b;
        out += r0 + "\n";
    }
    // A LiDAR's frame (the vehicle frame without one) to the reference camera's.
    const auto veloToCam = [&](const glm::dmat3& rot, const glm::dvec3& pos, double(&T)[12]) {
        rowsOf(glm::transpose(refRot) * rot, glm::transpose(refRot) * (pos - refPos), T);
    };
    double T[12], I[12];
    if (rig.lidars.empty()) {
        veloToCam(glm::dmat3(1.0), glm::dvec3(0.0), T);
        rowsOf(glm::dmat3(1.0), glm::dvec3(0.0), I);
    } else {
        const SensorMount& l = rig.lidars.front().mount;
        const glm::dmat3 lr = mountRotation(l);
        veloToCam(lr, l.position, T);
        rowsOf(glm::transpose(lr), -(glm::transpose(lr) * l.position), I);
    }
    out += line("Tr_velo_to_cam", T);
    out += line("Tr_imu_to_velo", I);
    out += extraP;
    for (size_t j = 1; j < rig.lidars.size(); ++j) {
        const SensorMount& l = rig.lidars[j].mount;
        veloToCam(mountRotation(l), l.position, T);
        out += line(("Tr_velo_" + std::to_string(j) + "_to_cam").c_str(), T);
    }
    return out;
}

}  // namespace vista
