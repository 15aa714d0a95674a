// loadNpy<T>(): the payload of a version-1 .npy file (the header's length in
// bytes 8-9, the data after it) as T values, without reading the header's
// dtype or shape: for tests that know what the writer wrote. Empty when the
// file is missing or shorter than a header.
#pragma once
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "tests/common/temp_dir.h"

namespace vista::test {

template <class T>
std::vector<T> loadNpy(const std::string& path) {
    const std::string b = readBytes(path);
    if (b.size() < 10) return {};
    const size_t hl = uint8_t(b[8]) | size_t(uint8_t(b[9])) << 8;
    if (b.size() < 10 + hl) return {};
    std::vector<T> v((b.size() - 10 - hl) / sizeof(T));
    std::memcpy(v.data(), b.data() + 10 + hl, v.size() * sizeof(T));
    return v;
}

}  // namespace vista::test
