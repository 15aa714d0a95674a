// Numbers as users write them: one set of rules for every number vista reads
// from a person (command-line values, JSON files, CSV files).
//
// Contract: parseUnsignedText() and parseSignedText() take decimal integers
// only: an optional '-' (signed; for unsigned a '-' is reported as out of
// range), then digits; no spaces, '+', fraction, exponent or hex. A value
// outside [min, max] is refused, never wrapped or saturated. parseRealText()
// takes decimal reals ("12", "-0.5", "1e3"); hex, "inf" and "nan" are
// refused, as is a value outside its range: [min, max], or a RealRange whose
// open ends exclude the bound itself ("(1, 179)", "(0, 86400]"). The whole text must be the
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

// An interval of reals; an open end excludes its bound. Written as "[0, 100]",
// "(1, 179)" or "(0, 86400]" in messages.
struct RealRange {
    double min = 0, max = 0;
    bool minOpen = false, maxOpen = false;
    static constexpr RealRange closed(double lo, double hi) { return {lo, hi, false, false}; }
    static constexpr RealRange open(double lo, double hi) { return {lo, hi, true, true}; }
    static constexpr RealRange openMin(double lo, double hi) { return {lo, hi, true, false}; }  // (lo, hi]
    static constexpr RealRange openMax(double lo, double hi) { return {lo, hi, false, true}; }  // [lo, hi)
    constexpr bool contains(double v) const { return (minOpen ? v > min : v >= min) && (maxOpen ? v < max : v <= max); }
    std::string text() const;
};

Result<double> parseRealText(const std::string& what, const std::string& text, double min, double max);
Result<double> parseRealText(const std::string& what, const std::string& text, const RealRange& range);

}  // namespace vista
