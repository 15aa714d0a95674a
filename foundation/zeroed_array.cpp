// Zero-filled allocations (see zeroed_array.h).
#include "foundation/zeroed_array.h"

#include <cstdint>
#include <cstdlib>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace vista {

namespace {
constexpr size_t kHugePage = size_t(2) << 20;
}  // namespace

// Large blocks are private anonymous mappings (zero pages until written) cut
// to 2 MiB boundaries, with MADV_HUGEPAGE; a block's first byte is then the
// start of the mapping, so freeZeroed can unmap it from its size alone.
void* allocateZeroed(size_t bytes) {
#if defined(__linux__)
    if (bytes >= kHugeBytes) {
        const size_t size = (bytes + kHugePage - 1) / kHugePage * kHugePage;
        void* raw = mmap(nullptr, size + kHugePage, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (raw != MAP_FAILED) {
            const uintptr_t base = reinterpret_cast<uintptr_t>(raw);
            const uintptr_t aligned = (base + kHugePage - 1) / kHugePage * kHugePage;
            if (aligned > base) munmap(raw, aligned - base);
            const uintptr_t tail = aligned + size, end = base + size + kHugePage;
            if (end > tail) munmap(reinterpret_cast<void*>(tail), end - tail);
            void* p = reinterpret_cast<void*>(aligned);
            madvise(p, size, MADV_HUGEPAGE);  // a hint: without it, ordinary pages
            return p;
        }
        return nullptr;  // out of address space or memory
    }
#endif
    return std::calloc(1, bytes);
}

void freeZeroed(void* p, size_t bytes) {
    if (!p) return;
#if defined(__linux__)
    if (bytes >= kHugeBytes) {
        munmap(p, (bytes + kHugePage - 1) / kHugePage * kHugePage);
        return;
    }
#endif
    std::free(p);
}

}  // namespace vista
