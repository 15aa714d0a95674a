// libFuzzer target: a ray-set file (bench_raw_rays reads `vista bench
// --dump-rays` output). Damaged files are errors, never crashes; accepted
// ones re-encode to the same bytes.
#include <cstdlib>
#include <string>

#include "runtime/engine/ray_set.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string bytes(reinterpret_cast<const char*>(data), size);
    auto r = vista::decodeRaySet(bytes, "fuzz");
    if (r && vista::encodeRaySet(*r) != bytes) std::abort();
    return 0;
}
