// ZeroedArray<T>: a fixed-size array whose elements start as all-zero bytes,
// taken from the OS as zero pages on first touch, so that pages never touched
// cost neither time nor memory. For big sparse tables such as the panoramic
// cache (millions of cells, a few thousand touched per frame): a std::vector
// would write every byte. Arrays of kHugeBytes or more are mapped on 2 MiB
// boundaries with transparent huge pages requested (Linux): a region is then
// faulted in by one 2 MiB zero fill instead of 512 page faults, and random
// lookups miss the TLB less; elsewhere, or when that fails, calloc.
//
// Contract: T is trivially copyable and all-zero bytes are a valid T (the
// caller encodes its "empty" value as zero). Allocation failure is a
// contract violation (VISTA_CHECK). Not thread-safe for concurrent writes to
// the same element; distinct elements may be written from distinct threads.
#pragma once
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <type_traits>

#include "foundation/status.h"

namespace vista {

// Zero-filled memory of `bytes` (> 0) bytes, or null when out of memory; free
// it with freeZeroed(p, bytes). Large blocks: huge pages where available.
void* allocateZeroed(size_t bytes);
void freeZeroed(void* p, size_t bytes);
constexpr size_t kHugeBytes = size_t(4) << 20;

template <class T>
class ZeroedArray {
    static_assert(std::is_trivially_copyable_v<T>, "ZeroedArray holds trivially copyable types");

public:
    ZeroedArray() = default;
    explicit ZeroedArray(size_t n) { reset(n); }
    // n elements, all zero bytes (the old contents are released).
    void reset(size_t n) {
        _data.reset();
        _size = 0;
        if (n == 0) return;
        VISTA_CHECK(n <= SIZE_MAX / sizeof(T));
        _data = std::unique_ptr<T, Free>(static_cast<T*>(allocateZeroed(n * sizeof(T))), Free{n * sizeof(T)});
        VISTA_CHECK(_data != nullptr);
        _size = n;
    }
    // Every element back to zero bytes, in place: the pages stay mapped, so
    // no later write pays their first touch (all of them are touched now).
    void zero() {
        if (_size) std::memset(static_cast<void*>(_data.get()), 0, _size * sizeof(T));
    }
    size_t size() const { return _size; }
    T& operator[](size_t i) { return _data.get()[i]; }
    const T& operator[](size_t i) const { return _data.get()[i]; }
    T* begin() { return _data.get(); }
    T* end() { return _data.get() + _size; }
    const T* begin() const { return _data.get(); }
    const T* end() const { return _data.get() + _size; }

private:
    struct Free {
        size_t bytes = 0;
        void operator()(T* p) const { freeZeroed(p, bytes); }
    };
    std::unique_ptr<T, Free> _data;
    size_t _size = 0;
};

}  // namespace vista
