// STUB
#include "citygen/surfaces.h"
namespace vista {
void meshSurfaces(const City&, const TileGrid&, int, const Lighting&, Tile&) {}
}
