// STUB
#include "citygen/trees.h"
namespace vista {
std::vector<TreePrototype> makeTreePrototypes(const CityParams&, const Lighting&) { return {}; }
std::vector<TreeInstance> placeTrees(const City&, Progress*) { return {}; }
}
