// libFuzzer target: the street graph JSON stored in every scene file.
#include <cstdlib>
#include <string>

#include "citygen/street_graph.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    auto g = vista::streetGraphFromJson(text);
    if (g) {
        auto back = vista::streetGraphFromJson(vista::streetGraphToJson(*g));
        if (!back) std::abort();
    }
    return 0;
}
