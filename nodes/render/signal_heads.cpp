// Traffic-light heads and their lamp overlays (signal_heads.h).
#include "nodes/render/signal_heads.h"

#include <cmath>

#include "citygen/blocks.h"
#include "citygen/lanes.h"
#include "citygen/terrain.h"
#include "citygen/traffic_signals.h"
#include "foundation/units.h"

namespace vista {
namespace {

// The static lamps' layout (citygen/traffic_signals.cpp): octagons of
// inradius 0.1 m on the housing's front, 5 mm proud of it.
constexpr double kStaticLampProud = 0.005;
constexpr double kOverlayInradius = 0.105;  // covers the static lamp's rim

double lampFront() { return 0.5 * kSignalPoleWidth + kTrafficLightDepth + kStaticLampProud + kLampOverlayProud; }

// Centre height of lamp k (0 red at the top, 1 amber, 2 green).
double lampHeight(int k) { return kTrafficLightBottom + kTrafficLightHeight - (k + 0.5) * (kTrafficLightHeight / 3.0); }

bool lit(LampState s, int k) {
    switch (s) {
        case LampState::Red: return k == 0;
        case LampState::RedAmber: return k == 0 || k == 1;
        case LampState::Amber: return k == 1;
        case LampState::Green: return k == 2;
        case LampState::Off: return false;
    }
    return false;
}

// Bright (lit) and dark colours of the red, amber and green lamps.
constexpr glm::u8vec4 kLit[3] = {{255, 40, 30, 255}, {255, 176, 0, 255}, {40, 255, 130, 255}};
constexpr glm::u8vec4 kDark[3] = {{46, 9, 9, 255}, {50, 34, 6, 255}, {8, 42, 22, 255}};

}  // namespace

std::vector<SignalHead> signalHeads(const StreetGraph& streets, const CityParams& params) {
    std::vector<SignalHead> out;
    if (streets.edges.empty()) return out;
    const std::vector<Block> blocks = extractBlocks(streets, params, nullptr);
    const LaneModel lanes = buildLaneModel(streets, params, &blocks);
    const glm::dvec2 origin(params.origin_x, params.origin_y);
    for (size_t i = 0; i < lanes.signals.size(); ++i) {
        const SignalPlacement& s = lanes.signals[i];
        if (s.kind != SignalPlacement::Kind::TrafficLight) continue;
        const double len = glm::length(s.facing);
        if (!std::isfinite(s.position.x) || !std::isfinite(s.position.y) || !std::isfinite(len) || !(len > 1e-9))
            continue;
        const glm::dvec2 w = s.facing / len;
        SignalHead h;
        h.signal = uint32_t(i);
        h.frame[0] = glm::dvec4(-w.y, w.x, 0.0, 0.0);  // right of the traffic looking at the head
        h.frame[1] = glm::dvec4(0.0, 0.0, 1.0, 0.0);
        h.frame[2] = glm::dvec4(w, 0.0, 0.0);
        h.frame[3] = glm::dvec4(s.position + origin, terrainHeight(params, s.position), 1.0);
        out.push_back(h);
    }
    return out;
}

glm::dvec3 lampOverlayCentre() { return glm::dvec3(0.0, lampHeight(1), lampFront()); }

Mesh lampOverlay(LampState state) {
    Mesh m;
    const double z = lampFront();
    const double R = kOverlayInradius / std::cos(kPi / 8);
    for (int k = 0; k < 3; ++k) {
        const glm::u8vec4 c = lit(state, k) ? kLit[k] : kDark[k];
        const uint32_t first = uint32_t(m.positions.size());
        const double cy = lampHeight(k);
        m.positions.push_back(glm::vec3(0.0f, float(cy), float(z)));
        for (int j = 0; j < 8; ++j) {
            const double a = kPi / 8 + 2 * kPi * j / 8;
            m.positions.push_back(glm::vec3(float(R * std::cos(a)), float(cy + R * std::sin(a)), float(z)));
        }
        for (int j = 0; j < 9; ++j) {
            m.normals.push_back(glm::vec3(0, 0, 1));
            m.colors.push_back(c);
        }
        // Counter-clockwise seen from +z (x right, y up): front faces toward the traffic.
        for (uint32_t j = 0; j < 8; ++j) {
            m.indices.push_back(first);
            m.indices.push_back(first + 1 + j);
            m.indices.push_back(first + 1 + (j + 1) % 8);
        }
    }
    return m;
}

}  // namespace vista
