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

std::string shellWord(const std::string& s) {
    bool safe = !s.empty();
    for (char c : s) {
        const bool alnum = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
        if (!alnum && std::string("_-./:=,+@%").find(c) == std::string::npos) safe = false;
    }
    if (safe) return s;
    std::string q = "'";
    for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

}  // namespace vista
