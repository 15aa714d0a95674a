// libFuzzer target: a walkthrough path CSV (vista bench/view --path).
// Accepted paths have finite samples within the documented ranges.
#include <cmath>
#include <cstdlib>

#include "runtime/scene/paths.h"
#include "tests/fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    auto p = vista::loadPathCsv(vista::fuzz::inputFile(".csv", data, size));
    if (p) {
        for (const auto& s : p->samples)
            if (!std::isfinite(s.t + s.position.x + s.position.y + s.position.z + s.heading + s.pitch) ||
                std::abs(s.position.x) > 2e7 || std::abs(s.pitch) >= 1.5708)
                std::abort();
    }
    return 0;
}
