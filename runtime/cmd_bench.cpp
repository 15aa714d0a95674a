// vista bench (placeholder until its issue lands: reports that it is not available yet).
#include <cstdio>

#include "runtime/commands.h"

namespace vista {

int runBench(int argc, char** argv) {
    std::fprintf(stderr, "vista bench: not available in this build yet\n");
    return 1;
}

}  // namespace vista
