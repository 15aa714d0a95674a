#include "runtime/scene/city_opendrive.h"

#include <vector>

#include "citygen/blocks.h"

namespace vista {

Result<std::string> cityOpenDrive(const SceneModel& city, const std::string& cityFile, OpenDriveCounts* counts) {
    if (city.streets.edges.empty())
        return Status::error("scene file '" + cityFile + "' has no street graph (no roads to write)");
    const std::vector<Block> blocks = extractBlocks(city.streets, city.params, nullptr);
    auto text = openDriveXml(city.streets, city.params, &blocks, counts);
    if (!text) return Status::error("scene file '" + cityFile + "': " + text.status().message());
    return text;
}

}  // namespace vista
