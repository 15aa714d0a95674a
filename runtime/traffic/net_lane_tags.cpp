#include "runtime/traffic/net_lane_tags.h"

#include <expat.h>

#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>

#include "foundation/atomic_file.h"

namespace vista {

namespace {

struct Scan {
    XML_Parser parser = nullptr;
    const std::function<Result<bool>(const LaneTag&)>* pick = nullptr;
    int depth = 0;
    int internalEdgeDepth = -1;  // depth of the internal <edge> being read, -1 outside one
    bool sawRoot = false;
    std::vector<size_t> kept;  // byte offsets of "<lane"
    std::string error;
};

void stop(Scan* s, std::string why) {
    s->error = std::move(why);
    XML_StopParser(s->parser, XML_FALSE);
}

void startElement(void* u, const XML_Char* name, const XML_Char** atts) {
    auto* s = static_cast<Scan*>(u);
    ++s->depth;
    if (!s->sawRoot) {
        s->sawRoot = true;
        if (std::strcmp(name, "net") != 0) stop(s, std::string("the root element is <") + name + ">, not <net>");
        return;
    }
    const LaneTag tag(atts);
    if (s->depth == 2 && std::strcmp(name, "edge") == 0) {
        const char* function = tag.attribute("function");
        if (function && std::strcmp(function, "internal") == 0) s->internalEdgeDepth = s->depth;
    } else if (s->internalEdgeDepth >= 0 && s->depth == s->internalEdgeDepth + 1 && std::strcmp(name, "lane") == 0) {
        auto keep = (*s->pick)(tag);
        if (!keep) return stop(s, keep.status().message());
        if (*keep) s->kept.push_back(size_t(XML_GetCurrentByteIndex(s->parser)));
    }
}

void endElement(void* u, const XML_Char*) {
    auto* s = static_cast<Scan*>(u);
    if (s->depth == s->internalEdgeDepth) s->internalEdgeDepth = -1;
    --s->depth;
}

}  // namespace

const char* LaneTag::attribute(const char* name) const {
    for (int i = 0; _atts[i]; i += 2)
        if (std::strcmp(_atts[i], name) == 0) return _atts[i + 1];
    return nullptr;
}

Result<NetLaneTags> scanInternalLanes(const std::string& netPath,
                                      const std::function<Result<bool>(const LaneTag&)>& pick) {
    std::ifstream in(netPath, std::ios::binary);
    if (!in) return Status::error("cannot read the SUMO network '" + netPath + "': " + errnoText());
    std::stringstream buf;
    buf << in.rdbuf();
    NetLaneTags net;
    net.text = buf.str();

    Scan scan;
    scan.pick = &pick;
    XML_Parser p = XML_ParserCreate(nullptr);
    std::unique_ptr<XML_ParserStruct, void (*)(XML_Parser)> guard(p, &XML_ParserFree);
    scan.parser = p;
    XML_SetUserData(p, &scan);
    XML_SetElementHandler(p, startElement, endElement);
    if (XML_Parse(p, net.text.data(), int(net.text.size()), 1) == XML_STATUS_ERROR || !scan.error.empty()) {
        const std::string why = scan.error.empty() ? XML_ErrorString(XML_GetErrorCode(p)) : scan.error;
        return Status::error("SUMO network '" + netPath + "', line " + std::to_string(XML_GetCurrentLineNumber(p)) +
                             ": " + why);
    }
    if (!scan.sawRoot) return Status::error("SUMO network '" + netPath + "' is empty");
    // A start tag ends at the first '>' outside a quoted value; "/>" stays
    // outside the range, so text appended to the range lands inside the tag.
    for (size_t begin : scan.kept) {
        size_t end = begin;
        char quote = 0;
        for (; end < net.text.size(); ++end) {
            const char c = net.text[end];
            if (quote) quote = c == quote ? 0 : quote;
            else if (c == '"' || c == '\'') quote = c;
            else if (c == '>') break;
        }
        if (end >= net.text.size() || net.text.compare(begin, 5, "<lane") != 0)
            return Status::error("SUMO network '" + netPath + "': a <lane> tag is not where the parser put it");
        if (net.text[end - 1] == '/') --end;
        net.tags.push_back({begin, end});
    }
    return net;
}

Status rewriteLaneTags(const std::string& netPath, const NetLaneTags& net,
                       const std::function<std::string(size_t, const std::string&)>& rewrite) {
    std::string out;
    out.reserve(net.text.size() + net.tags.size() * 48);
    size_t from = 0;
    for (size_t i = 0; i < net.tags.size(); ++i) {
        const LaneTagRange& r = net.tags[i];
        out.append(net.text, from, r.begin - from);
        out += rewrite(i, net.text.substr(r.begin, r.end - r.begin));
        from = r.end;
    }
    out.append(net.text, from, std::string::npos);
    return writeFileAtomic(netPath, out);
}

}  // namespace vista
