// vista view (placeholder until its issue lands: reports that it is not available yet).
#include <cstdio>

#include "runtime/commands.h"

namespace vista {

int runView(int argc, char** argv) {
    std::fprintf(stderr, "vista view: not available in this build yet\n");
    return 1;
}

}  // namespace vista
