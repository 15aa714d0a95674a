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
// `s` as one POSIX shell word, for commands printed to be pasted: unchanged
// when every character is safe (letters, digits, `_-./:=,+@%`), otherwise in
// single quotes (each ' written as '\''); "" gives ''.
std::string shellWord(const std::string& s);

}  // namespace vista
