// Shared by the libFuzzer targets: the input as a file (for readers that take
// a path), unique per process (in $TMPDIR, else /tmp), rewritten for every
// input and removed when the process exits normally (libFuzzer's time and
// run limits end with exit()); a crashed run leaves it as evidence.
#pragma once
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <unistd.h>

namespace vista::fuzz {

inline std::string inputFile(const char* suffix, const uint8_t* data, size_t size) {
    struct Owned {
        std::string path;
        ~Owned() { std::remove(path.c_str()); }
    };
    static const Owned file{[&] {
        const char* tmp = std::getenv("TMPDIR");
        return std::string(tmp && *tmp ? tmp : "/tmp") + "/vista_fuzz_" + std::to_string(::getpid()) + suffix;
    }()};
    FILE* f = std::fopen(file.path.c_str(), "wb");
    if (!f) return file.path;
    if (size) std::fwrite(data, 1, size, f);
    std::fclose(f);
    return file.path;
}

}  // namespace vista::fuzz
