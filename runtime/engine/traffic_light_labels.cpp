// Traffic-light state labels of one camera frame (traffic_light_labels.h).
#include "runtime/engine/traffic_light_labels.h"

#include <algorithm>
#include <map>

#include "citygen/labels.h"
#include "foundation/status.h"

namespace vista {

std::string trafficLightLabels(const std::vector<FrameBox>& boxes,
                               const std::function<std::string(uint32_t head)>& lampName) {
    std::string text;
    for (const FrameBox& b : boxes) {
        if (instanceKind(b.id) != InstanceKind::TrafficLight || b.pixels == 0) continue;
        const uint32_t head = instanceIndex(b.id);
        text += std::to_string(head) + " " + lampName(head) + " " + std::to_string(b.visibleU0) + " " +
                std::to_string(b.visibleV0) + " " + std::to_string(b.visibleU1) + " " + std::to_string(b.visibleV1) +
                " " + std::to_string(b.pixels) + " " + std::to_string(b.id) + "\n";
    }
    return text;
}

std::vector<FrameBox> trafficLightBoxes(const std::vector<uint32_t>& ids, int width, int height) {
    VISTA_CHECK(width >= 0 && height >= 0 && ids.size() == size_t(width) * size_t(height));
    std::map<uint32_t, FrameBox> found;
    for (int v = 0; v < height; ++v)
        for (int u = 0; u < width; ++u) {
            const uint32_t id = ids[size_t(v) * size_t(width) + size_t(u)];
            if (instanceKind(id) != InstanceKind::TrafficLight) continue;
            auto [it, fresh] = found.try_emplace(id);
            FrameBox& b = it->second;
            if (fresh) {
                b.id = id;
                b.visibleU0 = b.visibleU1 = u;
                b.visibleV0 = b.visibleV1 = v;
            }
            b.visibleU0 = std::min(b.visibleU0, u), b.visibleU1 = std::max(b.visibleU1, u);
            b.visibleV0 = std::min(b.visibleV0, v), b.visibleV1 = std::max(b.visibleV1, v);
            ++b.pixels;
        }
    std::vector<FrameBox> boxes;
    for (auto& [id, b] : found) boxes.push_back(b);
    return boxes;
}

}  // namespace vista
