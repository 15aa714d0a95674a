// Shard "K/N" parsing (see shard.h).
#include "foundation/shard.h"

#include <cstdint>

#include "foundation/number_text.h"

namespace vista {

Result<Shard> parseShard(const std::string& option, const std::string& text) {
    auto bad = [&](const std::string& why) {
        return Status::error("option " + option + " = '" + echoText(text) + "': " + why +
                             " (expected K/N with 1 <= K <= N <= " + std::to_string(kMaxShards) + ")");
    };
    const size_t slash = text.find('/');
    if (slash == std::string::npos) return bad("no '/'");
    auto n = parseUnsignedText("N", text.substr(slash + 1), 1, kMaxShards);
    if (!n) return bad(n.status().message());
    auto k = parseUnsignedText("K", text.substr(0, slash), 1, *n);
    if (!k) return bad(k.status().message());
    return Shard{int(*k) - 1, int(*n)};
}

std::string shardText(const Shard& shard) { return std::to_string(shard.k()) + "/" + std::to_string(shard.count); }

ShardRange shardRange(size_t total, const Shard& shard) {
    const auto at = [&](int i) { return size_t(uint64_t(total) * uint64_t(i) / uint64_t(shard.count)); };
    return {at(shard.index), at(shard.index + 1)};
}

}  // namespace vista
