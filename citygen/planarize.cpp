// STUB
#include "citygen/streets.h"
namespace vista {
StreetGraph planarize(const std::vector<RawSegment>&, double, double) { return {}; }
}
