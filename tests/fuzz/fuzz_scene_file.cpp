// libFuzzer target: a scene file (.osgb + integrity trailer) as `vista bench`,
// `view`, `bake` and `path` read it. Damaged files must be refused with a
// Status (the trailer check), never crash. Set VISTA_FUZZ_TRUSTED_TRAILER=1 to
// append a valid trailer to every input (a malformed payload another tool
// could write): that fuzzes the OSG reader itself (see docs/reliability.md,
// trust model).
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
    if (trusted) bytes += vista::sceneFileTrailer(bytes);
    const std::string path =
        vista::fuzz::inputFile(".osgb", reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
    auto m = vista::loadCityFile(path);
    (void)m;
    return 0;
}
