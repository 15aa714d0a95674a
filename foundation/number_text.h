// Numbers as users write them: one set of rules for every number vista reads
// from a person (command-line values, JSON files, CSV files).
//
// Contract: parseUnsignedText() and parseSignedText() take decimal integers
// only: an optional '-' (signed; for unsigned a '-' is reported as out of
// range), then digits; no spaces, '+', fraction, exponent or hex. A value
// outside [min, max] is refused, never wrapped or saturated. parseRealText()
// takes decimal reals ("12", "-0.5", "1e3"); hex, "inf" and "nan" are
// refused, as is a value outside [min, max]. The whole text must be the
// number. Every error names `what` (the option or field), the text as
// written (cut by echoText) and the allowed range. Pure; thread-safe.
//
// echoText(): user text for a message, cut to kMaxEchoChars characters with
// "…" appended, so a megabyte key does not flood stderr.
// shortNumber(): a double for a message, at most 17 significant digits in
// the shortest of %g-style forms ("1e+308", never 309 digits).
#pragma once
#include <cstdint>
#include <string>

#include "foundation/status.h"

namespace vista {

constexpr size_t kMaxEchoChars = 80;

std::string echoText(const std::string& text);
std::string shortNumber(double v);

Result<uint64_t> parseUnsignedText(const std::string& what, const std::string& text, uint64_t min, uint64_t max);
Result<int64_t> parseSignedText(const std::string& what, const std::string& text, int64_t min, int64_t max);
Result<double> parseRealText(const std::string& what, const std::string& text, double min, double max);

}  // namespace vista
