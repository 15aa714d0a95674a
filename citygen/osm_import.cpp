// STUB
#include "citygen/streets.h"
namespace vista {
Result<StreetGraph> importOsm(const std::string& path, const CityParams&) { return Status::error("OSM import not built yet: " + path); }
}
