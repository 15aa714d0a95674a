// Untrusted JSON text under one set of rules (json_input.h).
#include "citygen/json_input.h"

#include <set>
#include <vector>

#include "foundation/number_text.h"

namespace vista {

namespace {

using Json = nlohmann::json;

void lineCol(const std::string& text, size_t byte, size_t& line, size_t& col) {
    line = 1;
    col = 1;
    for (size_t i = 0; i < byte && i < text.size(); ++i) {
        if (text[i] == '\n') {
            ++line;
            col = 1;
        } else {
            ++col;
        }
    }
}

// Deepest nesting of arrays/objects in `text` (outside strings), stopping at `limit` + 1.
int nestingDepth(const std::string& text, int limit, size_t& where) {
    int depth = 0, worst = 0;
    bool inString = false;
    for (size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (inString) {
            if (c == '\\') ++i;
            else if (c == '"') inString = false;
            continue;
        }
        if (c == '"') inString = true;
        else if (c == '[' || c == '{') {
            if (++depth > worst) worst = depth;
            if (worst > limit) {
                where = i;
                return worst;
            }
        } else if (c == ']' || c == '}') {
            --depth;
        }
    }
    return worst;
}

// JSON pointer escaping of one reference token.
std::string escapeToken(const std::string& k) {
    std::string out;
    for (char c : k) {
        if (c == '~') out += "~0";
        else if (c == '/') out += "~1";
        else out += c;
    }
    return out;
}

// A DOM builder that also records number texts by pointer and refuses duplicate keys.
class CheckingSax {
public:
    CheckingSax(Json& root, JsonInput& out) : _dom(root, true), _out(out) {}

    bool null() { return scalar(_dom.null()); }
    bool boolean(bool v) { return scalar(_dom.boolean(v)); }
    bool number_integer(Json::number_integer_t v) { return number(std::to_string(v), _dom.number_integer(v)); }
    bool number_unsigned(Json::number_unsigned_t v) { return number(std::to_string(v), _dom.number_unsigned(v)); }
    bool number_float(Json::number_float_t v, const std::string& s) { return number(s, _dom.number_float(v, s)); }
    bool string(std::string& v) { return scalar(_dom.string(v)); }
    bool binary(Json::binary_t& v) { return scalar(_dom.binary(v)); }
    bool start_object(std::size_t n) {
        _frames.push_back({true, {}, 0, {}});
        return _dom.start_object(n);
    }
    bool key(std::string& k) {
        Frame& f = _frames.back();
        if (!f.keys.insert(k).second) {
            duplicate = k;
            return false;
        }
        f.key = k;
        return _dom.key(k);
    }
    bool end_object() {
        _frames.pop_back();
        return scalar(_dom.end_object());
    }
    bool start_array(std::size_t n) {
        _frames.push_back({false, {}, 0, {}});
        return _dom.start_array(n);
    }
    bool end_array() {
        _frames.pop_back();
        return scalar(_dom.end_array());
    }
    template <class Exception>
    bool parse_error(std::size_t pos, const std::string& token, const Exception& ex) {
        return _dom.parse_error(pos, token, ex);
    }

    std::string duplicate;

private:
    struct Frame {
        bool object;
        std::string key;
        size_t index;
        std::set<std::string> keys;
    };
    // A value ended: the next one of an enclosing array has the next index.
    bool scalar(bool ok) {
        if (!_frames.empty() && !_frames.back().object) ++_frames.back().index;
        return ok;
    }
    bool number(const std::string& text, bool ok) {
        std::string pointer;
        for (const Frame& f : _frames) pointer += "/" + (f.object ? escapeToken(f.key) : std::to_string(f.index));
        _out.numberText[pointer] = text;
        return scalar(ok);
    }

    nlohmann::detail::json_sax_dom_parser<Json> _dom;
    JsonInput& _out;
    std::vector<Frame> _frames;
};

}  // namespace

std::string JsonInput::textOf(const std::string& pointer, const nlohmann::json& value) const {
    auto it = numberText.find(pointer);
    return echoText(it != numberText.end() ? it->second : value.dump());
}

Result<JsonInput> parseJsonInput(const std::string& text, const std::string& source, int maxDepth) {
    // Bounded nesting: deeper input would only cost stack in the parser and in messages.
    size_t deepAt = 0;
    if (nestingDepth(text, maxDepth, deepAt) > maxDepth) {
        size_t line = 0, col = 0;
        lineCol(text, deepAt, line, col);
        return Status::error(source + ":" + std::to_string(line) + ":" + std::to_string(col) +
                             ": JSON nested deeper than " + std::to_string(maxDepth) + " levels");
    }
    JsonInput in;
    CheckingSax sax(in.doc, in);
    try {
        const bool ok = Json::sax_parse(text, &sax);
        if (!sax.duplicate.empty())
            return Status::error(source + ": key '" + echoText(sax.duplicate) + "' appears twice in one object");
        if (!ok) return Status::error(source + ": malformed JSON");
    } catch (const nlohmann::json::parse_error& e) {
        size_t line = 0, col = 0;
        lineCol(text, e.byte == 0 ? 0 : e.byte - 1, line, col);
        std::string what = e.what();
        auto pos = what.find("syntax error");
        what = pos == std::string::npos ? what : what.substr(pos);
        return Status::error(source + ":" + std::to_string(line) + ":" + std::to_string(col) +
                             ": malformed JSON: " + echoText(what));
    } catch (const nlohmann::json::exception& e) {
        // out_of_range 406: a number beyond the range of a double (1e999, 400 digits).
        std::string what = e.what();
        auto pos = what.find("number overflow");
        what = pos == std::string::npos ? what : what.substr(pos);
        if (what.size() > 80) what = what.substr(0, 77) + "...";
        return Status::error(source + ": malformed JSON: " + what + " (numbers must fit a double)");
    }
    return in;
}

}  // namespace vista
