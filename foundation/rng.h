// Deterministic random streams keyed by (seed, entity id, stream).
//
// Contract: the sequence depends only on the three keys, never on thread
// count, call order elsewhere or the platform's <random> implementation
// (no std:: distributions are used). Cheap to construct: make one per entity.
// Not thread-safe per instance; use one instance per thread/entity.
#pragma once
#include <cmath>
#include <cstdint>

#include "foundation/hash.h"
#include "foundation/units.h"

namespace vista {

// Well-known stream ids, so different subsystems never share a stream.
enum class Stream : uint64_t {
    Streets = 1,
    Blocks = 2,
    Lots = 3,
    Buildings = 4,
    Trees = 5,
    Terrain = 6,
    Facades = 7,
    Paths = 8,
    Bake = 9,
    Cars = 10,
};

class Rng {
public:
    Rng(uint64_t seed, uint64_t entity, Stream stream) : Rng(seed, entity, uint64_t(stream)) {}
    Rng(uint64_t seed, uint64_t entity, uint64_t stream) : _state(hashKeys(seed, entity, stream) | 1ull) {}

    uint64_t next() {  // xorshift64* on a splitmix-seeded state
        _state ^= _state >> 12;
        _state ^= _state << 25;
        _state ^= _state >> 27;
        return _state * 0x2545F4914F6CDD1Dull;
    }
    // Uniform in [0, 1).
    double uniform() { return double(next() >> 11) * (1.0 / 9007199254740992.0); }
    // Uniform in [lo, hi).
    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
    // Uniform integer in [lo, hi] (inclusive).
    int64_t range(int64_t lo, int64_t hi) { return lo + int64_t(next() % uint64_t(hi - lo + 1)); }
    bool chance(double p) { return uniform() < p; }
    // Standard normal (Box-Muller; deterministic, uses two uniforms).
    double normal() {
        double u1 = uniform(), u2 = uniform();
        if (u1 < 1e-300) u1 = 1e-300;
        return std::sqrt(-2.0 * std::log(u1)) * std::cos(kTwoPi * u2);
    }

private:
    uint64_t _state;
};

}  // namespace vista
