// STUB
#include "runtime/city_file.h"
namespace vista {
Status writeGltf(const City&, const std::string& path) { return Status::error("not implemented: " + path); }
}
