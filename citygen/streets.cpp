// STUB: replaced by the streets work.
#include "citygen/streets.h"
namespace vista {
StreetGraph growStreets(const CityParams&, Progress*) { return {}; }
}
