// Text forms shared by files and messages. Pure.
#pragma once
#include <cstdint>
#include <string>

namespace vista {

// 16 lowercase hex digits (content hashes in manifests and baked files).
std::string hex64(uint64_t v);
// A double with 17 significant digits: parses back to the same value (keys,
// manifests) and prints short values short ("2000", "0.25").
std::string exactDecimal(double v);

}  // namespace vista
