// Shared by the libFuzzer targets: the input as a file (for readers that take
// a path), unique per process, rewritten for every input.
#pragma once
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include <unistd.h>

namespace vista::fuzz {

inline std::string inputFile(const char* suffix, const uint8_t* data, size_t size) {
    static const std::string path = "/tmp/vista_fuzz_" + std::to_string(::getpid()) + suffix;
    FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) return path;
    if (size) std::fwrite(data, 1, size, f);
    std::fclose(f);
    return path;
}

}  // namespace vista::fuzz
