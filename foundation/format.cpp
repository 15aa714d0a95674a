// Shared text forms (see format.h).
#include "foundation/format.h"

#include <cinttypes>
#include <cstdio>
#include <sstream>

namespace vista {

std::string hex64(uint64_t v) {
    char b[17];
    std::snprintf(b, sizeof b, "%016" PRIx64, v);
    return b;
}

std::string exactDecimal(double v) {
    std::ostringstream s;
    s.precision(17);
    s << v;
    return s.str();
}

}  // namespace vista
