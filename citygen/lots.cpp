// STUB
#include "citygen/blocks.h"
namespace vista {
std::vector<Lot> subdivideLots(const std::vector<Block>&, const CityParams&, Progress*) { return {}; }
}
