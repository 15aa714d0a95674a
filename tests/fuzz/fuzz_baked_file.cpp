// libFuzzer target: a baked scene file (vista bake output, read by bench and view).
#include "nodes/baked_file.h"
#include "tests/fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    auto b = vista::loadBakedFile(vista::fuzz::inputFile(".baked.osgb", data, size));
    (void)b;
    return 0;
}
