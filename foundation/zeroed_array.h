// ZeroedArray<T>: a fixed-size array whose elements start as all-zero bytes,
// allocated with calloc so that pages never touched cost neither time nor
// memory (large allocations come from the OS as zero pages on first touch).
// For big sparse tables such as the panoramic cache (millions of cells, a
// few thousand touched per frame): a std::vector would write every byte.
//
// Contract: T is trivially copyable and all-zero bytes are a valid T (the
// caller encodes its "empty" value as zero). Allocation failure is a
// contract violation (VISTA_CHECK). Not thread-safe for concurrent writes to
// the same element; distinct elements may be written from distinct threads.
#pragma once
#include <cstddef>
#include <cstdlib>
#include <memory>
#include <type_traits>

#include "foundation/status.h"

namespace vista {

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
        _data.reset(static_cast<T*>(std::calloc(n, sizeof(T))));
        VISTA_CHECK(_data != nullptr);
        _size = n;
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
        void operator()(T* p) const { std::free(p); }
    };
    std::unique_ptr<T, Free> _data;
    size_t _size = 0;
};

}  // namespace vista
