// libFuzzer target: a scene file (.osgb + integrity trailer) as `vista bench`,
// `view`, `bake` and `path` read it. Damaged files must be refused with a
// Status (the trailer check), never crash. Set VISTA_FUZZ_TRUSTED_TRAILER=1 to
// append a valid trailer to every input (a malformed payload another tool
// could write): that fuzzes the OSG reader itself (see docs/measurements/reliability.md,
// trust model). Seeds: tiny_city.osgb (a file without ground-truth labels, as
// older versions wrote) and tiny_labelled_city.osgb (vista.labels = 1: label
// arrays on every geometry, tree ids per instance; a label array whose size
// does not match is refused like any other malformed geometry).
#include <cstdlib>
#include <string>

#include <osg/Node>
#include <osgDB/WriteFile>

#include "runtime/scene/city_file.h"
#include "runtime/scene/scene_file.h"
#include "tests/fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const bool trusted = std::getenv("VISTA_FUZZ_TRUSTED_TRAILER") != nullptr;
    std::string bytes(reinterpret_cast<const char*>(data), size);
    if (trusted) {
        bytes += vista::sceneFileTrailer(bytes);
    } else if (size >= 32 && bytes.compare(size - 32, 32, vista::sceneFileTrailer(bytes.substr(0, size - 32))) == 0) {
        // libFuzzer's comparison tracing forges the 64-bit trailer hash (an
        // integrity check, not an authentication): such an input is a
        // "malformed payload with a valid trailer", the trusted-trailer
        // mode's subject (trust model, docs/measurements/reliability.md), not this target's.
        return 0;
    }
    const std::string path =
        vista::fuzz::inputFile(".osgb", reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
    auto m = vista::loadCityFile(path);
    (void)m;
    return 0;
}
