// libFuzzer target: one cell result of the bake's work directory (resume reads
// them back). Damaged records are errors, never crashes; accepted ones
// re-encode to the same bytes.
#include <cstdlib>
#include <string>

#include "bake/cell_result.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    constexpr uint64_t kConfig = 0x5EED5EED5EED5EEDull;
    const std::string bytes(reinterpret_cast<const char*>(data), size);
    auto r = vista::decodeCellResult(bytes, kConfig, "fuzz");
    if (r && vista::encodeCellResult(*r, kConfig) != bytes) std::abort();
    return 0;
}
