// The process's resident set size now (Linux /proc/self/statm), for what
// measures or bounds its own memory: a streamed city held under a memory
// budget, the commands' memory phases. 0 where it cannot be read.
#pragma once
#include <cstdint>

namespace vista {

uint64_t residentSetBytes();
// Hands the heap's free pages back to the system (glibc malloc_trim; nothing
// elsewhere), so that the resident set is what is in use. Walks the whole
// heap: milliseconds on a heap of gigabytes.
void releaseFreeMemory();

}  // namespace vista
