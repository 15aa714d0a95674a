// Numbers as users write them (number_text.h).
#include "foundation/number_text.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace vista {

std::string echoText(const std::string& text) {
    if (text.size() <= kMaxEchoChars) return text;
    size_t cut = kMaxEchoChars;
    while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) --cut;  // whole UTF-8 characters
    return text.substr(0, cut) + "\xE2\x80\xA6";
}

std::string shortNumber(double v) {
    char buf[40];
    if (std::isfinite(v) && v == std::floor(v) && std::abs(v) < 1e15) {
        std::snprintf(buf, sizeof buf, "%.0f", v);
        return buf;
    }
    for (int digits = 6; digits <= 17; ++digits) {
        std::snprintf(buf, sizeof buf, "%.*g", digits, v);
        if (std::strtod(buf, nullptr) == v) return buf;
    }
    return buf;
}

namespace {

std::string quoted(const std::string& text) { return "'" + echoText(text) + "'"; }

Status notInteger(const std::string& what, const std::string& text, const std::string& range) {
    return Status::error(what + " = " + quoted(text) + " is not a whole number (expected a decimal integer in " +
                         range + ")");
}

std::string rangeText(const std::string& lo, const std::string& hi) { return "[" + lo + ", " + hi + "]"; }

// The digits of `text` after an optional '-': false if there are none or anything else.
bool decimalDigits(const std::string& text, bool& negative, std::string& digits) {
    negative = !text.empty() && text[0] == '-';
    digits = text.substr(negative ? 1 : 0);
    if (digits.empty()) return false;
    for (char c : digits)
        if (c < '0' || c > '9') return false;
    return true;
}

// `digits` (decimal, no sign) as a magnitude; false when it exceeds 2^64-1.
bool magnitude(const std::string& digits, uint64_t& out) {
    out = 0;
    for (char c : digits) {
        const uint64_t d = uint64_t(c - '0');
        if (out > (UINT64_MAX - d) / 10) return false;
        out = out * 10 + d;
    }
    return true;
}

}  // namespace

Result<uint64_t> parseUnsignedText(const std::string& what, const std::string& text, uint64_t min, uint64_t max) {
    const std::string range = rangeText(std::to_string(min), std::to_string(max));
    bool negative = false;
    std::string digits;
    if (!decimalDigits(text, negative, digits)) return notInteger(what, text, range);
    uint64_t v = 0;
    const bool fits = magnitude(digits, v);
    if (!fits || (negative && v != 0) || v < min || v > max)
        return Status::error(what + " = " + quoted(text) + " is out of range " + range);
    return v;
}

Result<int64_t> parseSignedText(const std::string& what, const std::string& text, int64_t min, int64_t max) {
    const std::string range = rangeText(std::to_string(min), std::to_string(max));
    bool negative = false;
    std::string digits;
    if (!decimalDigits(text, negative, digits)) return notInteger(what, text, range);
    uint64_t m = 0;
    const bool fits = magnitude(digits, m) && m <= (negative ? uint64_t(INT64_MAX) + 1 : uint64_t(INT64_MAX));
    const int64_t v = !fits ? 0 : negative ? int64_t(0 - m) : int64_t(m);
    if (!fits || v < min || v > max) return Status::error(what + " = " + quoted(text) + " is out of range " + range);
    return v;
}

std::string RealRange::text() const {
    return std::string(minOpen ? "(" : "[") + shortNumber(min) + ", " + shortNumber(max) + (maxOpen ? ")" : "]");
}

Result<double> parseRealText(const std::string& what, const std::string& text, double min, double max) {
    return parseRealText(what, text, RealRange::closed(min, max));
}

Result<double> parseRealText(const std::string& what, const std::string& text, const RealRange& r) {
    const std::string range = r.text();
    bool plain = !text.empty();
    for (char c : text)
        if (!((c >= '0' && c <= '9') || c == '.' || c == '-' || c == '+' || c == 'e' || c == 'E')) plain = false;
    if (!plain || text[0] == '+')
        return Status::error(what + " = " + quoted(text) + " is not a number (expected a decimal number in " + range +
                             ")");
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(text.c_str(), &end);
    if (end != text.c_str() + text.size())
        return Status::error(what + " = " + quoted(text) + " is not a number (expected a decimal number in " + range +
                             ")");
    if (!std::isfinite(v) || errno == ERANGE || !r.contains(v))
        return Status::error(what + " = " + quoted(text) + " is out of range " + range);
    return v;
}

}  // namespace vista
