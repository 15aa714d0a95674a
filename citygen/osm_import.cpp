// importOsm(): highway=* ways from .osm (XML, optionally .gz/.bz2) or .osm.pbf
// via libosmium -> drop invalid, missing and outlier nodes -> transverse
// Mercator about the centre of the data (geodesy.h) -> extent check ->
// simplification -> tangle bounds -> planarize(). Contract in streets.h.
//
// XML is read into memory and pre-scanned before libosmium parses it: every
// attribute libosmium would parse as a coordinate (lat, lon; the bounds' and
// changesets' min/max ones) must be plain decimal text in range; otherwise
// the element's coordinate attributes are overwritten with spaces, so
// libosmium's coordinate parser (which overflows a signed integer on values
// like 1e300) never sees them and the node has no location (counted as
// invalid). DOCTYPE declarations (entities, default attributes) and UTF-16/32
// text are refused, as are tags the scanner cannot follow.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <fcntl.h>
#include <fstream>
#include <iterator>
#include <limits>
#include <set>
#include <sstream>
#include <string_view>
#include <unordered_map>
#include <unordered_set>

#include <osmium/handler.hpp>
#include <osmium/handler/node_locations_for_ways.hpp>
#include <osmium/index/map/flex_mem.hpp>
#include <osmium/io/any_input.hpp>
#include <osmium/visitor.hpp>

#include "citygen/footprint_repair.h"
#include "citygen/osm_road_tags.h"
#include "citygen/polygon.h"
#include "citygen/short_bends.h"
#include "citygen/side_by_side.h"
#include "citygen/street_geometry.h"
#include "citygen/streets.h"
#include "foundation/hash.h"
#include "foundation/input_file.h"
#include "foundation/number_text.h"
#include "foundation/units.h"

namespace vista {

namespace {

using Index = osmium::index::map::FlexMem<osmium::unsigned_object_id_type, osmium::Location>;
using LocationHandler = osmium::handler::NodeLocationsForWays<Index>;
using NodeId = osmium::object_id_type;

constexpr double kEarthRadius_m = 6371008.8;      // mean radius: only for the outlier test
constexpr double kSimplifyTolerance_m = 0.5;      // Douglas-Peucker tolerance
constexpr size_t kSimplifyChunk = 1024;           // Douglas-Peucker works on runs of at most this many nodes
constexpr size_t kMaxSelfConflicts = 16;          // a way crossing itself more often is dropped
constexpr size_t kMaxConflicts = 100000;          // more crossings in all is refused
constexpr size_t kMaxXmlBytes = size_t(4) << 30;  // decompressed XML read into memory
constexpr double kAlongCos = 0.7;                 // a way within 45 degrees of an edge runs along it
constexpr double kParallelCos = 0.95;             // opposite one-ways merged into an edge: within 18 degrees of it

// ---- XML pre-scan ---------------------------------------------------------

bool xmlSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

// Attributes libosmium's XML parser hands to its coordinate parser; 0 = none, 1 = latitude, 2 = longitude.
int coordinateKind(std::string_view name) {
    static const char* lat[] = {"lat", "minlat", "maxlat", "min_lat", "max_lat"};
    static const char* lon[] = {"lon", "minlon", "maxlon", "min_lon", "max_lon"};
    for (const char* s : lat)
        if (name == s) return 1;
    for (const char* s : lon)
        if (name == s) return 2;
    return 0;
}

// -?digits[.digits][(e|E)-?digits], at most 32 characters, finite and |value| <= limit.
// Such text cannot overflow libosmium's parser: it scales the digits to value * 1e8.
bool saneCoordinate(std::string_view s, double limit) {
    if (s.empty() || s.size() > 32) return false;
    size_t p = 0, digits = 0;
    auto run = [&] {
        size_t k = 0;
        while (p < s.size() && s[p] >= '0' && s[p] <= '9') {
            ++p;
            ++k;
        }
        return k;
    };
    if (s[p] == '-') ++p;
    digits += run();
    if (p < s.size() && s[p] == '.') {
        ++p;
        digits += run();
    }
    if (digits == 0) return false;
    if (p < s.size() && (s[p] == 'e' || s[p] == 'E')) {
        ++p;
        if (p < s.size() && s[p] == '-') ++p;
        if (run() == 0) return false;
    }
    if (p != s.size()) return false;
    double v = 0;
    auto r = std::from_chars(s.data(), s.data() + s.size(), v);
    return r.ec == std::errc() && std::isfinite(v) && std::abs(v) <= limit;
}

struct CoordinateAttribute {
    size_t begin, end;  // the whole name="value" text
    size_t valueBegin, valueEnd;
    int kind;
};

// Bytes of an XML attribute value once its references are replaced: a named
// entity (&amp;) is one byte, a character reference (&#233; &#xE9;) the UTF-8
// length of its code point (libosmium's limits count these bytes).
size_t xmlDecodedBytes(std::string_view v) {
    size_t n = 0;
    for (size_t i = 0; i < v.size(); ++n) {
        const size_t semi = v[i] == '&' ? v.find(';', i) : std::string_view::npos;
        if (semi == std::string_view::npos) {
            ++i;
            continue;
        }
        const std::string_view ref = v.substr(i + 1, semi - i - 1);
        i = semi + 1;
        if (ref.empty() || ref[0] != '#') continue;
        uint32_t cp = 0;
        const bool hex = ref.size() > 1 && (ref[1] == 'x' || ref[1] == 'X');
        const std::string_view digits = ref.substr(hex ? 2 : 1);
        std::from_chars(digits.data(), digits.data() + digits.size(), cp, hex ? 16 : 10);
        n += cp < 0x80 ? 0 : cp < 0x800 ? 1 : cp < 0x10000 ? 2 : 3;
    }
    return n;
}

// Blanks bad coordinate attributes in place; returns the ids of nodes that lost their location.
Result<std::vector<NodeId>> sanitizeXml(std::string& xml, const std::string& path) {
    auto fail = [&](size_t at, const std::string& what) {
        const size_t line = 1 + size_t(std::count(xml.begin(), xml.begin() + std::min(at, xml.size()), '\n'));
        return Status::error("OSM file '" + path + "': " + what + " (line " + std::to_string(line) + ")");
    };
    const size_t n = xml.size();
    const auto* u = reinterpret_cast<const unsigned char*>(xml.data());
    if ((n >= 2 && ((u[0] == 0xFE && u[1] == 0xFF) || (u[0] == 0xFF && u[1] == 0xFE))) ||
        std::find(xml.begin(), xml.begin() + std::min<size_t>(n, 4), '\0') != xml.begin() + std::min<size_t>(n, 4))
        return fail(0, "UTF-16/UTF-32 XML is not supported (use UTF-8)");
    std::vector<NodeId> blanked;
    std::vector<CoordinateAttribute> coords;  // of the current tag
    std::string owner = "the file's header";  // the node, way or relation whose <tag> elements follow
    size_t i = 0;
    while (true) {
        const size_t lt = xml.find('<', i);
        if (lt == std::string::npos) break;
        auto skipTo = [&](const char* close) {
            size_t e = xml.find(close, lt + 1);
            return e == std::string::npos ? n : e + std::strlen(close);
        };
        if (xml.compare(lt, 4, "<!--") == 0) {
            i = skipTo("-->");
            continue;
        }
        if (xml.compare(lt, 9, "<![CDATA[") == 0) {
            i = skipTo("]]>");
            continue;
        }
        if (xml.compare(lt, 2, "<!") == 0) return fail(lt, "DOCTYPE and other declarations are not supported");
        if (xml.compare(lt, 2, "<?") == 0) {
            i = skipTo("?>");
            continue;
        }
        if (xml.compare(lt, 2, "</") == 0) {
            i = skipTo(">");
            continue;
        }
        // A start tag: name, then name="value" / name='value' pairs, then > or />.
        size_t p = lt + 1;
        while (p < n && !xmlSpace(xml[p]) && xml[p] != '>' && xml[p] != '/') ++p;
        const std::string_view element = std::string_view(xml).substr(lt + 1, p - lt - 1);
        const bool isNode = element == "node", isTag = element == "tag";
        const bool isObject = isNode || element == "way" || element == "relation";
        std::string_view idText, tagKey, tagValue;
        coords.clear();
        NodeId id = 0;
        bool hasId = false, closed = false;
        while (p < n) {
            while (p < n && xmlSpace(xml[p])) ++p;
            if (p >= n) break;
            if (xml[p] == '>') {
                ++p;
                closed = true;
                break;
            }
            if (xml[p] == '/') {
                if (p + 1 < n && xml[p + 1] == '>') {
                    p += 2;
                    closed = true;
                    break;
                }
                return fail(p, "malformed XML tag");
            }
            const size_t nameBegin = p;
            while (p < n && !xmlSpace(xml[p]) && xml[p] != '=' && xml[p] != '>' && xml[p] != '/') ++p;
            const std::string_view name = std::string_view(xml).substr(nameBegin, p - nameBegin);
            while (p < n && xmlSpace(xml[p])) ++p;
            if (p >= n) break;
            if (name.empty() || xml[p] != '=') return fail(p, "malformed XML attribute");
            ++p;
            while (p < n && xmlSpace(xml[p])) ++p;
            if (p >= n) break;
            if (xml[p] != '"' && xml[p] != '\'') return fail(p, "malformed XML attribute");
            const size_t valueBegin = p + 1, valueEnd = xml.find(xml[p], valueBegin);
            if (valueEnd == std::string::npos) {
                p = n;
                break;
            }
            p = valueEnd + 1;
            const std::string_view value = std::string_view(xml).substr(valueBegin, valueEnd - valueBegin);
            if (int kind = coordinateKind(name)) coords.push_back({nameBegin, p, valueBegin, valueEnd, kind});
            else if (isObject && name == "id") idText = value;
            else if (isTag && name == "k") tagKey = value;
            else if (isTag && name == "v") tagValue = value;
            if (isNode && name == "id")
                hasId = std::from_chars(xml.data() + valueBegin, xml.data() + valueEnd, id).ec == std::errc();
        }
        // An unfinished tag at the end of the text: expat rejects it before reporting it.
        if (!closed) break;
        if (isObject) owner = std::string(element) + " " + echoText(std::string(idText));
        // A tag key or value beyond libosmium's limit: its reader would stop
        // with a bare "too long"; name the tag and its owner instead.
        if (isTag)
            for (const auto& [what, text] : {std::pair{"key", tagKey}, std::pair{"value", tagValue}})
                if (const size_t bytes = xmlDecodedBytes(text); bytes > osmium::max_osm_string_length)
                    return fail(lt, owner + ": tag '" + echoText(std::string(tagKey)) + "' has a " + what + " of " +
                                        std::to_string(bytes) + " bytes, more than the limit of " +
                                        std::to_string(osmium::max_osm_string_length) +
                                        " bytes (OSM allows 255 characters)");
        bool bad = false;
        for (const auto& c : coords)
            bad = bad || !saneCoordinate(std::string_view(xml).substr(c.valueBegin, c.valueEnd - c.valueBegin),
                                         c.kind == 1 ? 90.0 : 180.0);
        if (bad) {
            for (const auto& c : coords) std::fill(xml.begin() + long(c.begin), xml.begin() + long(c.end), ' ');
            if (isNode && hasId) blanked.push_back(id);
        }
        i = p;
    }
    std::sort(blanked.begin(), blanked.end());
    return blanked;
}

// A bzip2 error in words (libbz2 reports a number).
std::string bzip2Problem(const osmium::bzip2_error& e) {
    switch (e.bzip2_error_code) {
        case BZ_UNEXPECTED_EOF: return "the bzip2 data ends early (the file is truncated or incomplete)";
        case BZ_DATA_ERROR:
        case BZ_DATA_ERROR_MAGIC: return "the file is not valid bzip2 data (damaged or not compressed with bzip2)";
        case BZ_MEM_ERROR: return "out of memory while decompressing bzip2 data";
        case BZ_IO_ERROR:
            return std::string("read error: ") + (e.system_errno ? std::strerror(e.system_errno) : "I/O error");
        default: return e.what();
    }
}

// The whole (decompressed) XML text.
Result<std::string> readXml(const osmium::io::File& file, const std::string& path) {
    const std::string tooLarge = "OSM file '" + path + "' holds more than " + std::to_string(kMaxXmlBytes >> 30) +
                                 " GiB of XML: use .osm.pbf for extracts this large";
    std::string text;
    if (file.compression() == osmium::io::file_compression::none) {
        // Plain XML: read exactly the file (libosmium's decompressor would zero a 1 MiB buffer per read).
        std::ifstream in(path, std::ios::binary | std::ios::ate);
        if (!in) return Status::error("OSM file '" + path + "' cannot be opened");
        const std::streamoff size = in.tellg();
        if (size < 0) return Status::error("OSM file '" + path + "' cannot be read");
        if (uint64_t(size) > kMaxXmlBytes) return Status::error(tooLarge);
        text.resize(size_t(size));
        in.seekg(0);
        if (size > 0 && !in.read(text.data(), size)) return Status::error("OSM file '" + path + "' cannot be read");
        return text;
    }
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return Status::error("OSM file '" + path + "' cannot be opened");
    auto dec = osmium::io::CompressionFactory::instance().create_decompressor(file.compression(), fd);
    for (std::string chunk = dec->read(); !chunk.empty(); chunk = dec->read()) {
        if (text.size() + chunk.size() > kMaxXmlBytes) {
            dec->close();
            return Status::error(tooLarge);
        }
        text += chunk;
    }
    dec->close();
    return text;
}

// ---- reading ways -----------------------------------------------------------

bool classify(const char* hw, RoadClass& cls) {
    static const char* highway[] = {"motorway", "motorway_link", "trunk", "trunk_link", "primary", "primary_link"};
    static const char* arterial[] = {"secondary", "secondary_link", "tertiary", "tertiary_link"};
    static const char* skip[] = {"footway",    "path",      "cycleway", "steps",        "bridleway",
                                 "pedestrian", "corridor",  "proposed", "construction", "platform",
                                 "elevator",   "abandoned", "raceway"};
    for (const char* s : skip)
        if (!std::strcmp(hw, s)) return false;
    for (const char* s : highway)
        if (!std::strcmp(hw, s)) {
            cls = RoadClass::Highway;
            return true;
        }
    for (const char* s : arterial)
        if (!std::strcmp(hw, s)) {
            cls = RoadClass::Arterial;
            return true;
        }
    cls = RoadClass::Local;
    return true;
}

struct WayNode {
    NodeId id = 0;
    osmium::Location loc;
    GeoPoint geo;
    glm::dvec2 xy{0.0};
};

struct Way {
    NodeId id = 0;
    RoadClass cls = RoadClass::Local;
    std::vector<WayNode> nodes;
    uint32_t tags = 0;  // index into WayCollector::roadTags
};

bool isBuilding(const osmium::TagList& tags) {
    const char* b = tags["building"];
    return b && *b && std::strcmp(b, "no") != 0;
}

// The height and roof tags of a building way or relation (absent / unparsable -> NaN).
void readBuildingTags(const osmium::TagList& tags, OsmFootprint& f) {
    constexpr double kAbsent = std::numeric_limits<double>::quiet_NaN();
    auto length = [&](const char* key) {
        const char* v = tags[key];
        return v ? parseOsmLength(v) : kAbsent;
    };
    auto levels = [&](const char* key) {
        const char* v = tags[key];
        return v ? parseOsmLevels(v) : kAbsent;
    };
    f.height_m = length("height");
    f.min_height_m = length("min_height");
    f.roof_height_m = length("roof:height");
    f.levels = levels("building:levels");
    f.min_level = levels("building:min_level");
    f.roof_levels = levels("roof:levels");
    const char* shape = tags["roof:shape"];
    f.roof = shape ? parseOsmRoofShape(shape) : OsmRoofShape::Absent;
}

// A way kept for the buildings: tagged building=* itself, or a member of a building relation.
struct BuildingWay {
    NodeId id = 0;
    bool building = false;  // tagged building=* (a footprint of its own)
    OsmFootprint tags;      // its parsed tags (when `building`)
    std::vector<WayNode> nodes;
};

struct BuildingRelation {
    NodeId id = 0;
    OsmFootprint tags;
    std::vector<std::pair<NodeId, bool>> members;  // way id, inner (else outer)
};

// Multipolygon relations tagged building=* (the first pass over the file).
struct RelationCollector : public osmium::handler::Handler {
    std::vector<BuildingRelation> relations;
    void relation(const osmium::Relation& r) {
        const char* type = r.tags()["type"];
        if (!type || std::strcmp(type, "multipolygon") != 0 || !isBuilding(r.tags())) return;
        BuildingRelation br;
        br.id = r.id();
        readBuildingTags(r.tags(), br.tags);
        for (const auto& m : r.members()) {
            if (m.type() != osmium::item_type::way) continue;
            const char* role = m.role();
            const bool inner = std::strcmp(role, "inner") == 0;
            if (!inner && *role && std::strcmp(role, "outer") != 0) continue;  // other roles are not rings
            br.members.push_back({m.ref(), inner});
        }
        relations.push_back(std::move(br));
    }
};

struct WayCollector : public osmium::handler::Handler {
    std::vector<Way> ways;
    std::vector<OsmRoadTags> roadTags;  // of every way in `ways` (by Way::tags)
    OsmRoadTagStats roadStats;
    bool buildings = false;
    std::unordered_set<NodeId> memberWays;  // ways of building relations
    std::vector<BuildingWay> buildingWays;
    void way(const osmium::Way& w) {
        if (buildings) {
            const bool building = isBuilding(w.tags());
            if (building || memberWays.count(w.id())) {
                BuildingWay bw;
                bw.id = w.id();
                bw.building = building;
                if (building) readBuildingTags(w.tags(), bw.tags);
                for (const auto& nr : w.nodes()) bw.nodes.push_back({nr.ref(), nr.location(), {}, {}});
                buildingWays.push_back(std::move(bw));
            }
        }
        const char* hw = w.tags()["highway"];
        RoadClass cls;
        if (!hw || !classify(hw, cls) || w.nodes().empty()) return;
        Way out;
        out.id = w.id();
        out.cls = cls;
        for (const auto& nr : w.nodes()) out.nodes.push_back({nr.ref(), nr.location(), {}, {}});
        out.tags = uint32_t(roadTags.size());
        roadTags.push_back(readOsmRoadTags([&](const char* key) { return w.tags()[key]; }, cls, roadStats));
        ways.push_back(std::move(out));
    }
};

// Splits ways where `keep` is false, keeping pieces of at least two nodes.
template <class Keep>
std::vector<Way> splitWays(std::vector<Way>&& ways, Keep keep) {
    std::vector<Way> out;
    for (auto& w : ways) {
        Way piece{w.id, w.cls, {}, w.tags};
        auto flush = [&] {
            if (piece.nodes.size() >= 2) out.push_back(piece);
            piece.nodes.clear();
        };
        for (const auto& n : w.nodes) {
            if (keep(n)) piece.nodes.push_back(n);
            else flush();
        }
        flush();
    }
    return out;
}

glm::dvec3 unitVector(const GeoPoint& g) {
    const double lat = degToRad(g.lat_deg), lon = degToRad(g.lon_deg);
    return {std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat)};
}

GeoPoint fromUnitVector(const glm::dvec3& v) {
    return {radToDeg(std::atan2(v.z, std::hypot(v.x, v.y))), radToDeg(std::atan2(v.y, v.x))};
}

// Median position: the normalised component-wise median of the unit vectors (robust, no seam at +-180).
glm::dvec3 medianDirection(const std::vector<Way>& ways) {
    std::vector<double> c[3];
    for (const auto& w : ways)
        for (const auto& n : w.nodes) {
            const glm::dvec3 v = unitVector(n.geo);
            for (int k = 0; k < 3; ++k) c[k].push_back(v[k]);
        }
    glm::dvec3 m(0.0);
    for (int k = 0; k < 3; ++k) {
        auto mid = c[k].begin() + long(c[k].size() / 2);
        std::nth_element(c[k].begin(), mid, c[k].end());
        m[k] = *mid;
    }
    // Degenerate (data spread evenly over opposite sides of the globe): the first node.
    return glm::length(m) > 1e-6 ? glm::normalize(m) : unitVector(ways.front().nodes.front().geo);
}

double roundTo1e7(double deg) { return std::round(deg * 1e7) / 1e7; }

// ---- simplification -----------------------------------------------------------

double pointSegmentDistance(const glm::dvec2& p, const glm::dvec2& a, const glm::dvec2& b) {
    const glm::dvec2 d = b - a;
    const double dd = glm::dot(d, d);
    const double t = dd > 0 ? std::clamp(glm::dot(p - a, d) / dd, 0.0, 1.0) : 0.0;
    return glm::length(p - (a + t * d));
}

// Douglas-Peucker on nodes[first..last] (both kept); marks kept nodes.
void douglasPeucker(const std::vector<WayNode>& nodes, size_t first, size_t last, std::vector<char>& keep) {
    std::vector<std::pair<size_t, size_t>> stack{{first, last}};
    while (!stack.empty()) {
        auto [s, e] = stack.back();
        stack.pop_back();
        double worst = 0;
        size_t at = s;
        for (size_t k = s + 1; k < e; ++k) {
            const double d = pointSegmentDistance(nodes[k].xy, nodes[s].xy, nodes[e].xy);
            if (d > worst) {
                worst = d;
                at = k;
            }
        }
        if (worst > kSimplifyTolerance_m) {
            keep[at] = 1;
            stack.push_back({s, at});
            stack.push_back({at, e});
        }
    }
}

// Drops nodes closer than minSegment to the previous kept node, then Douglas-Peucker; junctions
// (nodes used more than once) and the ends of every piece stay. Returns the number of nodes removed.
size_t simplify(std::vector<Way>& ways, double minSegment) {
    std::unordered_map<NodeId, int> uses;
    for (const auto& w : ways)
        for (const auto& n : w.nodes) uses[n.id]++;
    size_t removed = 0;
    for (auto& w : ways) {
        const size_t count = w.nodes.size();
        auto fixed = [&](size_t k) { return k == 0 || k + 1 == count || uses[w.nodes[k].id] > 1; };
        std::vector<WayNode> spaced;
        for (size_t k = 0; k < count; ++k)
            if (fixed(k) || glm::length(w.nodes[k].xy - spaced.back().xy) >= minSegment) spaced.push_back(w.nodes[k]);
        std::vector<char> keep(spaced.size(), 0);
        for (size_t k = 0, run = 0; k < spaced.size(); ++k, ++run)
            if (k == 0 || k + 1 == spaced.size() || uses[spaced[k].id] > 1 || run == kSimplifyChunk) {
                keep[k] = 1;
                run = 0;
            }
        for (size_t s = 0, e = 1; e < spaced.size(); ++e)
            if (keep[e]) {
                douglasPeucker(spaced, s, e, keep);
                s = e;
            }
        w.nodes.clear();
        for (size_t k = 0; k < spaced.size(); ++k)
            if (keep[k]) w.nodes.push_back(spaced[k]);
        removed += count - w.nodes.size();
    }
    return removed;
}

// The segments of `ways` as a graph (one node per OSM node id), for the conflict counts.
StreetGraph segmentGraph(const std::vector<Way>& ways, size_t first, size_t last) {
    StreetGraph g;
    std::unordered_map<NodeId, uint32_t> index;
    auto node = [&](const WayNode& n) {
        auto [it, inserted] = index.emplace(n.id, uint32_t(g.nodes.size()));
        if (inserted) g.nodes.push_back(n.xy);
        return it->second;
    };
    for (size_t w = first; w < last; ++w)
        for (size_t k = 1; k < ways[w].nodes.size(); ++k) {
            const uint32_t a = node(ways[w].nodes[k - 1]), b = node(ways[w].nodes[k]);
            if (a == b || g.nodes[a] == g.nodes[b]) continue;
            StreetEdge e;
            e.a = a;
            e.b = b;
            e.cls = ways[w].cls;
            g.edges.push_back(e);
        }
    return g;
}

// ---- road tags onto the planar edges ---------------------------------------------

struct WaySeg {
    glm::dvec2 p, q;
    uint32_t way;
};

uint64_t gridKey(int64_t x, int64_t y) { return (uint64_t(x) << 32) ^ (uint64_t(y) & 0xffffffffull); }

// Uniform grid of cell side `cell`: a segment is listed in the 3 x 3 cells around points every
// `cell` along it, so every point within cell / 2 of it finds it in its own cell (gridKey).
std::unordered_map<uint64_t, std::vector<uint32_t>> segmentGrid(const std::vector<WaySeg>& segs, double cell) {
    std::unordered_map<uint64_t, std::vector<uint32_t>> grid;
    for (uint32_t s = 0; s < segs.size(); ++s) {
        const double len = glm::length(segs[s].q - segs[s].p);
        const int steps = int(std::min(std::ceil(len / cell), 1e6));
        for (int i = 0; i <= steps; ++i) {
            const glm::dvec2 p = segs[s].p + (steps ? double(i) / steps : 0.0) * (segs[s].q - segs[s].p);
            const int64_t cx = int64_t(std::floor(p.x / cell)), cy = int64_t(std::floor(p.y / cell));
            for (int64_t dy = -1; dy <= 1; ++dy)
                for (int64_t dx = -1; dx <= 1; ++dx) {
                    auto& list = grid[gridKey(cx + dx, cy + dy)];
                    if (list.empty() || list.back() != s) list.push_back(s);
                }
        }
    }
    return grid;
}

// The tags of way `w` (`t`, in the way's direction) in the direction a -> b of an edge on it:
// the way's segment nearest to the edge's midpoint decides.
OsmRoadTags tagsAlong(const Way& w, const OsmRoadTags& t, const glm::dvec2& a, const glm::dvec2& b) {
    const glm::dvec2 mid = 0.5 * (a + b);
    size_t nearest = 1;
    double bestD = 1e300;
    for (size_t k = 1; k < w.nodes.size(); ++k)
        if (const double d = pointSegmentDistance(mid, w.nodes[k - 1].xy, w.nodes[k].xy); d < bestD)
            bestD = d, nearest = k;
    return glm::dot(b - a, w.nodes[nearest].xy - w.nodes[nearest - 1].xy) >= 0 ? t : t.reversed();
}

// Turns every one-way edge to run along its traffic (a and b, the directions' lanes and turn
// lanes swapped where it ran against it) and, unless `widthTagged`, makes it as wide as its
// lanes are at the class's lane width (roadWidth / roadLanes).
void alignOneWayEdges(StreetGraph& g, const std::vector<char>& widthTagged) {
    for (size_t i = 0; i < g.edges.size(); ++i) {
        StreetEdge& e = g.edges[i];
        const bool forwardOnly = e.lanesForward > 0 && e.lanesBackward == 0;
        const bool backwardOnly = e.lanesBackward > 0 && e.lanesForward == 0;
        if (!forwardOnly && !backwardOnly) continue;
        if (backwardOnly) {
            std::swap(e.a, e.b);
            std::swap(e.lanesForward, e.lanesBackward);
            std::swap(e.turnForward, e.turnBackward);
        }
        if (!widthTagged[i]) e.width = float(e.lanesForward * roadWidth(e.cls) / roadLanes(e.cls));
    }
}

// Gives every street edge the road tags (osm_road_tags.h) of the way it lies on. An edge of a
// one-way way's carriageway (planarize() keeps each one-way way apart; `carriageways`: per edge,
// way index + 1, or 0) takes that way's tags. Any other edge: among the
// ways of the edge's class, the one whose segments come closest to the points at 1/4, 1/2
// and 3/4 of the edge (the largest of the three distances, at most `tol`: planarization moves
// nodes by up to the snap radius and merges ends closer than the minimum segment). The way's
// segment nearest to the edge's midpoint gives the direction: tags are swapped for an edge
// running against the way; ways whose segment there lies within 45 degrees of the edge come
// before crossing ones. When that way is one-way and another way of the class within
// `mergeTol` is one-way the other way round, both within 18 degrees of the edge (a dual
// carriageway whose two ways overlapped into one edge), each gives its direction.
// Then alignOneWayEdges().
void assignRoadTags(StreetGraph& g, const std::vector<uint32_t>& carriageways, const std::vector<Way>& ways,
                    const std::vector<OsmRoadTags>& tags, double tol, double mergeTol, OsmRoadTagStats& st) {
    std::vector<WaySeg> segs;
    for (size_t w = 0; w < ways.size(); ++w)
        for (size_t k = 1; k < ways[w].nodes.size(); ++k)
            segs.push_back({ways[w].nodes[k - 1].xy, ways[w].nodes[k].xy, uint32_t(w)});
    const double cell = std::max(2.0 * tol, 1.0);
    auto cellOf = [&](const glm::dvec2& p) {
        return std::make_pair(int64_t(std::floor(p.x / cell)), int64_t(std::floor(p.y / cell)));
    };
    const auto grid = segmentGrid(segs, cell);
    struct Cand {
        uint32_t way;
        double d[3];
        uint32_t midSeg;  // the way's segment nearest to the edge's midpoint
        double score() const { return std::max({d[0], d[1], d[2]}); }
    };
    std::vector<Cand> cands;
    std::unordered_map<uint32_t, size_t> candOf;  // way -> index in cands
    std::vector<char> widthTagged(g.edges.size(), 0);
    for (size_t i = 0; i < g.edges.size(); ++i) {
        StreetEdge& e = g.edges[i];
        const glm::dvec2 a = g.nodes[e.a], b = g.nodes[e.b];
        if (i < carriageways.size() && carriageways[i] > 0 && carriageways[i] <= ways.size()) {
            const Way& w = ways[carriageways[i] - 1];  // the edge's own one-way way
            ++st.edgesMatched;
            applyOsmRoadTags(tagsAlong(w, tags[w.tags], a, b), e);
            widthTagged[i] = tags[w.tags].width > 0;
            continue;
        }
        cands.clear();
        candOf.clear();
        for (int k = 0; k < 3; ++k) {
            const glm::dvec2 p = a + 0.25 * (k + 1) * (b - a);
            const auto [cx, cy] = cellOf(p);
            auto it = grid.find(gridKey(cx, cy));
            if (it == grid.end()) continue;
            for (uint32_t s : it->second) {
                if (ways[segs[s].way].cls != e.cls) continue;
                const double d = pointSegmentDistance(p, segs[s].p, segs[s].q);
                if (d > tol) continue;
                auto [slot, fresh] = candOf.emplace(segs[s].way, cands.size());
                if (fresh) cands.push_back(Cand{segs[s].way, {1e300, 1e300, 1e300}, s});
                Cand& c = cands[slot->second];
                if (d < c.d[k]) {
                    c.d[k] = d;
                    if (k == 1) c.midSeg = s;
                }
            }
        }
        // |cos| of the angle between the edge and the way's segment at the midpoint.
        const glm::dvec2 dir = glm::normalize(b - a);
        auto alignment = [&](const Cand& c) {
            const glm::dvec2 sd = segs[c.midSeg].q - segs[c.midSeg].p;
            const double len = glm::length(sd);
            return len > 0 ? std::abs(glm::dot(dir, sd / len)) : 0.0;
        };
        // Ways along the edge before crossing ones (near a junction a short edge is close to both).
        auto better = [&](const Cand& x, const Cand& y) {
            const bool ax = alignment(x) >= kAlongCos, ay = alignment(y) >= kAlongCos;
            if (ax != ay) return ax;
            return x.score() < y.score() || (x.score() == y.score() && x.way < y.way);
        };
        const Cand* best = nullptr;
        for (const auto& c : cands)
            if (c.score() <= tol && (!best || better(c, *best))) best = &c;
        if (!best) {
            ++st.edgesUnmatched;
            continue;
        }
        ++st.edgesMatched;
        auto oriented = [&](const Cand& c) {
            const WaySeg& s = segs[c.midSeg];
            const OsmRoadTags& t = tags[ways[c.way].tags];
            return glm::dot(b - a, s.q - s.p) >= 0 ? t : t.reversed();
        };
        OsmRoadTags t = oriented(*best);
        if ((t.onlyForward() || t.onlyBackward()) && alignment(*best) >= kParallelCos) {
            const Cand* other = nullptr;
            OsmRoadTags u;
            for (const auto& c : cands) {
                if (&c == best || c.score() > mergeTol || alignment(c) < kParallelCos || (other && !better(c, *other)))
                    continue;
                OsmRoadTags o = oriented(c);
                if (t.onlyForward() ? o.onlyBackward() : o.onlyForward()) {
                    other = &c;
                    u = std::move(o);
                }
            }
            if (other) {
                ++st.edgesMergedOneWays;
                const OsmRoadTags& f = t.onlyForward() ? t : u;
                const OsmRoadTags& r = t.onlyForward() ? u : t;
                OsmRoadTags m;
                m.lanesForward = f.lanesForward;
                m.lanesBackward = r.lanesBackward;
                m.turnForward = f.turnForward;
                m.turnBackward = r.turnBackward;
                m.lanes = f.lanes + r.lanes;
                m.maxspeedKmh = t.maxspeedKmh > 0 ? t.maxspeedKmh : u.maxspeedKmh;
                m.width = f.width > 0 && r.width > 0 ? f.width + r.width : 0.0f;
                t = std::move(m);
            }
        }
        applyOsmRoadTags(t, e);
        widthTagged[i] = t.width > 0;
    }
    alignOneWayEdges(g, widthTagged);
}

// "74.3 m", "22.6 km".
std::string distance(double m) {
    std::ostringstream s;
    s.precision(3);
    if (m < 1000) s << m << " m";
    else s << m / 1000.0 << " km";
    return s.str();
}

// The largest city vista gen builds (paged above kMaxSingleFileSizeM).
double maxExtent_m() { return kMaxPagedSizeM; }

// The side of the city square that holds the roads' bounding box [lo, hi]
// (centred on the origin by placeFrame) with a margin: whole tiles, within
// size_m's range.
double extractCitySize(const OsmImport& out, const CityParams& params) {
    const double need = std::max(out.extentX_m, out.extentY_m) + 2.0 * kOsmExtentMargin_m;
    const double tile = std::isfinite(params.tile_size_m) && params.tile_size_m > 0 ? params.tile_size_m : 250.0;
    const double side = std::ceil(need / tile - 1e-9) * tile;
    return std::clamp(side, 100.0, kMaxPagedSizeM);
}

// ---- buildings ------------------------------------------------------------------

enum class RingFail { None, Missing, Outside, TooFew, TooSmall, SelfIntersecting };

struct RingRepairs {
    bool duplicates = false, unclosed = false, split = false;
    RingRepairs& operator|=(const RingRepairs& o) {
        duplicates |= o.duplicates;
        unclosed |= o.unclosed;
        split |= o.split;
        return *this;
    }
};

struct BuildingContext {
    GeoReference ref;
    glm::dvec3 median{0.0};
    double outlierRadius_m = 0;
    double half_m = 0;  // half the city side: footprints must lie inside the square
};

// One ring from its nodes (closed or not, in order) -> a simple counter-clockwise polygon.
RingFail makeRing(const std::vector<WayNode>& nodes, const BuildingContext& ctx, Polygon2& out, RingRepairs& rep) {
    for (const auto& n : nodes)
        if (!n.loc.valid()) return RingFail::Missing;
    std::vector<WayNode> d;
    for (const auto& n : nodes) {
        if (!d.empty() && (n.id == d.back().id || n.loc == d.back().loc)) {
            rep.duplicates = true;
            continue;
        }
        d.push_back(n);
    }
    if (d.size() >= 2 && (d.front().id == d.back().id || d.front().loc == d.back().loc)) d.pop_back();
    else if (d.size() >= 2) rep.unclosed = true;
    Polygon2 poly;
    for (auto& n : d) {
        const GeoPoint g{n.loc.lat(), n.loc.lon()};
        const glm::dvec3 v = unitVector(g);
        if (std::atan2(glm::length(glm::cross(v, ctx.median)), glm::dot(v, ctx.median)) * kEarthRadius_m >
            ctx.outlierRadius_m)
            return RingFail::Outside;
        poly.push_back(projectToLocal(ctx.ref, g));
    }
    if (poly.size() < 3) return RingFail::TooFew;
    bool split = false;
    Polygon2 r = makeSimpleRing(poly, split);
    if (r.empty())
        return poly.size() <= kMaxRepairRingNodes && std::abs(signedArea(poly)) < kOsmMinFootprintArea_m2
                   ? RingFail::TooSmall
                   : RingFail::SelfIntersecting;
    if (std::abs(signedArea(r)) < kOsmMinFootprintArea_m2) return RingFail::TooSmall;
    rep.split = split;
    out = std::move(r);
    return RingFail::None;
}

void countSkip(RingFail f, OsmBuildingStats& st) {
    switch (f) {
        case RingFail::Missing: ++st.missingNodes; break;
        case RingFail::Outside: ++st.outsideCity; break;
        case RingFail::TooFew: ++st.tooFewNodes; break;
        case RingFail::TooSmall: ++st.tooSmall; break;
        case RingFail::SelfIntersecting: ++st.selfIntersecting; break;
        case RingFail::None: break;
    }
}

bool insideCity(const Polygon2& r, double half) {
    for (const auto& p : r)
        if (!(std::abs(p.x) <= half && std::abs(p.y) <= half)) return false;
    return true;
}

// Joins member ways into rings by their end node ids (reversing ways as needed), in member
// order; a chain whose ends never meet comes back open (makeRing closes it).
std::vector<std::vector<WayNode>> assembleRings(std::vector<const std::vector<WayNode>*> parts) {
    std::vector<std::vector<WayNode>> rings;
    std::vector<char> used(parts.size(), 0);
    for (size_t i = 0; i < parts.size(); ++i) {
        if (used[i] || parts[i]->empty()) continue;
        used[i] = 1;
        std::vector<WayNode> ring = *parts[i];
        while (ring.size() < 2 || ring.front().id != ring.back().id) {
            bool found = false;
            for (size_t j = 0; j < parts.size() && !found; ++j) {
                if (used[j] || parts[j]->empty()) continue;
                const auto& p = *parts[j];
                if (p.front().id == ring.back().id) ring.insert(ring.end(), p.begin() + 1, p.end());
                else if (p.back().id == ring.back().id) ring.insert(ring.end(), p.rbegin() + 1, p.rend());
                else continue;
                used[j] = 1;
                found = true;
            }
            if (!found) break;
        }
        rings.push_back(std::move(ring));
    }
    return rings;
}

void addRepairs(const RingRepairs& r, OsmBuildingStats& st) {
    st.duplicateNodes += r.duplicates ? 1 : 0;
    st.unclosedRings += r.unclosed ? 1 : 0;
    st.selfIntersections += r.split ? 1 : 0;
}

// Footprints of the building ways (file order), then of the relations (file order).
void importBuildings(const std::vector<BuildingWay>& ways, const std::vector<BuildingRelation>& relations,
                     const BuildingContext& ctx, OsmImport& out) {
    OsmBuildingStats& st = out.buildingStats;
    st.enabled = true;
    std::unordered_map<NodeId, size_t> wayIndex;
    for (size_t i = 0; i < ways.size(); ++i) wayIndex.emplace(ways[i].id, i);
    std::unordered_set<NodeId> outerOfRelation;
    for (const auto& r : relations)
        for (const auto& [id, inner] : r.members)
            if (!inner) outerOfRelation.insert(id);
    auto accept = [&](OsmFootprint f, const RingRepairs& rep) {
        if (!insideCity(f.outer, ctx.half_m)) {
            ++st.outsideCity;
            return;
        }
        addRepairs(rep, st);
        ++st.imported;
        out.buildings.push_back(std::move(f));
    };
    for (const auto& w : ways) {
        if (!w.building || outerOfRelation.count(w.id)) continue;
        ++st.ways;
        ++st.candidates;
        OsmFootprint f = w.tags;
        f.source = BuildingSource::OsmWay;
        f.osm_id = w.id;
        RingRepairs rep;
        const RingFail fail = makeRing(w.nodes, ctx, f.outer, rep);
        if (fail != RingFail::None) {
            countSkip(fail, st);
            continue;
        }
        accept(std::move(f), rep);
    }
    for (const auto& r : relations) {
        ++st.relations;
        std::vector<const std::vector<WayNode>*> outerParts, innerParts;
        bool outerMissing = false;
        for (const auto& [id, inner] : r.members) {
            auto it = wayIndex.find(id);
            if (it == wayIndex.end()) {
                if (inner) ++st.innerRingsDropped;
                else outerMissing = true;
                continue;
            }
            (inner ? innerParts : outerParts).push_back(&ways[it->second].nodes);
        }
        if (outerMissing) {
            ++st.candidates;
            ++st.missingNodes;
            continue;
        }
        const auto outerRings = assembleRings(outerParts);
        if (outerRings.empty()) {
            ++st.candidates;
            ++st.noOuterRing;
            continue;
        }
        std::vector<OsmFootprint> made;
        std::vector<RingRepairs> reps;
        for (size_t k = 0; k < outerRings.size(); ++k) {
            ++st.candidates;
            OsmFootprint f = r.tags;
            f.source = BuildingSource::OsmRelation;
            f.osm_id = r.id;
            f.ring = uint32_t(k);
            RingRepairs rep;
            const RingFail fail = makeRing(outerRings[k], ctx, f.outer, rep);
            if (fail != RingFail::None) {
                countSkip(fail, st);
                continue;
            }
            made.push_back(std::move(f));
            reps.push_back(rep);
        }
        // Inner rings go to the first outer ring that holds them strictly inside, clear of its other holes.
        for (const auto& nodes : assembleRings(innerParts)) {
            Polygon2 hole;
            RingRepairs rep;
            bool placed = false;
            if (makeRing(nodes, ctx, hole, rep) == RingFail::None) {
                for (size_t k = 0; k < made.size() && !placed; ++k) {
                    if (!ringStrictlyInside(hole, made[k].outer)) continue;
                    bool clear = true;
                    for (const auto& h : made[k].holes) clear = clear && ringsDisjoint(hole, h);
                    if (!clear) continue;
                    std::reverse(hole.begin(), hole.end());  // clockwise
                    made[k].holes.push_back(hole);
                    reps[k] |= rep;
                    placed = true;
                }
            }
            if (!placed) ++st.innerRingsDropped;
        }
        for (size_t k = 0; k < made.size(); ++k) accept(std::move(made[k]), reps[k]);
    }
}

}  // namespace

std::string OsmImport::dropSummary() const {
    std::string nodes;
    auto add = [&](std::string& to, size_t count, const std::string& what) {
        if (count) to += (to.empty() ? "" : ", ") + std::to_string(count) + " " + what;
    };
    add(nodes, invalidNodes, "with invalid coordinates");
    add(nodes, missingNodes, "missing from the file");
    add(nodes, outlierNodes,
        std::string(outlierNodes == 1 ? "outlier" : "outliers") + " farther than " + distance(outlierRadius_m) +
            " from the median position");
    std::string out;
    const size_t total = invalidNodes + missingNodes + outlierNodes;
    if (total) out = "dropped " + std::to_string(total) + (total == 1 ? " node (" : " nodes (") + nodes + ")";
    if (clippedSegments) {
        auto km = [](double m) {
            char b[32];
            std::snprintf(b, sizeof b, m < 1000 ? "%.0f m" : "%.1f km", m < 1000 ? m : m / 1000.0);
            return std::string(b);
        };
        char pct[32];
        std::snprintf(pct, sizeof pct, "%.1f %%", roadLength_m > 0 ? 100.0 * keptLength_m / roadLength_m : 0.0);
        out += (out.empty() ? "" : "; ") + std::string("clipped the roads to the city square of size_m = ") +
               distance(2.0 * clipHalf_m) + ": kept " + km(keptLength_m) + " of " + km(roadLength_m) + " of road (" +
               pct + "); " + std::to_string(clippedSegments) + " of " + std::to_string(roadSegments) +
               " road segments cut or dropped, " + std::to_string(clippedWays) + " of " + std::to_string(roadWays) +
               " ways wholly outside";
    }
    if (tangledWays)
        out += (out.empty() ? "dropped " : "; dropped ") + std::to_string(tangledWays) +
               (tangledWays == 1 ? " way" : " ways") + " crossing itself more than " +
               std::to_string(kMaxSelfConflicts) + " times";
    return out;
}

namespace {

// Reads the node locations and highway ways of an OSM file, and with
// buildings its building ways and relations (relations first, so the second
// pass keeps their member ways). XML is read as text and scanned first: the
// ids of nodes whose coordinates it blanks go to `blanked`.
Status readOsm(const std::string& path, bool buildings, WayCollector& collector, RelationCollector& relationCollector,
               std::vector<NodeId>& blanked) {
    try {
        osmium::io::File file(path);
        const auto format = file.format();
        if (format != osmium::io::file_format::xml && format != osmium::io::file_format::pbf)
            return Status::error("OSM file '" + path + "': format '" + osmium::io::as_string(format) +
                                 "' is not supported (use .osm, .osm.gz, .osm.bz2 or .osm.pbf)");
        std::string xml;
        if (format == osmium::io::file_format::xml) {
            auto text = readXml(file, path);
            if (!text) return text.status();
            xml = std::move(*text);
            auto scan = sanitizeXml(xml, path);
            if (!scan) return scan.status();
            blanked = std::move(*scan);
            file = osmium::io::File(xml.data(), xml.size(), "osm");
        }
        collector.buildings = buildings;
        if (buildings) {  // first pass: the building relations, so the second keeps their member ways
            osmium::io::Reader relReader(file, osmium::osm_entity_bits::relation);
            osmium::apply(relReader, relationCollector);
            relReader.close();
            for (const auto& r : relationCollector.relations)
                for (const auto& m : r.members) collector.memberWays.insert(m.first);
        }
        osmium::io::Reader reader(file, osmium::osm_entity_bits::node | osmium::osm_entity_bits::way);
        Index index;
        LocationHandler locations(index);
        locations.ignore_errors();
        osmium::apply(reader, locations, collector);
        reader.close();
    } catch (const osmium::bzip2_error& e) {
        return Status::error("OSM file '" + path + "' could not be read: " + bzip2Problem(e));
    } catch (const std::exception& e) {
        return Status::error("OSM file '" + path + "' could not be read: " + e.what());
    }
    return Status::ok();
}

// Splits the ways at nodes without a valid location: invalid coordinates
// (blanked by the scan, or out of range in PBF) or missing; counts both.
std::vector<Way> dropUnlocatedNodes(std::vector<Way>&& collected, const std::vector<NodeId>& blanked, OsmImport& out) {
    std::set<NodeId> invalid, missing;
    std::vector<Way> ways = splitWays(std::move(collected), [&](const WayNode& n) {
        if (n.loc.valid()) return true;
        const bool bad = n.loc.is_defined() || std::binary_search(blanked.begin(), blanked.end(), n.id);
        (bad ? invalid : missing).insert(n.id);
        return false;
    });
    out.invalidNodes = invalid.size();
    out.missingNodes = missing.size();
    return ways;
}

// Splits the ways at outliers: nodes farther than the outlier radius (limit *
// sqrt(2): a city of the largest size never loses a node) from the median; counts them.
std::vector<Way> dropOutliers(std::vector<Way>&& located, const glm::dvec3& median, OsmImport& out) {
    std::set<NodeId> outliers;
    std::vector<Way> ways = splitWays(std::move(located), [&](const WayNode& n) {
        const glm::dvec3 v = unitVector(n.geo);
        if (std::atan2(glm::length(glm::cross(v, median)), glm::dot(v, median)) * kEarthRadius_m <= out.outlierRadius_m)
            return true;
        outliers.insert(n.id);
        return false;
    });
    out.outlierNodes = outliers.size();
    return ways;
}

// Places the frame: transverse Mercator about the centroid, moved to the
// centre of the bounding box (repeated: near a pole moving the reference
// turns the frame), rounded to 1e-7 deg. Projects every node into it (n.xy)
// and returns the reference; lo, hi: the nodes' bounding box.
GeoReference placeFrame(std::vector<Way>& ways, glm::dvec2& lo, glm::dvec2& hi) {
    glm::dvec3 sum(0.0);
    for (const auto& w : ways)
        for (const auto& n : w.nodes) sum += unitVector(n.geo);
    const GeoPoint centroid = fromUnitVector(glm::normalize(sum));
    GeoReference ref{centroid.lat_deg, centroid.lon_deg};
    auto bounds = [&] {
        lo = glm::dvec2(1e300);
        hi = glm::dvec2(-1e300);
        for (auto& w : ways)
            for (auto& n : w.nodes) {
                n.xy = projectToLocal(ref, n.geo);
                lo = glm::min(lo, n.xy);
                hi = glm::max(hi, n.xy);
            }
    };
    for (int pass = 0; pass < 10; ++pass) {
        bounds();
        const glm::dvec2 centre = 0.5 * (lo + hi);
        if (glm::length(centre) < 1e-3) break;
        const GeoPoint c = localToGeo(ref, centre);
        ref = {c.lat_deg, c.lon_deg};
    }
    ref = {roundTo1e7(ref.lat0_deg), roundTo1e7(ref.lon0_deg)};
    bounds();
    return ref;
}

// Refuses roads that span more than the largest city vista gen builds (`limit` metres).
Status checkExtent(const std::string& path, double limit, const OsmImport& out) {
    if (std::max(out.extentX_m, out.extentY_m) > limit) {
        std::string dropped = out.outlierNodes ? " after dropping " + std::to_string(out.outlierNodes) +
                                                     " outlier nodes farther than " + distance(out.outlierRadius_m) +
                                                     " from the median position"
                                               : "";
        return Status::error("OSM file '" + path + "': the roads span " + distance(out.extentX_m) + " east-west by " +
                             distance(out.extentY_m) + " north-south" + dropped +
                             ", more than the largest city vista gen builds (size_m up to " +
                             std::to_string(int(limit)) + " m = " + distance(limit) + "); crop the extract");
    }
    return Status::ok();
}

// Bounded planarization: simplifies the ways, drops ways tangled with
// themselves, refuses a tangle of many ways; returns the kept ways.
Result<std::vector<Way>> untangleWays(std::vector<Way>& ways, const CityParams& params, const std::string& path,
                                      const std::string& noRoads, OsmImport& out) {
    out.simplifiedNodes = simplify(ways, params.min_segment_m);
    std::set<NodeId> tangled;
    std::vector<Way> kept;
    for (size_t w = 0; w < ways.size(); ++w) {
        if (findConflictingEdges(segmentGraph(ways, w, w + 1), kMaxSelfConflicts + 1).size() > kMaxSelfConflicts)
            tangled.insert(ways[w].id);
        else kept.push_back(std::move(ways[w]));
    }
    out.tangledWays = tangled.size();
    if (kept.empty()) return Status::error(noRoads + "; " + out.dropSummary());
    if (findConflictingEdges(segmentGraph(kept, 0, kept.size()), kMaxConflicts + 1).size() > kMaxConflicts)
        return Status::error("OSM file '" + path +
                             "': the roads cross or touch each other away from shared nodes more than " +
                             std::to_string(kMaxConflicts) + " times; planarizing that many crossings is refused");
    return kept;
}

// Clips segment a-b to the square [-half, half]^2 (Liang-Barsky): 1 = whole
// inside, 2 = cut (a, b moved onto the border), 0 = outside.
int clipToSquare(glm::dvec2& a, glm::dvec2& b, double half) {
    const glm::dvec2 d = b - a;
    double t0 = 0.0, t1 = 1.0;
    const double p[4] = {-d.x, d.x, -d.y, d.y};
    const double q[4] = {a.x + half, half - a.x, a.y + half, half - a.y};
    for (int i = 0; i < 4; ++i) {
        if (p[i] == 0.0) {
            if (q[i] < 0.0) return 0;
            continue;
        }
        const double t = q[i] / p[i];
        if (p[i] < 0.0) t0 = std::max(t0, t);
        else t1 = std::min(t1, t);
    }
    if (t0 > t1) return 0;
    if (t0 == 0.0 && t1 == 1.0) return 1;
    const glm::dvec2 a0 = a;
    a = a0 + t0 * d;
    b = a0 + t1 * d;
    return 2;
}

// Planarizes the kept ways' segments into the street graph and gives its
// edges the road tags of the ways they come from.
Status buildStreets(const std::vector<Way>& kept, const WayCollector& collector, const CityParams& params,
                    const std::string& path, OsmImport& out) {
    std::vector<RawSegment> segs;
    const double half = 0.5 * out.citySize_m;
    out.clipHalf_m = half;
    out.roadWays = kept.size();
    for (size_t i = 0; i < kept.size(); ++i) {
        const Way& w = kept[i];
        const OsmRoadTags& t = collector.roadTags[w.tags];
        const uint32_t carriageway = t.onlyForward() || t.onlyBackward() ? uint32_t(i + 1) : 0u;
        bool inside = false;
        for (size_t k = 1; k < w.nodes.size(); ++k) {
            glm::dvec2 a = w.nodes[k - 1].xy, b = w.nodes[k].xy;
            ++out.roadSegments;
            out.roadLength_m += glm::length(b - a);
            const int clip = clipToSquare(a, b, half);
            if (clip != 1) ++out.clippedSegments;
            if (clip) {
                segs.push_back({a, b, w.cls, carriageway});
                out.keptLength_m += glm::length(b - a);
                inside = true;
            }
        }
        out.clippedWays += inside ? 0 : 1;
    }
    if (segs.empty())
        return Status::error("OSM file '" + path + "': no road lies inside the city square of size_m = " +
                             distance(out.citySize_m) + " about the data's centre");
    std::vector<uint32_t> carriageways;
    out.streets = planarize(segs, params.snap_radius_m, params.min_segment_m, &carriageways);
    if (out.streets.edges.empty())
        return Status::error("OSM file '" + path + "' has highway ways but none longer than min_segment_m = " +
                             std::to_string(params.min_segment_m) + " m");
    out.roadTagStats = collector.roadStats;
    const double snap = std::isfinite(params.snap_radius_m) ? std::max(params.snap_radius_m, 0.0) : 0.0;
    const double minSeg = std::isfinite(params.min_segment_m) ? std::max(params.min_segment_m, 0.0) : 0.0;
    assignRoadTags(out.streets, carriageways, kept, collector.roadTags, snap + minSeg + 1.0, snap + 1.0,
                   out.roadTagStats);
    straightenShortBends(out.streets);
    narrowSideBySide(out.streets);
    return Status::ok();
}

}  // namespace

Result<OsmImport> importOsm(const std::string& path, const CityParams& params, bool buildings, OsmExtent extent) {
    VISTA_RETURN_IF_ERROR(checkInputFile("OSM file", path, kMaxOsmFileBytes));
    OsmImport out;
    {
        std::ifstream in(path, std::ios::binary);
        if (!in) return Status::error("OSM file '" + path + "' cannot be opened");
        Hasher64 h;
        std::vector<unsigned char> buf(size_t(1) << 20);
        while (in) {
            in.read(reinterpret_cast<char*>(buf.data()), std::streamsize(buf.size()));
            if (in.gcount() > 0) h.update(buf.data(), size_t(in.gcount()));
        }
        if (in.bad()) return Status::error("OSM file '" + path + "' cannot be read");
        out.fileHash = h.finish();
    }
    const double limit = maxExtent_m();
    out.outlierRadius_m = limit * std::sqrt(2.0);
    WayCollector collector;
    RelationCollector relationCollector;
    std::vector<NodeId> blanked;
    if (Status read = readOsm(path, buildings, collector, relationCollector, blanked); !read) return read;
    const std::string noRoads = "OSM file '" + path + "' contains no usable highway=* ways (roads with node locations)";
    if (collector.ways.empty()) return Status::error(noRoads);

    std::vector<Way> ways = dropUnlocatedNodes(std::move(collector.ways), blanked, out);
    if (ways.empty()) return Status::error(noRoads);
    for (auto& w : ways)
        for (auto& n : w.nodes) n.geo = {n.loc.lat(), n.loc.lon()};
    const glm::dvec3 median = medianDirection(ways);
    ways = dropOutliers(std::move(ways), median, out);
    if (ways.empty()) return Status::error(noRoads);

    glm::dvec2 lo(0.0), hi(0.0);
    const GeoReference ref = placeFrame(ways, lo, hi);
    out.geo = ref;
    out.extentX_m = hi.x - lo.x;
    out.extentY_m = hi.y - lo.y;
    if (Status fits = checkExtent(path, limit, out); !fits) return fits;
    out.citySize_m = extent == OsmExtent::Extract ? extractCitySize(out, params) : params.size_m;

    if (buildings)
        importBuildings(collector.buildingWays, relationCollector.relations,
                        {ref, median, out.outlierRadius_m, 0.5 * out.citySize_m}, out);

    auto kept = untangleWays(ways, params, path, noRoads, out);
    if (!kept) return kept.status();
    if (Status streets = buildStreets(*kept, collector, params, path, out); !streets) return streets;
    return out;
}

}  // namespace vista
