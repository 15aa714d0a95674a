// libFuzzer target: the sensor-rig file of `vista render --rig` (JSON).
// Contract under test: parseRigJson returns a rig or a Status, never crashes,
// throws or recurses without bound; an accepted rig has at least one sensor,
// every camera at least one channel, a valid image size and focal lengths
// within the field-of-view limit (minFocalLength), every LiDAR a
// sweep within kMaxLidarRays, and it survives its own canonical JSON.
#include <cstdlib>
#include <string>

#include "runtime/engine/rig.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    auto r = vista::parseRigJson(text, "fuzz.json");
    if (!r) return 0;
    if (r->cameras.empty() && r->lidars.empty()) std::abort();
    if (r->order.size() != r->cameras.size() + r->lidars.size()) std::abort();
    for (const auto& c : r->cameras)
        if (c.channels == 0 || c.model.width < 1 || c.model.height < 1 ||
            !(c.model.fx >= vista::minFocalLength(c.model, true)) ||
            !(c.model.fy >= vista::minFocalLength(c.model, false)))
            std::abort();
    for (const auto& l : r->lidars)
        if (l.spec.elevationDeg.empty() || l.spec.elevationDeg.size() * size_t(l.spec.columns) > vista::kMaxLidarRays)
            std::abort();
    const std::string canonical = vista::rigToJson(*r);
    auto back = vista::parseRigJson(canonical, "round trip");
    if (!back || vista::rigToJson(*back) != canonical) std::abort();
    return 0;
}
