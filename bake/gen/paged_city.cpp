// The paged city writer: regions (citygen/regions.h) as city files, their
// records (resume), the PagedLOD index and the manifest. See paged_city.h.
#include "bake/gen/paged_city.h"
#include "foundation/format.h"

#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>
#include <osg/ComputeBoundsVisitor>
#include <osg/Group>
#include <osg/PagedLOD>

#include "citygen/generate.h"
#include "citygen/opendrive.h"
#include "citygen/regions.h"
#include "foundation/atomic_file.h"
#include "foundation/hash.h"
#include "runtime/scene/scene_file.h"
#include "runtime/scene/scene_graph.h"

namespace vista {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

namespace {

constexpr int kPagedFormatVersion = kPagedCityVersion;

double seconds(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Size and content hash (hashBytes64) of a file, streamed; false if unreadable.
bool hashFile(const std::string& path, uint64_t& bytes, uint64_t& hash) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return false;
    Hasher64 h;
    std::vector<unsigned char> buf(1 << 20);
    bytes = 0;
    while (in) {
        in.read(reinterpret_cast<char*>(buf.data()), std::streamsize(buf.size()));
        const std::streamsize n = in.gcount();
        if (n <= 0) break;
        h.update(buf.data(), size_t(n));
        bytes += uint64_t(n);
    }
    if (in.bad()) return false;
    hash = h.finish();
    return true;
}

std::string recordPath(const std::string& dir, int ix, int iy) {
    return (fs::path(dir) / "records" / ("region_" + std::to_string(ix) + "_" + std::to_string(iy) + ".json")).string();
}

// The record of region r if it is present, for these params (key) and every
// file it lists has the recorded size and hash.
std::optional<Json> validRecord(const std::string& dir, const RegionGrid& grid, int r, const std::string& key) {
    std::ifstream in(recordPath(dir, grid.ix(r), grid.iy(r)), std::ios::binary);
    if (!in) return std::nullopt;
    std::stringstream ss;
    ss << in.rdbuf();
    Json j = Json::parse(ss.str(), nullptr, false);
    if (j.is_discarded() || !j.is_object()) return std::nullopt;
    try {
        if (j.at("key").get<std::string>() != key || j.at("region").get<int>() != r) return std::nullopt;
        if (j.at("ix").get<int>() != grid.ix(r) || j.at("iy").get<int>() != grid.iy(r)) return std::nullopt;
        const bool empty = j.at("empty").get<bool>();
        const Json& files = j.at("files");
        if (!files.is_array() || files.size() != (empty ? 0u : 2u)) return std::nullopt;
        for (const Json& f : files) {
            const std::string name = f.at("name").get<std::string>();
            if (name.find('/') != std::string::npos) return std::nullopt;
            uint64_t bytes = 0, hash = 0;
            if (!hashFile((fs::path(dir) / name).string(), bytes, hash)) return std::nullopt;
            if (bytes != f.at("bytes").get<uint64_t>() || hex64(hash) != f.at("hash").get<std::string>())
                return std::nullopt;
        }
        if (!empty && (!j.at("bounds").is_array() || j.at("bounds").size() != 6)) return std::nullopt;
    } catch (const std::exception&) { return std::nullopt; }
    return j;
}

Result<Json> fileEntry(const std::string& dir, const std::string& role, const std::string& name) {
    uint64_t bytes = 0, hash = 0;
    const std::string path = (fs::path(dir) / name).string();
    if (!hashFile(path, bytes, hash)) return Status::error("cannot read back '" + path + "': " + errnoText());
    Json f;
    f["role"] = role;
    f["name"] = name;
    f["bytes"] = bytes;
    f["hash"] = hex64(hash);
    return f;
}

// Generates region r, writes its files and then its record; returns the record.
// The generation's identity on a region file's root (paged_load.h checks it against the manifest).
void markGeneration(osg::Node& scene, const CityParams& params, const std::string& key) {
    scene.setUserValue(kPagedGenerationKey, key);
    scene.setUserValue(kPagedSeedKey, std::to_string(params.seed));
}

Result<Json> generateRegion(const RegionalCity& base, int r, const std::string& dir, const std::string& key,
                            const CityParams& params) {
    const RegionGrid& grid = base.grid();
    const int ix = grid.ix(r), iy = grid.iy(r);
    City c = base.region(r);
    const CityCounts n = countCity(c);
    Json rec;
    rec["key"] = key;
    rec["region"] = r;
    rec["ix"] = ix;
    rec["iy"] = iy;
    rec["empty"] = c.tiles.empty();
    rec["buildings"] = c.buildings.size();
    rec["trees"] = c.trees.size();
    rec["triangles"] = n.triangles;
    rec["files"] = Json::array();
    const std::string full = regionFileName(ix, iy), coarse = coarseFileName(ix, iy);
    if (c.tiles.empty()) {
        std::error_code ec;  // files of an earlier run with other params
        fs::remove(fs::path(dir) / full, ec);
        fs::remove(fs::path(dir) / coarse, ec);
    } else {
        osg::BoundingBox box;
        {
            osg::ref_ptr<osg::Node> scene = buildCityScene(c);
            markGeneration(*scene, params, key);
            osg::ComputeBoundsVisitor cbv;
            scene->accept(cbv);
            box = cbv.getBoundingBox();
            VISTA_RETURN_IF_ERROR(writeSceneFile(*scene, (fs::path(dir) / full).string(), false));
        }
        {
            City k = RegionalCity::coarse(c);
            c = City();
            osg::ref_ptr<osg::Node> scene = buildCityScene(k);
            markGeneration(*scene, params, key);
            osg::ComputeBoundsVisitor cbv;  // the impostors' quads may reach beyond the trees' meshes
            scene->accept(cbv);
            box.expandBy(cbv.getBoundingBox());
            VISTA_RETURN_IF_ERROR(writeSceneFile(*scene, (fs::path(dir) / coarse).string(), false));
        }
        rec["bounds"] = {box.xMin(), box.yMin(), box.zMin(), box.xMax(), box.yMax(), box.zMax()};
        for (auto [role, name] : {std::pair<const char*, std::string>{"full", full}, {"coarse", coarse}}) {
            auto f = fileEntry(dir, role, name);
            if (!f) return f.status();
            rec["files"].push_back(*f);
        }
    }
    VISTA_RETURN_IF_ERROR(writeFileAtomic(recordPath(dir, ix, iy), rec.dump(2) + "\n"));
    return rec;
}

osg::ref_ptr<osg::Node> buildIndex(const CityParams& params, const RegionGrid& grid, double regionSize,
                                   const std::vector<Json>& records) {
    osg::ref_ptr<osg::Group> root = new osg::Group;
    root->setName("vista.paged_city");
    root->setUserValue("vista.format", kPagedFormatVersion);
    root->setUserValue("vista.params", paramsToJson(params));
    root->setUserValue("vista.region_size_m", regionSize);
    root->setUserValue("vista.regions_x", grid.countX());
    root->setUserValue("vista.regions_y", grid.countY());
    root->setUserValue("vista.origin_x", params.origin_x);
    root->setUserValue("vista.origin_y", params.origin_y);
    for (const Json& rec : records) {
        if (rec.at("empty").get<bool>()) continue;
        const auto& b = rec.at("bounds");
        const osg::Vec3d lo(b[0].get<double>(), b[1].get<double>(), b[2].get<double>());
        const osg::Vec3d hi(b[3].get<double>(), b[4].get<double>(), b[5].get<double>());
        const double radius = 0.5 * (hi - lo).length();
        double fullRange = 0, coarseRange = 0;
        pagedRanges(regionSize, params.size_m, radius, fullRange, coarseRange);
        osg::ref_ptr<osg::PagedLOD> lod = new osg::PagedLOD;
        const int ix = rec.at("ix").get<int>(), iy = rec.at("iy").get<int>();
        lod->setName("region_" + std::to_string(ix) + "_" + std::to_string(iy));
        lod->setCenterMode(osg::LOD::USER_DEFINED_CENTER);
        lod->setCenter(osg::Vec3((lo + hi) * 0.5));
        lod->setRadius(float(radius));
        lod->setRangeMode(osg::LOD::DISTANCE_FROM_EYE_POINT);
        lod->setFileName(0, coarseFileName(ix, iy));
        lod->setRange(0, float(fullRange), float(coarseRange));
        lod->setFileName(1, regionFileName(ix, iy));
        lod->setRange(1, 0.0f, float(fullRange));
        root->addChild(lod.get());
    }
    return root;
}

Json manifestJson(const CityParams& params, const RegionGrid& grid, double regionSize, const std::vector<Json>& records,
                  const std::string& key) {
    Json m;
    m["format"] = "vista.paged_city";
    m["version"] = kPagedFormatVersion;
    m["generation"] = {{"seed", params.seed}, {"key", key}};
    m["params"] = Json::parse(paramsToJson(params));
    m["region_size_m"] = regionSize;
    m["tile_size_m"] = params.tile_size_m;
    m["regions_x"] = grid.countX();
    m["regions_y"] = grid.countY();
    m["index"] = kPagedIndexFile;
    size_t buildings = 0, trees = 0, triangles = 0, bytes = 0, nonEmpty = 0;
    Json regions = Json::array();
    for (const Json& rec : records) {
        Json e;
        for (const char* k : {"region", "ix", "iy", "empty", "buildings", "trees", "triangles"}) e[k] = rec.at(k);
        buildings += rec.at("buildings").get<size_t>();
        trees += rec.at("trees").get<size_t>();
        triangles += rec.at("triangles").get<size_t>();
        if (!rec.at("empty").get<bool>()) {
            ++nonEmpty;
            e["bounds"] = rec.at("bounds");
            const auto& b = rec.at("bounds");
            const double radius = 0.5 * std::sqrt(std::pow(b[3].get<double>() - b[0].get<double>(), 2) +
                                                  std::pow(b[4].get<double>() - b[1].get<double>(), 2) +
                                                  std::pow(b[5].get<double>() - b[2].get<double>(), 2));
            double fullRange = 0, coarseRange = 0;
            pagedRanges(regionSize, params.size_m, double(float(radius)), fullRange, coarseRange);
            e["full_range_m"] = double(float(fullRange));
            e["coarse_range_m"] = double(float(coarseRange));
            e["files"] = rec.at("files");
            for (const Json& f : rec.at("files")) bytes += f.at("bytes").get<size_t>();
        }
        regions.push_back(std::move(e));
    }
    m["totals"] = {{"regions", records.size()}, {"non_empty_regions", nonEmpty},
                   {"buildings", buildings},    {"trees", trees},
                   {"triangles", triangles},    {"bytes", bytes}};
    m["regions"] = std::move(regions);
    return m;
}

// The merge's refusal: how many regions are missing (the first few by name,
// each with the shard K/N that owns it) and which shards to run again: K/N
// for each and the command that runs them, when the merge knows the N the
// shards ran with, otherwise how regions map to shards.
Status missingRegionsError(const PagedCityOptions& o, const RegionGrid& grid, const std::vector<int>& missing) {
    const int n = o.mergeShards;
    auto shardName = [&](int k) { return std::to_string(k + 1) + "/" + std::to_string(n); };
    std::string names;
    for (size_t i = 0; i < missing.size() && i < 8; ++i) {
        names += (i ? ", " : "") + regionFileName(grid.ix(missing[i]), grid.iy(missing[i]));
        if (n >= 1) names += " (shard " + shardName(missing[i] % n) + ")";
    }
    if (missing.size() > 8) names += ", ...";
    std::string msg = "--merge: " + std::to_string(missing.size()) + " of " + std::to_string(grid.count()) +
                      " regions of '" + o.dir + "' are missing, corrupt or from other parameters (" + names + "); ";
    if (n < 1)
        return Status::error(msg + "run the shards that own them again (--shard K/N owns the regions whose index " +
                             "IY * " + std::to_string(grid.countX()) + " + IX satisfies index % N == K - 1; " +
                             "--merge --shards N names them)");
    std::vector<bool> rerun(size_t(n), false);
    for (int r : missing) rerun[size_t(r % n)] = true;
    std::string shards;
    int count = 0, first = -1;
    for (int k = 0; k < n; ++k) {
        if (!rerun[size_t(k)]) continue;
        if (first < 0) first = k;
        if (++count <= 20) shards += (count > 1 ? ", " : "") + shardName(k);
    }
    if (count > 20) shards += ", ...";
    msg += "run " + (count == 1 ? std::string("shard ") : std::to_string(count) + " shards ") + shards + " again";
    if (o.shardCommand.empty()) return Status::error(msg + " (--shard K/N with the same parameters), then the merge");
    if (count == 1) return Status::error(msg + ": " + o.shardCommand + " " + shardName(first) + "; then the merge");
    return Status::error(msg + ", each with: " + o.shardCommand + " K/" + std::to_string(n) + "; then the merge");
}

}  // namespace

std::string regionFileName(int ix, int iy) {
    return "region_" + std::to_string(ix) + "_" + std::to_string(iy) + ".osgb";
}
std::string coarseFileName(int ix, int iy) {
    return "region_" + std::to_string(ix) + "_" + std::to_string(iy) + ".coarse.osgb";
}

void pagedRanges(double regionSizeM, double citySizeM, double radius, double& fullRange, double& coarseRange) {
    fullRange = radius + regionSizeM;
    // osgviewer's home view stands 3.5 bounding radii from the centre: small
    // cities show their coarse level from there.
    const double home = 4.0 * 0.5 * std::sqrt(2.0) * citySizeM;
    coarseRange = radius + std::min(std::max(6.0 * regionSizeM, home), 16.0 * regionSizeM);
}

Status checkPagedOutput(const std::string& option, const std::string& dir) {
    std::error_code ec;
    const auto st = fs::status(dir, ec);
    if (fs::exists(st) && !fs::is_directory(st))
        return Status::error("option " + option + " = '" + dir +
                             "': exists and is not a directory (a paged city is a directory)");
    return checkWritableDirectory(option, dir);
}

// Adds one region record's counts (empty, buildings, trees, triangles, file bytes) to the report.
static void addRegionTotals(PagedCityReport& rep, const Json& rec) {
    rep.emptyRegions += rec.at("empty").get<bool>() ? 1 : 0;
    rep.buildings += rec.at("buildings").get<size_t>();
    rep.trees += rec.at("trees").get<size_t>();
    rep.triangles += rec.at("triangles").get<size_t>();
    for (const Json& f : rec.at("files")) rep.bytes += f.at("bytes").get<size_t>();
}

Result<PagedCityReport> generatePagedCity(const CityParams& params, const PagedCityOptions& o) {
    VISTA_RETURN_IF_ERROR(validateParams(params));
    VISTA_RETURN_IF_ERROR(validateRegionSize(params, o.regionSizeM));
    if (o.shard.count < 1 || o.shard.index < 0 || o.shard.index >= o.shard.count)
        return Status::error("shard " + std::to_string(o.shard.index) + "/" + std::to_string(o.shard.count) +
                             " out of range");
    VISTA_RETURN_IF_ERROR(checkPagedOutput("-o", o.dir));
    std::error_code ec;
    CreatedDirectories made;  // removed again if the run leaves them empty
    if (!o.merge)             // a merge only reads (and writes index and manifest once every region is there)
        VISTA_RETURN_IF_ERROR(made.create("-o", (fs::path(o.dir) / "records").string()));

    const RegionGrid grid(params, o.regionSizeM);
    const std::string keyText = paramsToJson(params) + "\nregion_size_m=" + exactDecimal(o.regionSizeM) +
                                "\nformat=" + std::to_string(kPagedFormatVersion) + "\ncoarse_trees=impostors" +
                                "\nsignals=lane_model" +  // regions of runs whose tiles had no signals are remade
                                (o.inputKey.empty() ? std::string() : "\ninput=" + o.inputKey);
    const std::string key = hex64(hashBytes64(keyText.data(), keyText.size()));
    PagedCityReport rep;
    rep.regions = grid.count();
    std::vector<std::optional<Json>> records(size_t(grid.count()));
    std::optional<RegionalCity> base;
    Progress* pr = o.progress;
    const auto t0 = std::chrono::steady_clock::now();
    double baseSeconds = 0;
    if (!o.merge) {
        std::vector<int> todo;
        for (int r = 0; r < grid.count(); ++r) {
            if (r % o.shard.count != o.shard.index) continue;
            records[size_t(r)] = validRecord(o.dir, grid, r, key);
            if (records[size_t(r)]) {
                ++rep.reused;
                continue;
            }
            if (fs::exists(recordPath(o.dir, grid.ix(r), grid.iy(r)), ec) ||
                fs::exists(fs::path(o.dir) / regionFileName(grid.ix(r), grid.iy(r)), ec))
                ++rep.regenerated;
            todo.push_back(r);
        }
        if (!todo.empty()) {
            const auto tb = std::chrono::steady_clock::now();
            auto b = RegionalCity::create(params, o.regionSizeM, pr, o.inputs);
            if (!b) return b.status();
            base.emplace(std::move(*b));
            baseSeconds = seconds(tb);
            rep.streetEdges = base->streets().edges.size();
            rep.blocks = base->blockCount();
            if (pr) pr->begin("regions (" + std::to_string(todo.size()) + " of " + std::to_string(grid.count()) + ")");
            for (size_t k = 0; k < todo.size(); ++k) {
                auto rec = generateRegion(*base, todo[k], o.dir, key, params);
                if (!rec) {
                    if (pr) pr->end();
                    return rec.status();
                }
                records[size_t(todo[k])] = std::move(*rec);
                ++rep.generated;
                if (pr) pr->update(double(k + 1) / double(todo.size()));
            }
            if (pr) pr->end();
        }
    }
    rep.baseSeconds = baseSeconds;
    rep.regionSeconds = seconds(t0) - baseSeconds;
    for (const auto& rec : records)
        if (rec) addRegionTotals(rep, *rec);
    made.keep();
    if (o.shard.count > 1 && !o.merge) return rep;

    const auto ti = std::chrono::steady_clock::now();
    std::vector<Json> all;
    std::vector<int> missingRegions;
    for (int r = 0; r < grid.count(); ++r) {
        if (!records[size_t(r)]) records[size_t(r)] = validRecord(o.dir, grid, r, key);
        if (!records[size_t(r)]) {
            missingRegions.push_back(r);
            continue;
        }
        all.push_back(*records[size_t(r)]);
    }
    if (!missingRegions.empty()) return missingRegionsError(o, grid, missingRegions);
    osg::ref_ptr<osg::Node> index = buildIndex(params, grid, o.regionSizeM, all);
    OutputBatch own;
    OutputBatch& batch = o.batch ? *o.batch : own;
    VISTA_RETURN_IF_ERROR(writeSceneFile(*index, batch.stage((fs::path(o.dir) / kPagedIndexFile).string()), false));
    Json manifest = manifestJson(params, grid, o.regionSizeM, all, key);
    if (o.inputs.streets) {  // readers cannot grow given streets again: the graph travels beside the regions
        VISTA_RETURN_IF_ERROR(writeFileAtomic(batch.stage((fs::path(o.dir) / kPagedStreetsFile).string()),
                                              streetGraphToJson(*o.inputs.streets)));
        manifest["streets"] = kPagedStreetsFile;
    }
    VISTA_RETURN_IF_ERROR(
        writeFileAtomic(batch.stage((fs::path(o.dir) / kPagedManifestFile).string()), manifest.dump(2) + "\n"));
    rep.indexSeconds = seconds(ti);
    if (!o.xodr.empty()) {  // the whole road network; a run that reused every region grows the streets again
        const auto tx = std::chrono::steady_clock::now();
        if (!base) {
            auto b = RegionalCity::create(params, o.regionSizeM, pr, o.inputs);
            if (!b) return b.status();
            base.emplace(std::move(*b));
        }
        auto text = openDriveXml(base->streets(), params, &base->blocks(), &rep.roads);
        if (!text) return Status::error("option --xodr = '" + o.xodr + "': " + text.status().message());
        VISTA_RETURN_IF_ERROR(writeFileAtomic(batch.stage(o.xodr), *text));
        rep.xodrWritten = true;
        rep.xodrSeconds = seconds(tx);
    }
    if (!o.batch) VISTA_RETURN_IF_ERROR(own.commit());
    rep.indexWritten = true;
    if (o.merge) {  // totals over the whole city
        rep.emptyRegions = 0;
        rep.buildings = rep.trees = rep.triangles = rep.bytes = 0;
        for (const Json& rec : all) addRegionTotals(rep, rec);
    }
    return rep;
}

}  // namespace vista
