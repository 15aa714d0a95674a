// Untrusted JSON text (parameter files, --effects) read under one set of rules.
//
// Contract: parseJsonInput() parses `text` (named `source` in messages) and
// refuses, with exit-2 style messages: nesting deeper than maxDepth
// ("source:LINE:COL: JSON nested deeper than N levels", checked before the
// parser runs), malformed JSON ("source:LINE:COL: malformed JSON: ..."), a
// number beyond the range of a double, and a key that appears twice in one
// object at any depth ("source: key 'K' appears twice in one object"). It
// keeps the text of every number as written, keyed by its JSON pointer
// ("/seed", "/effects/haze/visibility_m"), so that integers are parsed from
// that text (number_text.h: no wrap-around, no rounding through a double)
// and messages print what the user wrote. Keys and texts echoed in messages
// are cut by echoText(). Pure; thread-safe.
#pragma once
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "foundation/status.h"

namespace vista {

constexpr int kMaxJsonDepth = 16;

struct JsonInput {
    nlohmann::json doc;
    std::map<std::string, std::string> numberText;  // JSON pointer -> the number as written
    // The text of the number at `pointer`, or its dump() when unknown.
    std::string textOf(const std::string& pointer, const nlohmann::json& value) const;
};

Result<JsonInput> parseJsonInput(const std::string& text, const std::string& source, int maxDepth = kMaxJsonDepth);

}  // namespace vista
