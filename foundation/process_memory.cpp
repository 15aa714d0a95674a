// Resident set size from /proc/self/statm (process_memory.h).
#include "foundation/process_memory.h"

#include <cstdio>

#include <unistd.h>

#ifdef __GLIBC__
#include <malloc.h>
#endif

namespace vista {

uint64_t residentSetBytes() {
    std::FILE* f = std::fopen("/proc/self/statm", "r");
    if (!f) return 0;
    unsigned long long pages = 0, resident = 0;
    const int n = std::fscanf(f, "%llu %llu", &pages, &resident);
    std::fclose(f);
    const long page = sysconf(_SC_PAGESIZE);
    return n == 2 && page > 0 ? uint64_t(resident) * uint64_t(page) : 0;
}

void releaseFreeMemory() {
#ifdef __GLIBC__
    malloc_trim(0);
#endif
}

}  // namespace vista
