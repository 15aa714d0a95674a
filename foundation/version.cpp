#include "foundation/version.h"

// VISTA_VERSION_TEXT comes from foundation/CMakeLists.txt (PROJECT_VERSION), for this file only,
// so that a new version recompiles one file.
#ifndef VISTA_VERSION_TEXT
#error "VISTA_VERSION_TEXT must be defined by the build (PROJECT_VERSION)"
#endif

namespace vista {

const char* version() { return VISTA_VERSION_TEXT; }

}  // namespace vista
