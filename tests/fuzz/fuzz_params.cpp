// libFuzzer target: the parameter file (JSON, with its effects object).
// Contract under test: parseParamsJson returns a value or a Status, never
// crashes, throws or recurses without bound; accepted parameters validate and
// survive their own canonical JSON.
#include <cstdlib>
#include <string>

#include "citygen/params.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    auto r = vista::parseParamsJson(text, "fuzz.json");
    if (r) {
        if (!vista::validateParams(*r)) std::abort();
        auto back = vista::parseParamsJson(vista::paramsToJson(*r), "round trip");
        if (!back || vista::paramsToJson(*back) != vista::paramsToJson(*r)) std::abort();
    }
    return 0;
}
