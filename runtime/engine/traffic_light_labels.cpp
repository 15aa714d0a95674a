// Traffic-light state labels of one camera frame (traffic_light_labels.h).
#include "runtime/engine/traffic_light_labels.h"

#include "citygen/labels.h"

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

}  // namespace vista
