#include "runtime/traffic/junction_turns.h"

#include <expat.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>

#include "foundation/atomic_file.h"
#include "foundation/units.h"

namespace vista {

namespace {

constexpr double kTurningVertexRad = 1e-3;

const char* attrOf(const XML_Char** atts, const char* name) {
    for (int i = 0; atts[i]; i += 2)
        if (std::strcmp(atts[i], name) == 0) return atts[i + 1];
    return nullptr;
}

std::vector<std::pair<double, double>> parseShape(const char* shape) {
    std::vector<std::pair<double, double>> pts;
    std::istringstream in(shape);
    for (std::string p; in >> p;) {
        double x = 0, y = 0;
        if (std::sscanf(p.c_str(), "%lf,%lf", &x, &y) >= 2) pts.push_back({x, y});
    }
    return pts;
}

std::vector<std::string> words(const std::string& list) {
    std::vector<std::string> out;
    std::istringstream in(list);
    for (std::string w; in >> w;) out.push_back(w);
    return out;
}

bool contains(const std::vector<std::string>& list, const std::string& word) {
    for (const std::string& w : list)
        if (w == word) return true;
    return false;
}

// One internal lane whose permissions change: where its start tag lies and
// the classes it loses.
struct Edit {
    size_t tag = 0;  // byte offset of "<lane"
    std::vector<std::string> remove;
};

struct Scan {
    XML_Parser parser = nullptr;
    const std::vector<TurnClass>* classes = nullptr;
    std::vector<double> needs;
    std::vector<size_t> closed;
    int depth = 0;
    int internalEdgeDepth = -1;
    bool sawRoot = false;
    std::vector<Edit> edits;
    std::string error;
};

}  // namespace

double turnRadius(const std::vector<std::pair<double, double>>& shape) {
    struct Seg {
        double length, heading;
    };
    std::vector<Seg> segs;
    for (size_t i = 1; i < shape.size(); ++i) {
        const double dx = shape[i].first - shape[i - 1].first, dy = shape[i].second - shape[i - 1].second;
        const double len = std::hypot(dx, dy);
        if (len > 1e-6) segs.push_back({len, std::atan2(dy, dx)});
    }
    // The bend runs from the first to the last vertex where the heading
    // turns; the straight parts before and after it do not count.
    double turn = 0.0;
    size_t first = 0, last = 0;
    for (size_t i = 1; i < segs.size(); ++i) {
        const double d = wrapAngle(segs[i].heading - segs[i - 1].heading);
        turn += d;
        if (std::fabs(d) > kTurningVertexRad) {
            if (first == 0) first = i;
            last = i;
        }
    }
    if (std::fabs(turn) < degToRad(kMinTurnDeg) || first == 0) return std::numeric_limits<double>::infinity();
    double bent = 0.0;
    for (size_t i = first; i < last; ++i) bent += segs[i].length;
    return bent / std::fabs(turn);
}

double turningNeedM(double lengthM) {
    // The sagitta R (1 - cos(L / 2R)) falls as R grows (for L / 2R below pi,
    // where the chord of length L exists); bisect for kMaxBoxCutM.
    auto cut = [&](double r) { return r * (1.0 - std::cos(std::min(kPi, lengthM / (2.0 * r)))); };
    double lo = lengthM / (2.0 * kPi), hi = lengthM * lengthM;
    if (cut(lo) <= kMaxBoxCutM) return 0.0;
    if (hi < 1.0) hi = 1.0;
    for (int i = 0; i < 100; ++i) {
        const double mid = 0.5 * (lo + hi);
        (cut(mid) > kMaxBoxCutM ? lo : hi) = mid;
    }
    return hi;
}

Result<std::vector<size_t>> restrictTightTurns(const std::string& netPath, const std::vector<TurnClass>& classes) {
    std::ifstream in(netPath, std::ios::binary);
    if (!in) return Status::error("cannot read the SUMO network '" + netPath + "': " + errnoText());
    std::stringstream buf;
    buf << in.rdbuf();
    const std::string text = buf.str();

    Scan scan;
    scan.classes = &classes;
    for (const TurnClass& c : classes) scan.needs.push_back(turningNeedM(c.lengthM));
    scan.closed.assign(classes.size(), 0);
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
                       std::strcmp(name, "lane") == 0) {
                const char* shape = attrOf(atts, "shape");
                if (!shape) return;
                const double radius = turnRadius(parseShape(shape));
                const char *allow = attrOf(atts, "allow"), *disallow = attrOf(atts, "disallow");
                const std::vector<std::string> allowed = allow ? words(allow) : std::vector<std::string>{};
                const std::vector<std::string> denied = disallow ? words(disallow) : std::vector<std::string>{};
                Edit edit;
                edit.tag = size_t(XML_GetCurrentByteIndex(s->parser));
                for (size_t c = 0; c < s->classes->size(); ++c) {
                    const std::string& cls = (*s->classes)[c].sumoClass;
                    if (!(s->needs[c] > radius)) continue;
                    const bool permitted =
                        allow ? (contains(allowed, cls) || contains(allowed, "all")) : !contains(denied, cls);
                    if (!permitted) continue;
                    if (allow && !contains(allowed, cls)) {
                        s->error = "an internal lane allows 'all': its classes cannot be listed";
                        XML_StopParser(s->parser, XML_FALSE);
                        return;
                    }
                    edit.remove.push_back(cls);
                    ++s->closed[c];
                }
                if (!edit.remove.empty()) s->edits.push_back(std::move(edit));
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

    // Each edited start tag is rewritten in place: its allow or disallow
    // value changes (or a disallow is added before its end), the rest of the
    // tag keeps its bytes.
    std::string out;
    out.reserve(text.size() + scan.edits.size() * 16);
    size_t from = 0;
    for (const Edit& e : scan.edits) {
        size_t end = e.tag;
        char quote = 0;
        for (; end < text.size(); ++end) {
            const char c = text[end];
            if (quote) quote = c == quote ? 0 : quote;
            else if (c == '"' || c == '\'') quote = c;
            else if (c == '>') break;
        }
        if (end >= text.size() || text.compare(e.tag, 5, "<lane") != 0)
            return Status::error("SUMO network '" + netPath + "': a <lane> tag is not where the parser put it");
        if (text[end - 1] == '/') --end;
        std::string tag = text.substr(e.tag, end - e.tag);
        auto valueAt = [&](const char* name, size_t* begin, size_t* stop) {
            const std::string key = std::string(" ") + name + "=\"";
            const size_t at = tag.find(key);
            if (at == std::string::npos) return false;
            *begin = at + key.size();
            *stop = tag.find('"', *begin);
            return *stop != std::string::npos;
        };
        size_t b = 0, s = 0;
        if (valueAt("allow", &b, &s)) {
            std::string kept;
            for (const std::string& w : words(tag.substr(b, s - b)))
                if (!contains(e.remove, w)) kept += (kept.empty() ? "" : " ") + w;
            tag.replace(b, s - b, kept);
        } else if (valueAt("disallow", &b, &s)) {
            std::string list = tag.substr(b, s - b);
            for (const std::string& w : e.remove) list += (list.empty() ? "" : " ") + w;
            tag.replace(b, s - b, list);
        } else {
            std::string list;
            for (const std::string& w : e.remove) list += (list.empty() ? "" : " ") + w;
            tag += " disallow=\"" + list + "\"";
        }
        out.append(text, from, e.tag - from);
        out += tag;
        from = end;
    }
    out.append(text, from, std::string::npos);
    VISTA_RETURN_IF_ERROR(writeFileAtomic(netPath, out));
    return scan.closed;
}

}  // namespace vista
