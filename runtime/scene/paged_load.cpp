// Reading a paged city: manifest, region selection, merge. See paged_load.h.
#include "runtime/scene/paged_load.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <utility>

#include <unistd.h>

#include <nlohmann/json.hpp>
#include <osg/Group>

#include "citygen/regions.h"
#include "citygen/streets.h"
#include "foundation/number_text.h"
#include "foundation/input_file.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/scene_graph.h"

namespace vista {

namespace fs = std::filesystem;
using Json = nlohmann::json;

int PagedManifest::nonEmpty() const {
    int n = 0;
    for (const auto& r : regions) n += r.empty ? 0 : 1;
    return n;
}

bool isPagedCityPath(const std::string& path) {
    std::error_code ec;
    return !path.empty() && fs::is_directory(path, ec);
}

Status validatePagedRadius(const std::string& option, double value) {
    if (!std::isfinite(value) || value < kMinPagedRadiusM || value > kMaxPagedRadiusM) {
        std::ostringstream s;
        s << "option " << option << " = " << value << ": out of range (" << kMinPagedRadiusM << " .. "
          << kMaxPagedRadiusM << " metres)";
        return Status::error(s.str());
    }
    return Status::ok();
}

namespace {

// Field checks of manifest.json: each names the field (with `where`, e.g.
// "regions[3]: ") and the value as written, and states the allowed range.
// JSON integers only for counts and sizes: -5 or 1e3 is refused, never cast.
Status manifestField(const Json& obj, const char* field, const std::string& where) {
    if (!obj.is_object() || !obj.contains(field)) return Status::error(where + "field '" + field + "' is missing");
    return Status::ok();
}

Status manifestUnsigned(const Json& obj, const char* field, uint64_t lo, uint64_t hi, const std::string& where,
                        uint64_t& out) {
    VISTA_RETURN_IF_ERROR(manifestField(obj, field, where));
    const Json& v = obj[field];
    if (!v.is_number_unsigned() || v.get<uint64_t>() < lo || v.get<uint64_t>() > hi)
        return Status::error(where + "field '" + field + "' = " + echoText(v.dump()) +
                             " is out of range (an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                             "])");
    out = v.get<uint64_t>();
    return Status::ok();
}

Status manifestInt(const Json& obj, const char* field, int lo, int hi, const std::string& where, int& out) {
    uint64_t v = 0;
    VISTA_RETURN_IF_ERROR(manifestUnsigned(obj, field, uint64_t(lo), uint64_t(hi), where, v));
    out = int(v);
    return Status::ok();
}

Status manifestBool(const Json& obj, const char* field, const std::string& where, bool& out) {
    VISTA_RETURN_IF_ERROR(manifestField(obj, field, where));
    if (!obj[field].is_boolean())
        return Status::error(where + "field '" + field + "' = " + echoText(obj[field].dump()) +
                             " is not true or false");
    out = obj[field].get<bool>();
    return Status::ok();
}

// The grid, the regions' order and the regions' files against each other
// (readPagedManifest has read each field within its range): the grid is the
// one region_size_m makes of the city, region i is entry i at (i % regions_x,
// i / regions_x), no file is listed twice, and at least one region is not empty.
Status checkManifestRegions(const PagedManifest& m, const std::string& path) {
    const RegionGrid grid(m.params, m.regionSizeM);
    if (grid.countX() != m.regionsX || grid.countY() != m.regionsY)
        return Status::error("'" + path + "': fields 'regions_x'/'regions_y' = " + std::to_string(m.regionsX) + "/" +
                             std::to_string(m.regionsY) + " do not match region_size_m = " +
                             shortNumber(m.regionSizeM) + " over size_m = " + shortNumber(m.params.size_m) +
                             " (expected " + std::to_string(grid.countX()) + "/" + std::to_string(grid.countY()) + ")");
    std::map<std::string, int> files;
    for (size_t i = 0; i < m.regions.size(); ++i) {
        const PagedRegionEntry& r = m.regions[i];
        const std::string where = "'" + path + "': regions[" + std::to_string(i) + "]: ";
        if (size_t(r.region) != i) {
            const bool repeated = size_t(r.region) < i;
            return Status::error(
                where + "field 'region' = " + std::to_string(r.region) +
                (repeated ? " repeats regions[" + std::to_string(r.region) + "]'s" : " is out of order") +
                " (each region of the grid is listed once, in order: entry i is region i, 0 .. " +
                std::to_string(m.regions.size() - 1) + ")");
        }
        if (r.ix != r.region % m.regionsX || r.iy != r.region / m.regionsX)
            return Status::error(where + "fields 'ix'/'iy' = " + std::to_string(r.ix) + "/" + std::to_string(r.iy) +
                                 " do not match region " + std::to_string(r.region) + " (expected " +
                                 std::to_string(r.region % m.regionsX) + "/" + std::to_string(r.region / m.regionsX) +
                                 ": region = iy x regions_x + ix)");
        if (r.empty) continue;
        for (const std::string& name : {r.file, r.coarseFile}) {
            auto [it, added] = files.emplace(name, int(i));
            if (!added)
                return Status::error(where + "file '" + echoText(name) + "' is also listed by regions[" +
                                     std::to_string(it->second) + "] (each region has files of its own)");
        }
    }
    if (m.nonEmpty() == 0)
        return Status::error("'" + path + "': every region is 'empty': the manifest lists no region to load");
    return Status::ok();
}

}  // namespace

Result<PagedManifest> readPagedManifest(const std::string& dir) {
    const std::string path = (fs::path(dir) / kPagedManifestFile).string();
    if (::access(path.c_str(), F_OK) != 0)
        return Status::error("paged city '" + dir + "': cannot read '" + path +
                             "' (not a paged city from `vista gen -o DIR.paged`, or its run did not finish)");
    auto text = readInputFile("paged city manifest", path, kMaxManifestBytes);
    if (!text) return Status::error("paged city '" + dir + "': " + text.status().message());
    Json j = Json::parse(*text, nullptr, false);
    auto bad = [&](const std::string& why) { return Status::error("'" + path + "': " + why); };
    if (j.is_discarded() || !j.is_object()) return bad("not valid JSON (corrupt or truncated)");
    PagedManifest m;
    m.dir = dir;
    try {
        if (!j.contains("format") || j.at("format") != "vista.paged_city")
            return bad("field 'format' is not \"vista.paged_city\"");
        if (j.at("version") != kPagedCityVersion)
            return bad("field 'version' = " + j.at("version").dump() + " is not supported (expected " +
                       std::to_string(kPagedCityVersion) + "; generate the city again with this vista)");
        auto params = parseParamsJson(j.at("params").dump(), path + " (params)");
        if (!params) return params.status();
        m.params = *params;
        const Json& gen = j.at("generation");
        if (!gen.is_object() || !gen.contains("seed") || !gen.contains("key") || !gen.at("key").is_string() ||
            !gen.at("seed").is_number_unsigned())
            return bad("field 'generation' is not {\"seed\": N, \"key\": \"16 hex digits\"}");
        m.generation = gen.at("key").get<std::string>();
        if (m.generation.size() != 16 || m.generation.find_first_not_of("0123456789abcdef") != std::string::npos)
            return bad("field 'generation.key' = \"" + m.generation + "\" is not 16 hex digits");
        if (gen.at("seed").get<uint64_t>() != m.params.seed)
            return bad("field 'generation.seed' = " + gen.at("seed").dump() + " is not the params' seed " +
                       std::to_string(m.params.seed));
        VISTA_RETURN_IF_ERROR(manifestField(j, "region_size_m", "'" + path + "': "));
        if (!j["region_size_m"].is_number())
            return bad("field 'region_size_m' = " + echoText(j["region_size_m"].dump()) + " is not a number");
        m.regionSizeM = j["region_size_m"].get<double>();
        if (Status s = validateRegionSize(m.params, m.regionSizeM); !s) return bad(s.message());
        VISTA_RETURN_IF_ERROR(
            manifestInt(j, "regions_x", 1, kMaxManifestRegionsPerSide, "'" + path + "': ", m.regionsX));
        VISTA_RETURN_IF_ERROR(
            manifestInt(j, "regions_y", 1, kMaxManifestRegionsPerSide, "'" + path + "': ", m.regionsY));
        const Json& regions = j.at("regions");
        if (!regions.is_array() || regions.size() != size_t(m.regionsX) * size_t(m.regionsY))
            return bad("field 'regions' is not an array of regions_x * regions_y entries");
        const int last = int(regions.size()) - 1;
        for (const Json& e : regions) {
            PagedRegionEntry r;
            const std::string at = "'" + path + "': regions[" + std::to_string(m.regions.size()) + "]: ";
            VISTA_RETURN_IF_ERROR(manifestInt(e, "region", 0, last, at, r.region));
            VISTA_RETURN_IF_ERROR(manifestInt(e, "ix", 0, m.regionsX - 1, at, r.ix));
            VISTA_RETURN_IF_ERROR(manifestInt(e, "iy", 0, m.regionsY - 1, at, r.iy));
            VISTA_RETURN_IF_ERROR(manifestBool(e, "empty", at, r.empty));
            VISTA_RETURN_IF_ERROR(manifestUnsigned(e, "triangles", 0, kMaxManifestCount, at, r.triangles));
            const std::string where = "region " + std::to_string(r.region);
            if (!r.empty) {
                const Json& b = e.at("bounds");
                if (!b.is_array() || b.size() != 6) return bad(where + ": field 'bounds' is not 6 numbers");
                double v[6];
                for (int k = 0; k < 6; ++k) {
                    v[k] = b[size_t(k)].get<double>();
                    if (!std::isfinite(v[k])) return bad(where + ": field 'bounds' has a non-finite value");
                }
                r.lo = glm::dvec3(v[0], v[1], v[2]);
                r.hi = glm::dvec3(v[3], v[4], v[5]);
                if (!(r.lo.x <= r.hi.x && r.lo.y <= r.hi.y && r.lo.z <= r.hi.z))
                    return bad(where + ": field 'bounds' = " + echoText(b.dump()) +
                               " has a minimum above its maximum ([xmin, ymin, zmin, xmax, ymax, zmax])");
                VISTA_RETURN_IF_ERROR(manifestField(e, "files", at));
                if (!e["files"].is_array()) return bad(where + ": field 'files' is not a list");
                for (size_t k = 0; k < e["files"].size(); ++k) {
                    const Json& f = e["files"][k];
                    const std::string fat = at + "files[" + std::to_string(k) + "]: ";
                    VISTA_RETURN_IF_ERROR(manifestField(f, "role", fat));
                    const bool full = f["role"] == "full", coarse = f["role"] == "coarse";
                    if (!full && !coarse)
                        return Status::error(fat + "field 'role' = " + echoText(f["role"].dump()) +
                                             " is not \"full\" or \"coarse\"");
                    if (!(full ? r.file : r.coarseFile).empty())
                        return Status::error(fat + "a second file with role " + f["role"].dump());
                    VISTA_RETURN_IF_ERROR(manifestField(f, "name", fat));
                    if (!f["name"].is_string() || f["name"].get<std::string>().empty())
                        return Status::error(fat + "field 'name' = " + echoText(f["name"].dump()) +
                                             " is not a file name");
                    (full ? r.file : r.coarseFile) = f["name"].get<std::string>();
                    VISTA_RETURN_IF_ERROR(
                        manifestUnsigned(f, "bytes", 1, kMaxRegionFileBytes, fat, full ? r.bytes : r.coarseBytes));
                }
                if (r.file.empty()) return bad(where + ": no file with role 'full'");
                if (r.coarseFile.empty()) return bad(where + ": no file with role 'coarse'");
                for (const std::string& name : {r.file, r.coarseFile})
                    if (name.find('/') != std::string::npos || name.find('\\') != std::string::npos || name == ".." ||
                        name == ".")
                        return bad(where + ": file name '" + name + "' is not a plain name inside the directory");
            }
            m.regions.push_back(std::move(r));
        }
    } catch (const std::exception& ex) { return bad(std::string("missing or mistyped field (") + ex.what() + ")"); }
    VISTA_RETURN_IF_ERROR(checkManifestRegions(m, path));
    return m;
}

std::vector<int> selectPagedRegions(const PagedManifest& m, const std::vector<glm::dvec2>& points, double radiusM) {
    std::vector<int> out;
    const double r2 = radiusM * radiusM;
    for (size_t i = 0; i < m.regions.size(); ++i) {
        const PagedRegionEntry& r = m.regions[i];
        if (r.empty) continue;
        for (const glm::dvec2& p : points) {
            const double dx = std::max({r.lo.x - p.x, 0.0, p.x - r.hi.x});
            const double dy = std::max({r.lo.y - p.y, 0.0, p.y - r.hi.y});
            if (dx * dx + dy * dy <= r2) {
                out.push_back(int(i));
                break;
            }
        }
    }
    return out;
}

std::vector<int> selectCoarseRegions(const PagedManifest& m, const std::vector<glm::dvec2>& points, double farM,
                                     const std::vector<int>& full) {
    std::vector<int> out;
    if (!(farM > 0)) return out;
    std::vector<char> isFull(m.regions.size(), 0);
    for (int i : full)
        if (i >= 0 && size_t(i) < isFull.size()) isFull[size_t(i)] = 1;
    for (int i : selectPagedRegions(m, points, farM))
        if (!isFull[size_t(i)]) out.push_back(i);
    return out;
}

Result<SceneModel> loadPagedRegion(const PagedManifest& m, int i, bool coarse, bool* foreign) {
    if (i < 0 || size_t(i) >= m.regions.size() || m.regions[size_t(i)].empty)
        return Status::error("paged city '" + m.dir + "': no non-empty region " + std::to_string(i));
    const PagedRegionEntry& r = m.regions[size_t(i)];
    const std::string& name = coarse ? r.coarseFile : r.file;
    const uint64_t bytes = coarse ? r.coarseBytes : r.bytes;
    const std::string path = (fs::path(m.dir) / name).string();
    std::error_code ec;
    const uint64_t size = fs::file_size(path, ec);
    if (ec)
        return Status::error("paged city '" + m.dir + "': region file '" + path + "' is missing or unreadable (" +
                             ec.message() + ")");
    if (size != bytes)
        return Status::error("paged city '" + m.dir + "': region file '" + path + "' has " + std::to_string(size) +
                             " bytes, the manifest says " + std::to_string(bytes) + " (damaged or from another run)");
    auto model = loadCityFile(path);
    if (!model) return model;
    // The generation's identity: a file of another generation (two writers mixed in one
    // directory) is refused, not drawn.
    std::string key, seed;
    const osg::Node* root = sceneRoot(*model);
    if (!root || !root->getUserValue(kPagedGenerationKey, key)) key = "none";
    if (!root || !root->getUserValue(kPagedSeedKey, seed)) seed = "none";
    if (key != m.generation || seed != std::to_string(m.params.seed)) {
        if (foreign) *foreign = true;
        return Status::error("paged city '" + m.dir + "': region file '" + path + "' is of another generation (seed " +
                             seed + ", key " + key + ") than its manifest '" +
                             (fs::path(m.dir) / kPagedManifestFile).string() + "' (seed " +
                             std::to_string(m.params.seed) + ", key " + m.generation +
                             "): regions of different runs are mixed in the directory; generate the city again");
    }
    return model;
}

namespace {

// Appends `b`'s streets to `a`, merging nodes by exact position and edges by end nodes.
struct StreetUnion {
    StreetGraph g;
    std::map<std::pair<double, double>, uint32_t> nodeIndex;
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> edgeIndex;
    void add(const StreetGraph& b) {
        std::vector<uint32_t> remap(b.nodes.size());
        for (size_t n = 0; n < b.nodes.size(); ++n) {
            auto [it, fresh] = nodeIndex.emplace(std::make_pair(b.nodes[n].x, b.nodes[n].y), uint32_t(g.nodes.size()));
            if (fresh) g.nodes.push_back(b.nodes[n]);
            remap[n] = it->second;
        }
        for (const StreetEdge& e : b.edges) {
            if (e.a >= remap.size() || e.b >= remap.size()) continue;
            StreetEdge x = e;
            x.a = remap[e.a];
            x.b = remap[e.b];
            const auto key = std::make_pair(std::min(x.a, x.b), std::max(x.a, x.b));
            if (edgeIndex.emplace(key, uint32_t(g.edges.size())).second) g.edges.push_back(x);
        }
    }
};

}  // namespace

Result<SceneModel> loadPagedCity(const PagedManifest& m, const std::vector<int>& regions, double radiusM,
                                 PagedLoadReport* report, const std::vector<int>& coarse) {
    if (regions.empty())
        return Status::error("paged city '" + m.dir + "': no region within --paged-radius " + std::to_string(radiusM) +
                             " m of the walkthrough (" + std::to_string(m.nonEmpty()) + " non-empty regions)");
    PagedLoadReport rep;
    rep.regionsTotal = m.nonEmpty();
    rep.radiusM = radiusM;
    SceneModel out;
    osg::ref_ptr<osg::Group> root = new osg::Group;
    root->setName("vista.city");
    StreetUnion streets;
    bool first = true, foreign = false;
    std::vector<std::pair<int, bool>> order;  // (region, coarse): full regions first
    for (int i : regions) order.emplace_back(i, false);
    const size_t fullCount = order.size();
    for (size_t k = 0;; ++k) {
        if (k == fullCount) {
            // Every full region tried (damaged ones' fallbacks after them): then the far city, if one loaded.
            if (first) break;
            for (int i : coarse) order.emplace_back(i, true);
        }
        if (k >= order.size()) break;
        const auto [i, isCoarse] = order[k];
        if (i < 0 || size_t(i) >= m.regions.size() || m.regions[size_t(i)].empty) continue;
        const std::string& name = isCoarse ? m.regions[size_t(i)].coarseFile : m.regions[size_t(i)].file;
        auto rm = loadPagedRegion(m, i, isCoarse, &foreign);
        if (!rm && foreign) return rm.status();  // a region of another generation: the directory is refused
        if (!rm) {
            // A damaged or missing region file: reported by name, the rest of the city loads;
            // a full region falls back to its coarse level.
            rep.damaged.push_back(rm.status().message());
            if (!isCoarse) order.emplace_back(i, true);
            continue;
        }
        SceneModel& r = *rm;
        osg::Group* rroot = sceneRoot(r) ? sceneRoot(r)->asGroup() : nullptr;
        if (!rroot) return Status::error("region file '" + m.regions[size_t(i)].file + "' has no scene graph");
        if (first) {
            out.params = r.params;
            out.prototypes = std::move(r.prototypes);
            root->setStateSet(rroot->getStateSet());
            for (const char* key : {"vista.format", "vista.tree_prototypes"}) {
                int v = 0;
                if (rroot->getUserValue(key, v)) root->setUserValue(key, v);
            }
            for (const char* key : {"vista.origin_x", "vista.origin_y", "vista.tile_size_m"}) {
                double v = 0;
                if (rroot->getUserValue(key, v)) root->setUserValue(key, v);
            }
            std::string params;
            if (rroot->getUserValue("vista.params", params)) root->setUserValue("vista.params", params);
            first = false;
        } else if (r.prototypes.size() == out.prototypes.size()) {
            for (size_t p = 0; p < out.prototypes.size(); ++p)
                if (out.prototypes[p].indices.empty() && !r.prototypes[p].indices.empty())
                    out.prototypes[p] = std::move(r.prototypes[p]);
        } else if (!isCoarse) {
            return Status::error("region file '" + name + "': " + std::to_string(r.prototypes.size()) +
                                 " tree prototypes, the first region has " + std::to_string(out.prototypes.size()) +
                                 " (regions of different cities)");
        } else {
            // A coarse level with its own (or no) tree shapes: appended, its instances renumbered.
            const uint32_t base = uint32_t(out.prototypes.size());
            for (SceneMesh& p : r.prototypes) out.prototypes.push_back(std::move(p));
            for (SceneInstance& in : r.instances) in.prototype += base;
            for (SceneInstance& im : r.impostors) im.prototype += base;
        }
        SceneRegionSpan span;
        span.region = i;
        span.coarse = isCoarse;
        span.firstTile = uint32_t(out.tiles.size());
        span.tileCount = uint32_t(r.tiles.size());
        span.firstImpostor = uint32_t(out.impostors.size());
        span.impostorCount = uint32_t(r.impostors.size());
        out.regions.push_back(span);
        const uint32_t meshBase = uint32_t(out.meshes.size()), instBase = uint32_t(out.instances.size());
        for (SceneMesh& mesh : r.meshes) {
            mesh.ids.clear();
            mesh.ids.shrink_to_fit();
            out.meshes.push_back(std::move(mesh));
        }
        for (SceneInstance& in : r.instances) {
            in.id = 0;
            out.instances.push_back(in);
        }
        for (const SceneInstance& im : r.impostors) out.impostors.push_back(im);
        for (SceneTile& t : r.tiles) {
            osg::Node* child = rroot->getChild(t.child);
            t.child = root->getNumChildren();
            root->addChild(child);
            for (uint32_t& k : t.meshes) k += meshBase;
            for (uint32_t& k : t.instances) k += instBase;
            out.tiles.push_back(std::move(t));
        }
        out.triangles += r.triangles;
        streets.add(r.streets);
        const uint64_t bytes = isCoarse ? m.regions[size_t(i)].coarseBytes : m.regions[size_t(i)].bytes;
        if (isCoarse) {
            ++rep.coarseLoaded;
            rep.coarseBytes += bytes;
        } else {
            ++rep.regionsLoaded;
        }
        rep.bytesLoaded += bytes;
        rep.files.push_back(name);
    }
    if (first) {
        std::string why = "paged city '" + m.dir + "': no region near the walkthrough could be read";
        for (const std::string& d : rep.damaged) why += "; " + d;
        return Status::error(why);
    }
    for (SceneMesh& p : out.prototypes) p.ids.clear();
    out.streets = std::move(streets.g);
    root->setUserValue("vista.streets", streetGraphToJson(out.streets));
    out.labelled = false;
    setSceneRoot(out, root.get());
    if (report) *report = std::move(rep);
    return out;
}

Result<StreetGraph> pagedPathStreets(const PagedManifest& m) {
    // The street graph of a city depends only on its params (paged cities are
    // never imported from OSM); growing it is cheap (the 64 km city: 21,475
    // edges, about a second), so the path is the single-file city's path.
    return growStreets(m.params, nullptr);
}

}  // namespace vista
