// Stable 64-bit hashing: splitmix64 mixing, key hashing for random streams and
// cache keys, and a streaming byte hash for file integrity trailers.
//
// Contract: results depend only on the input bytes/keys and the seed: the same
// on every platform, compiler and run (little-endian byte order is explicit).
// Not cryptographic. Pure functions; Hasher64 is not thread-safe per instance.
#pragma once
#include <cstddef>
#include <cstdint>

namespace vista {

inline uint64_t splitmix64(uint64_t x) {
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

// Stable hash of several keys (order matters).
inline uint64_t hashKeys(uint64_t a, uint64_t b, uint64_t c = 0) {
    return splitmix64(splitmix64(splitmix64(a) ^ b) ^ c);
}

// Little-endian 64-bit load/store (file formats).
uint64_t loadLE64(const unsigned char* p);
void storeLE64(unsigned char* p, uint64_t v);

// Streaming byte hash: update() any number of times; finish() gives the same
// value as hashBytes64 over the concatenated input, for any split.
class Hasher64 {
public:
    explicit Hasher64(uint64_t seed = 0);
    void update(const unsigned char* p, size_t n);
    uint64_t finish() const;

private:
    uint64_t _h;
    uint64_t _size = 0;
    unsigned char _tail[8] = {0};
    size_t _pending = 0;
};

// 64-bit hash of a byte range (the scene-file trailer's checksum).
uint64_t hashBytes64(const void* data, size_t size, uint64_t seed = 0);

}  // namespace vista
