#include "runtime/traffic/junction_lanes.h"

#include <expat.h>

#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>
#include <vector>

#include "foundation/atomic_file.h"

namespace vista {

namespace {

struct Scan {
    XML_Parser parser = nullptr;
    int depth = 0;
    int internalEdgeDepth = -1;  // depth of the internal <edge> being read, -1 outside one
    bool sawRoot = false;
    std::vector<size_t> insertAt;  // byte offsets just past "<lane"
    std::string error;
};

bool hasAttr(const XML_Char** atts, const char* name) {
    for (int i = 0; atts[i]; i += 2)
        if (std::strcmp(atts[i], name) == 0) return true;
    return false;
}

const char* attrOf(const XML_Char** atts, const char* name) {
    for (int i = 0; atts[i]; i += 2)
        if (std::strcmp(atts[i], name) == 0) return atts[i + 1];
    return nullptr;
}

}  // namespace

Result<size_t> forbidJunctionLaneChanges(const std::string& netPath) {
    std::ifstream in(netPath, std::ios::binary);
    if (!in) return Status::error("cannot read the SUMO network '" + netPath + "': " + errnoText());
    std::stringstream buf;
    buf << in.rdbuf();
    const std::string text = buf.str();

    Scan scan;
    XML_Parser p = XML_ParserCreate(nullptr);
    std::unique_ptr<XML_ParserStruct, void (*)(XML_Parser)> guard(p, &XML_ParserFree);
    scan.parser = p;
    XML_SetUserData(p, &scan);
    XML_SetElementHandler(
        p,
        [](void* u, const XML_Char* name, const XML_Char** atts) {
            auto* s = static_cast<Scan*>(u);
            ++s->depth;
            if (!s->sawRoot) {
                s->sawRoot = true;
                if (std::strcmp(name, "net") != 0) {
                    s->error = std::string("the root element is <") + name + ">, not <net>";
                    XML_StopParser(s->parser, XML_FALSE);
                }
                return;
            }
            if (s->depth == 2 && std::strcmp(name, "edge") == 0) {
                const char* function = attrOf(atts, "function");
                if (function && std::strcmp(function, "internal") == 0) s->internalEdgeDepth = s->depth;
            } else if (s->internalEdgeDepth >= 0 && s->depth == s->internalEdgeDepth + 1 &&
                       std::strcmp(name, "lane") == 0 && !hasAttr(atts, "changeLeft") &&
                       !hasAttr(atts, "changeRight")) {
                s->insertAt.push_back(size_t(XML_GetCurrentByteIndex(s->parser)));
            }
        },
        [](void* u, const XML_Char*) {
            auto* s = static_cast<Scan*>(u);
            if (s->depth == s->internalEdgeDepth) s->internalEdgeDepth = -1;
            --s->depth;
        });
    if (XML_Parse(p, text.data(), int(text.size()), 1) == XML_STATUS_ERROR || !scan.error.empty()) {
        const std::string why = scan.error.empty() ? XML_ErrorString(XML_GetErrorCode(p)) : scan.error;
        return Status::error("SUMO network '" + netPath + "', line " + std::to_string(XML_GetCurrentLineNumber(p)) +
                             ": " + why);
    }
    if (!scan.sawRoot) return Status::error("SUMO network '" + netPath + "' is empty");

    // The marks go at the end of each <lane ...> start tag (before "/>" or
    // ">"), so the tag still begins with its id as netconvert wrote it.
    static const char kMark[] = " changeLeft=\"ignoring\" changeRight=\"ignoring\"";
    std::string out;
    out.reserve(text.size() + scan.insertAt.size() * (sizeof kMark - 1));
    size_t from = 0;
    for (size_t tag : scan.insertAt) {
        size_t at = tag;
        char quote = 0;
        for (; at < text.size(); ++at) {
            const char c = text[at];
            if (quote) quote = c == quote ? 0 : quote;
            else if (c == '"' || c == '\'') quote = c;
            else if (c == '>') break;
        }
        if (at >= text.size() || text.compare(tag, 5, "<lane") != 0)
            return Status::error("SUMO network '" + netPath + "': a <lane> tag is not where the parser put it");
        if (text[at - 1] == '/') --at;
        out.append(text, from, at - from);
        out += kMark;
        from = at;
    }
    out.append(text, from, std::string::npos);
    VISTA_RETURN_IF_ERROR(writeFileAtomic(netPath, out));
    return scan.insertAt.size();
}

}  // namespace vista
