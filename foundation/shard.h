// Shard: one of N independent parts of a job (paged generation, bake), as
// the command line gives it: "K/N" with 1 <= K <= N <= kMaxShards (K is
// 1-based, like a Slurm array task id from --array=1-N). Pure.
#pragma once
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

}  // namespace vista
