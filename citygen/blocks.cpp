// STUB
#include "citygen/blocks.h"
namespace vista {
std::vector<Block> extractBlocks(const StreetGraph&, const CityParams&, Progress*) { return {}; }
}
