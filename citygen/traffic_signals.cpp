// Meshes of the lane model's signals (traffic_signals.h).
#include "citygen/traffic_signals.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "citygen/mesh_builder.h"
#include "citygen/terrain.h"
#include "foundation/units.h"

namespace vista {
namespace {

// Albedos (linear RGB) of the parts.
constexpr glm::dvec3 kPoleGrey{0.28, 0.29, 0.30};
constexpr glm::dvec3 kHousing{0.05, 0.06, 0.05};
constexpr glm::dvec3 kRed{0.60, 0.03, 0.03}, kAmber{0.80, 0.42, 0.02}, kGreen{0.03, 0.55, 0.25};
constexpr glm::dvec3 kSignRed{0.55, 0.03, 0.03}, kSignWhite{0.80, 0.80, 0.78}, kSignBack{0.45, 0.46, 0.47};
constexpr double kFaceProud = 0.005;   // lamp and sign faces stand this far in front of what carries them
constexpr double kStopBorder = 0.035;  // white rim of the stop sign (each side)
constexpr double kYieldBorder = 0.09;  // red rim of the yield sign (inradius difference)

// The signal's frame: u to the right of the traffic looking at it, v up, w
// toward the traffic (SignalPlacement::facing), origin at the pole base.
struct Frame {
    glm::dvec3 base, u, w;
    glm::dvec3 at(double pu, double pv, double pw) const { return base + u * pu + glm::dvec3(0, 0, pv) + w * pw; }
};

// A planar face, wound so that its normal points along `out`.
void face(MeshBuilder& b, std::vector<glm::dvec3> p, const glm::dvec3& out) {
    glm::dvec3 n(0.0);
    for (size_t i = 1; i + 1 < p.size(); ++i) n += glm::cross(p[i] - p[0], p[i + 1] - p[0]);
    if (glm::dot(n, out) < 0) std::reverse(p.begin(), p.end());
    for (size_t i = 1; i + 1 < p.size(); ++i) b.triangle(p[0], p[i], p[i + 1]);  // convex faces: a fan
}

// A convex outline (u, v) extruded along w over [w0, w1]: front (normal w),
// back (normal -w, when withBack) and sides.
void slab(MeshBuilder& b, const Frame& f, const std::vector<glm::dvec2>& outline, double w0, double w1, bool withBack) {
    std::vector<glm::dvec3> front, back;
    for (const auto& q : outline) {
        front.push_back(f.at(q.x, q.y, w1));
        back.push_back(f.at(q.x, q.y, w0));
    }
    face(b, front, f.w);
    if (withBack) face(b, back, -f.w);
    glm::dvec2 c(0.0);
    for (const auto& q : outline) c += q;
    c /= double(outline.size());
    for (size_t i = 0; i < outline.size(); ++i) {
        const size_t j = (i + 1) % outline.size();
        const glm::dvec2 m = 0.5 * (outline[i] + outline[j]) - c;
        face(b, {back[i], back[j], front[j], front[i]}, f.u * m.x + glm::dvec3(0, 0, m.y));
    }
}

std::vector<glm::dvec2> rect(double u0, double v0, double u1, double v1) {
    return {{u0, v0}, {u1, v0}, {u1, v1}, {u0, v1}};
}

// Regular polygon of `n` sides with inradius r around (0, cv), counter-clockwise, its
// first vertex at angle `phase` (octagon: pi/8 puts a flat side at the bottom; triangle:
// -pi/2 its point).
std::vector<glm::dvec2> regular(int n, double r, double cv, double phase) {
    std::vector<glm::dvec2> p;
    const double R = r / std::cos(kPi / n);
    for (int k = 0; k < n; ++k) {
        const double a = phase + 2 * kPi * k / n;
        p.emplace_back(R * std::cos(a), cv + R * std::sin(a));
    }
    return p;
}

}  // namespace

Material signalMaterial(SignalPlacement::Kind kind) {
    return kind == SignalPlacement::Kind::TrafficLight ? Material::TrafficLight : Material::TrafficSign;
}

InstanceKind signalInstanceKind(SignalPlacement::Kind kind) {
    return kind == SignalPlacement::Kind::TrafficLight ? InstanceKind::TrafficLight : InstanceKind::TrafficSign;
}

void meshSignal(const SignalPlacement& s, const CityParams& params, const glm::dvec3& origin, const Lighting& light,
                Mesh& mesh, uint32_t id) {
    const double len = glm::length(s.facing);
    if (!std::isfinite(s.position.x) || !std::isfinite(s.position.y) || !std::isfinite(len) || !(len > 1e-9)) return;
    const glm::dvec2 w2 = s.facing / len;
    Frame f;
    f.base = glm::dvec3(s.position, terrainHeight(params, s.position));
    f.w = glm::dvec3(w2, 0.0);
    f.u = glm::dvec3(-w2.y, w2.x, 0.0);  // (-w) x z: the right hand of traffic looking along -w
    MeshBuilder b(mesh, origin, signalMaterial(s.kind), light);
    b.setId(id);
    const double r = 0.5 * kSignalPoleWidth;
    const bool lightHead = s.kind == SignalPlacement::Kind::TrafficLight;
    const double top =
        lightHead
            ? kTrafficLightBottom + kTrafficLightHeight
            : kSignBottom + (s.kind == SignalPlacement::Kind::Stop ? kSignSize : 0.5 * std::sqrt(3.0) * kSignSize);
    b.setAlbedo(kPoleGrey);
    std::vector<glm::dvec2> pole;
    for (const glm::dvec2 q : {glm::dvec2(-r, -r), glm::dvec2(r, -r), glm::dvec2(r, r), glm::dvec2(-r, r)})
        pole.push_back(glm::dvec2(f.base) + glm::dvec2(f.u) * q.x + w2 * q.y);
    b.prism(pole, f.base.z, f.base.z + top, true);

    if (lightHead) {
        const double hw = 0.5 * kTrafficLightWidth, v0 = kTrafficLightBottom, v1 = v0 + kTrafficLightHeight;
        const double front = r + kTrafficLightDepth;
        b.setAlbedo(kHousing);
        slab(b, f, rect(-hw, v0, hw, v1), r, front, true);
        // Lamps: squares 0.2 m wide on 0.3 m centres, red at the top.
        const glm::dvec3 colours[3] = {kRed, kAmber, kGreen};
        for (int k = 0; k < 3; ++k) {
            const double cv = v1 - (k + 0.5) * (kTrafficLightHeight / 3.0);
            b.setAlbedo(colours[k]);
            std::vector<glm::dvec3> lamp;
            for (const auto& q : regular(8, 0.1, cv, kPi / 8)) lamp.push_back(f.at(q.x, q.y, front + kFaceProud));
            face(b, lamp, f.w);
        }
        return;
    }
    const double back = r, plate = r + kSignThickness;
    if (s.kind == SignalPlacement::Kind::Stop) {
        const double half = 0.5 * kSignSize, cv = kSignBottom + half;
        b.setAlbedo(kSignWhite);
        slab(b, f, regular(8, half, cv, kPi / 8), back, plate, false);
        b.setAlbedo(kSignBack);
        std::vector<glm::dvec3> rear;
        for (const auto& q : regular(8, half, cv, kPi / 8)) rear.push_back(f.at(q.x, q.y, back));
        face(b, rear, -f.w);
        b.setAlbedo(kSignRed);
        std::vector<glm::dvec3> red;
        for (const auto& q : regular(8, half - kStopBorder, cv, kPi / 8))
            red.push_back(f.at(q.x, q.y, plate + kFaceProud));
        face(b, red, f.w);
        return;
    }
    // Yield: point down, top edge horizontal at the top.
    const double inradius = kSignSize / (2.0 * std::sqrt(3.0)), cv = top - inradius;
    const auto triangle = [&](double ri) { return regular(3, ri, cv, -kHalfPi); };
    b.setAlbedo(kSignRed);
    slab(b, f, triangle(inradius), back, plate, false);
    b.setAlbedo(kSignBack);
    std::vector<glm::dvec3> rear;
    for (const auto& q : triangle(inradius)) rear.push_back(f.at(q.x, q.y, back));
    face(b, rear, -f.w);
    b.setAlbedo(kSignWhite);
    std::vector<glm::dvec3> white;
    for (const auto& q : triangle(inradius - kYieldBorder)) white.push_back(f.at(q.x, q.y, plate + kFaceProud));
    face(b, white, f.w);
}

}  // namespace vista
