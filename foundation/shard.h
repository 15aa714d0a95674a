// Shard: one of N independent parts of a job (paged generation, bake,
// render), as the command line gives it: "K/N" with 1 <= K <= N <= kMaxShards
// (K is 1-based, like a Slurm array task id from --array=1-N). Pure.
#pragma once
#include <cstddef>
#include <string>

#include "foundation/status.h"

namespace vista {

constexpr int kMaxShards = 100000;

struct Shard {
    int index = 0;  // 0-based: K - 1
    int count = 1;  // N
    int k() const { return index + 1; }
};

// Parses "K/N", K and N by number_text.h (decimal, never wrapped); a bad
// value is an error naming `option`, the value and the allowed range
// ("expected K/N with 1 <= K <= N <= 100000").
Result<Shard> parseShard(const std::string& option, const std::string& text);

// "K/N" of a shard (the text parseShard reads).
std::string shardText(const Shard& shard);

// A shard's contiguous share [begin, end) of `total` items (frames, drives):
// begin = floor(total * index / count), end = floor(total * (index + 1) / count).
// The N shares tile [0, total) in order; their sizes differ by at most one;
// a share is empty when total < count. Exact for total < 2^44.
struct ShardRange {
    size_t begin = 0, end = 0;
    size_t size() const { return end - begin; }
    bool contains(size_t i) const { return i >= begin && i < end; }
};
ShardRange shardRange(size_t total, const Shard& shard);

}  // namespace vista
