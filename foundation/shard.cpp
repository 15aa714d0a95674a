// Shard "K/N" parsing (see shard.h).
#include "foundation/shard.h"

namespace vista {

Result<Shard> parseShard(const std::string& option, const std::string& text) {
    auto bad = [&](const std::string& why) {
        return Status::error("option " + option + " = '" + text + "': " + why +
                             " (expected K/N with 1 <= K <= N <= " + std::to_string(kMaxShards) + ")");
    };
    const size_t slash = text.find('/');
    if (slash == std::string::npos) return bad("no '/'");
    auto num = [](const std::string& s, long& v) {
        if (s.empty() || s.size() > 9 || s.find_first_not_of("0123456789") != std::string::npos) return false;
        v = std::stol(s);
        return true;
    };
    long k = 0, n = 0;
    if (!num(text.substr(0, slash), k) || !num(text.substr(slash + 1), n)) return bad("K and N must be whole numbers");
    if (n < 1 || n > kMaxShards) return bad("N out of range");
    if (k < 1 || k > n) return bad("K out of range");
    return Shard{int(k - 1), int(n)};
}

Result<int> parseShardCount(const std::string& option, const std::string& text) {
    if (text.empty() || text.size() > 9 || text.find_first_not_of("0123456789") != std::string::npos ||
        std::stol(text) < 1 || std::stol(text) > kMaxShards)
        return Status::error("option " + option + " = '" + text +
                             "': expected a whole number N with 1 <= N <= " + std::to_string(kMaxShards));
    return int(std::stol(text));
}

}  // namespace vista
