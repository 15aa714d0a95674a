// Stable 64-bit hashing (hash.h).
#include "foundation/hash.h"

#include <cstring>

namespace vista {
namespace {

constexpr uint64_t kK1 = 0x9E3779B185EBCA87ull;
constexpr uint64_t kK2 = 0xC2B2AE3D27D4EB4Full;

inline uint64_t rotl(uint64_t x, int r) { return (x << r) | (x >> (64 - r)); }
inline uint64_t mixWord(uint64_t h, uint64_t w) { return rotl(h ^ (w * kK1), 31) * kK2 + 0x165667B19E3779F9ull; }

}  // namespace

uint64_t loadLE64(const unsigned char* p) {
    uint64_t v = 0;
    for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
    return v;
}

void storeLE64(unsigned char* p, uint64_t v) {
    for (int i = 0; i < 8; ++i) p[i] = (unsigned char)(v >> (8 * i));
}

Hasher64::Hasher64(uint64_t seed) : _h(seed ^ kK2) {}

void Hasher64::update(const unsigned char* p, size_t n) {
    _size += n;
    while (n > 0 && _pending > 0 && _pending < 8) {
        _tail[_pending++] = *p++;
        --n;
    }
    if (_pending == 8) {
        _h = mixWord(_h, loadLE64(_tail));
        _pending = 0;
    }
    while (n >= 8) {
        _h = mixWord(_h, loadLE64(p));
        p += 8;
        n -= 8;
    }
    while (n > 0) {
        _tail[_pending++] = *p++;
        --n;
    }
}

uint64_t Hasher64::finish() const {
    uint64_t h = _h;
    if (_pending) {
        unsigned char t[8] = {0};
        std::memcpy(t, _tail, _pending);
        h = mixWord(h, loadLE64(t));
    }
    h ^= _size;
    h ^= h >> 33;
    h *= 0xFF51AFD7ED558CCDull;
    h ^= h >> 33;
    h *= 0xC4CEB9FE1A85EC53ull;
    h ^= h >> 33;
    return h;
}

uint64_t hashBytes64(const void* data, size_t size, uint64_t seed) {
    Hasher64 h(seed);
    h.update(static_cast<const unsigned char*>(data), size);
    return h.finish();
}

}  // namespace vista
