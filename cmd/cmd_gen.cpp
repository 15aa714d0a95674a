// vista gen: params -> city.osgb (+ optional GeoJSON streets, glTF, stats).
#include <cmath>
#include <cstdio>
#include <functional>
#include <fstream>
#include <optional>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "citygen/generate.h"
#include "citygen/opendrive.h"
#include "foundation/atomic_file.h"
#include "foundation/format.h"
#include "foundation/input_file.h"
#include "foundation/number_text.h"
#include "foundation/output_paths.h"
#include "foundation/shard.h"
#include "foundation/timing.h"
#include "citygen/streets.h"
#include "cmd/options.h"
#include "bake/gen/baked_lighting.h"
#include "runtime/scene/city_file.h"
#include "bake/gen/paged_city.h"
#include "citygen/regions.h"
#include "cmd/cli.h"
#include "cmd/commands.h"
#include "cmd/memory.h"

namespace vista {

namespace {

const char* const kCmd = "vista gen";

struct GenArgs {
    std::string paramsFile, out, statsFile, osmFile, geojsonFile, gltfFile, xodrFile;
    std::optional<std::string> effects;  // unset: the params file's
    std::string osmBuildings = "on";
    std::optional<uint64_t> seed;
    std::optional<double> size;
    bool sizeInParams = false;  // the params file sets size_m (with --osm: clips as --size does)
    std::optional<int> detail, threads;
    bool quiet = false, listParams = false;
    // Paged output (-o DIR.paged).
    std::optional<double> regionSize;
    std::string shard;
    std::optional<int> shards;
    bool merge = false;
    double budgetGb = 0;  // --memory-budget (0 = none)
    bool paged() const { return endsWith(out, ".paged") || endsWith(out, ".paged/"); }
    static bool endsWith(const std::string& s, const std::string& t) {
        return s.size() >= t.size() && s.compare(s.size() - t.size(), t.size(), t) == 0;
    }
};

// The range of the parameter `name` (citygen/params.h), for the flag that sets it.
const ParamSpec& paramSpec(const char* name) {
    for (const auto& s : paramSpecs())
        if (std::string(s.name) == name) return s;
    VISTA_CHECK(false);
    return paramSpecs().front();
}

CLI::Option* declareFlags(CLI::App& app, GenArgs& a) {
    app.add_option("--params", a.paramsFile, "JSON parameter file (see docs/params.md; examples in data/)");
    addNumberOption(app, "--seed", a.seed, 0, UINT64_MAX, "random seed (overrides the params file)");
    const ParamSpec &size = paramSpec("size_m"), &detail = paramSpec("detail"), &threads = paramSpec("threads");
    addNumberOption(app, "--size", a.size, RealRange::closed(size.min, size.max),
                    "side of the square city area in metres, 100..16000 (default 2000); up to 64000 with paged output");
    addNumberOption(app, "--detail", a.detail, int(detail.min), int(detail.max),
                    "facade detail 0..3 (0 = plain boxes, default 2)");
    addNumberOption(app, "--threads", a.threads, int(threads.min), int(threads.max),
                    "worker threads, 0 .. 256 (0 = all; output never depends on it)");
    app.add_option("--effects", a.effects,
                   "effects the scene declares, over the params file's: 'none', names (" + effectNames() +
                       ") or a JSON object as in the params file (see docs/params.md)");
    app.add_option("--osm", a.osmFile,
                   "take the streets (highway=* ways) and buildings (building=*, see --osm-buildings) from an "
                   "OpenStreetMap extract (.osm/.osm.pbf); the city covers the extract's extent (over 16 km: "
                   "paged output only) unless --size (or size_m in --params) clips it to a square about its centre");
    app.add_option("--osm-buildings", a.osmBuildings,
                   "with --osm: 'on' (default) imports building=* footprints and keeps procedural lots only where the "
                   "data has no building; 'off' fills every block procedurally (docs/buildings.md)");
    app.add_option("--geojson", a.geojsonFile, "also write the street graph as GeoJSON");
    app.add_option("--gltf", a.gltfFile, "also write the city as binary glTF 2.0 (.glb)");
    app.add_option("--xodr", a.xodrFile,
                   "also write the road network as ASAM OpenDRIVE 1.6 (.xodr, see docs/formats.md); with paged "
                   "output one file for the whole city, written with the index (not by a --shard)");
    app.add_option("--stats", a.statsFile, "write statistics (counts, timings, peak memory) as JSON");
    auto* out = app.add_option("-o,--output", a.out,
                               "output: a scene file (.osgb), or a paged city directory (DIR.paged: one city file per "
                               "region, index.osgb with a PagedLOD per region for osgviewer, manifest.json; "
                               "docs/formats.md 'Paged city')");
    addNumberOption(
        app, "--region-size", a.regionSize, RealRange::closed(kMinRegionSizeM, kMaxRegionSizeM),
        "paged output: side of a region in metres, a whole number of tiles (tile_size_m), 250..16000 (default 2000)");
    app.add_option("--shard", a.shard,
                   "paged output: shard K of N (K/N, 1 <= K <= N): generate only the regions whose index % N == K - 1, "
                   "no index; then --merge (or an unsharded run) writes index and manifest");
    app.add_flag("--merge", a.merge,
                 "paged output: generate nothing; write index.osgb and manifest.json once every region is done "
                 "(exit 2 naming the missing regions otherwise)");
    addNumberOption(
        app, "--shards", a.shards, 1, kMaxShards,
        "with --merge: N, 1 .. 100000, the shard count of the shards' --shard K/N; a merge that finds regions missing "
        "then names the shards K/N to run again and the command that runs them");
    addNumberOption(
        app, "--memory-budget", a.budgetGb, kMemoryBudgetGbRange,
        "GB, (0, 65536]: refuse up front, before the meshes are made and with nothing written, a generation whose "
        "estimated peak memory exceeds it (one file: from the laid-out city's estimated triangles; paged: "
        "from --region-size); --stats reports the estimate beside the measured peak (default: no budget)");
    app.add_flag("--list-params", a.listParams,
                 "print every parameter with unit, range and default (Markdown) and exit");
    app.add_flag("-q,--quiet", a.quiet, "no progress on stderr");
    return out;
}

void printParamTable() {
    CityParams d;
    auto defaults = nlohmann::json::parse(paramsToJson(d));
    std::printf("| parameter | unit | range | default | meaning |\n|---|---|---|---|---|\n");
    for (const auto& s : paramSpecs()) {
        std::string def = std::string(s.name) == "threads" ? "0" : defaults[s.name].dump();
        char range[64];
        if (std::string(s.name) == "seed") std::snprintf(range, sizeof range, "0 .. 2^64-1");
        else std::snprintf(range, sizeof range, "%g .. %g", s.min, s.max);
        std::printf("| `%s` | %s | %s | %s | %s |\n", s.name, s.unit, range, def.c_str(), s.help);
    }
    std::printf(
        "\n### Effects\n\nThe `effects` object: an effect is on when its key is present; its object holds "
        "its parameters (absent ones keep these defaults), e.g. `\"effects\": {\"haze\": "
        "{\"visibility_m\": 1500}, \"glass\": {}}`. Baked effects change the prelit colours at "
        "generation and cost nothing per frame beyond the triangles their refinement adds; run-time effects "
        "are applied per frame, only where on screen (docs/effects.md measures both).\n\n");
    std::printf("| effect | kind | field | unit | range | default | meaning |\n|---|---|---|---|---|---|---|\n");
    for (const auto& f : effectSpecs()) {
        char range[64], def[32];
        std::snprintf(range, sizeof range, "%g .. %g", f.min, f.max);
        std::snprintf(def, sizeof def, "%g", f.defaultValue);
        std::printf("| `%s` | %s | `%s` | %s | %s | %s | %s |\n", effectName(f.effect),
                    effectIsBaked(f.effect) ? "baked" : "run time", f.name, f.unit, range, def, f.help);
    }
}

// The parameters (file, then the flags over it) and the output paths, checked.
Result<CityParams> resolveParams(GenArgs& a) {
    CityParams params;
    if (!a.paramsFile.empty()) {
        if (Status s = checkInputFile("parameter file", a.paramsFile, kMaxParamsFileBytes); !s)
            return Status::error("option --params: " + s.message());
        auto r = loadParamsFile(a.paramsFile);
        if (!r) return r.status();
        params = *r;
        std::ifstream in(a.paramsFile, std::ios::binary);
        const auto j = nlohmann::json::parse(in, nullptr, false);
        a.sizeInParams = j.is_object() && j.contains("size_m");
    }
    if (a.seed) params.seed = *a.seed;
    if (a.size) params.size_m = *a.size;
    if (a.detail) params.detail = *a.detail;
    if (a.threads) params.threads = *a.threads;
    if (a.effects) {
        auto e = parseEffectsOption(*a.effects, params.effects);
        if (!e) return e.status();
        params.effects = *e;
    }
    if (Status s = validateParams(params); !s) {
        std::string m = s.message();
        if (a.size && m.find("'size_m'") != std::string::npos) m = "option --size: " + m;
        return Status::error(m);
    }
    if (a.osmBuildings != "on" && a.osmBuildings != "off")
        return Status::error("option --osm-buildings = '" + a.osmBuildings + "': must be 'on' or 'off'");
    if (a.paged()) return params;  // checked by resolvePaged
    if (a.regionSize || !a.shard.empty() || a.merge || a.shards)
        return Status::error(std::string("option ") +
                             (a.regionSize       ? "--region-size"
                              : !a.shard.empty() ? "--shard"
                              : a.shards         ? "--shards"
                                                 : "--merge") +
                             ": only with paged output (-o DIR.paged)");
    if (a.out.size() < 5 || a.out.substr(a.out.size() - 5) != ".osgb")
        return Status::error("option -o = '" + a.out +
                             "': the output must end in .osgb (a scene file) or .paged (a paged city directory)");
    if (Status s = checkSingleFileSize(params); !s)
        return Status::error((a.size ? "option --size: " : "") + s.message());
    if (!a.xodrFile.empty()) VISTA_RETURN_IF_ERROR(checkXodrPath("--xodr", a.xodrFile));
    for (auto [opt, path] : {std::pair<const char*, std::string*>{"-o", &a.out},
                             {"--stats", &a.statsFile},
                             {"--geojson", &a.geojsonFile},
                             {"--gltf", &a.gltfFile},
                             {"--xodr", &a.xodrFile}}) {
        if (!path->empty()) VISTA_RETURN_IF_ERROR(checkWritablePath(opt, *path));
    }
    return params;
}

// The command that runs one shard of this paged generation again: the flags
// that decide the regions' bytes as given, the output, then `--shard` (the
// merge's refusal appends K/N).
std::string shardCommand(const GenArgs& a, const std::string& dir) {
    std::string c = "vista gen";
    auto add = [&](const char* flag, const std::string& v) { c += std::string(" ") + flag + " " + shellWord(v); };
    if (!a.paramsFile.empty()) add("--params", a.paramsFile);
    if (a.seed) add("--seed", std::to_string(*a.seed));
    if (a.size) add("--size", exactDecimal(*a.size));
    if (a.detail) add("--detail", std::to_string(*a.detail));
    if (a.effects) add("--effects", *a.effects);
    if (!a.osmFile.empty()) add("--osm", a.osmFile);
    if (!a.osmFile.empty() && a.osmBuildings != "on") add("--osm-buildings", a.osmBuildings);
    if (a.regionSize) add("--region-size", exactDecimal(*a.regionSize));
    add("-o", dir);
    return c + " --shard";
}

// The paged output's options, checked before anything is written.
Result<PagedCityOptions> resolvePaged(const GenArgs& a, const CityParams& params) {
    PagedCityOptions o;
    o.dir = a.out;
    while (o.dir.size() > 1 && o.dir.back() == '/') o.dir.pop_back();
    if (a.regionSize) o.regionSizeM = *a.regionSize;
    o.merge = a.merge;
    if (Status s = validateRegionSize(params, o.regionSizeM); !s)
        return Status::error("option --region-size: " + s.message());
    if (!a.shard.empty()) {
        auto sh = parseShard("--shard", a.shard);
        if (!sh) return sh.status();
        o.shard = *sh;
    }
    if (a.merge && !a.shard.empty())
        return Status::error("option --merge: not with --shard (the merge covers every shard)");
    if (a.shards) {
        if (!a.merge) return Status::error("option --shards: only with --merge (shards take --shard K/N)");
        o.mergeShards = *a.shards;
        o.shardCommand = shardCommand(a, o.dir);
    }
    for (auto [opt, path] :
         {std::pair<const char*, const std::string*>{"--geojson", &a.geojsonFile}, {"--gltf", &a.gltfFile}})
        if (!path->empty())
            return Status::error(std::string("option ") + opt + ": not supported with paged output (-o DIR.paged)");
    if (!a.xodrFile.empty()) {
        if (o.shard.count > 1)
            return Status::error(
                "option --xodr: not with --shard (a shard writes its regions only; give --xodr to "
                "the --merge, which writes the whole road network)");
        VISTA_RETURN_IF_ERROR(checkXodrPath("--xodr", a.xodrFile));
        VISTA_RETURN_IF_ERROR(checkWritablePath("--xodr", a.xodrFile));
        o.xodr = a.xodrFile;
    }
    if (bakedLightingCalledFor(params))
        return Status::error(
            "parameter 'effects' = " + params.effects.list() +
            ": baked lighting (sun_shadows, ambient_occlusion, night street lights) is computed over the "
            "whole city and is not supported with paged output (-o DIR.paged)");
    VISTA_RETURN_IF_ERROR(checkPagedOutput("-o", o.dir));
    if (!a.statsFile.empty()) VISTA_RETURN_IF_ERROR(checkWritablePath("--stats", a.statsFile));
    return o;
}

// The OSM import of --osm: the extract's own extent, or the square of
// --size (or the params file's size_m) about its centre. Sets the params'
// geo reference and size_m; prints what was dropped or clipped. A city larger
// than a single file holds is refused unless the output is paged.
Result<OsmImport> importForGen(const GenArgs& a, CityParams& params) {
    const bool clip = a.size || a.sizeInParams;
    auto g = importOsm(a.osmFile, params, a.osmBuildings == "on", clip ? OsmExtent::CitySquare : OsmExtent::Extract);
    if (!g) return g.status();
    if (!a.paged() && g->citySize_m > kMaxSingleFileSizeM)
        return Status::error("option --osm = '" + a.osmFile + "': the extract's roads span " +
                             exactDecimal(std::round(g->extentX_m)) + " m east-west by " +
                             exactDecimal(std::round(g->extentY_m)) +
                             " m north-south, a city of size_m = " + exactDecimal(g->citySize_m) +
                             " m, more than a single file holds (size_m up to " + exactDecimal(kMaxSingleFileSizeM) +
                             "): write a paged city (-o DIR.paged) or clip the extract with --size (100 .. " +
                             exactDecimal(kMaxSingleFileSizeM) + ")");
    if (std::string dropped = g->dropSummary(); !dropped.empty()) {
        if (g->clippedSegments)
            dropped += std::string(" (") + (a.size ? "--size" : "size_m in --params") +
                       "; without it the city covers the whole extract)";
        std::fprintf(stderr, "osm: %s\n", dropped.c_str());
    }
    params.geo = g->geo;
    params.size_m = g->citySize_m;
    if (a.osmBuildings == "on") {
        const OsmBuildingStats& b = g->buildingStats;
        if (const size_t skipped = b.candidates - b.imported)
            std::fprintf(stderr, "osm: skipped %zu of %zu building footprints (see --stats osm_buildings.skipped)\n",
                         skipped, b.candidates);
    }
    return g;
}

int runPaged(const GenArgs& a, CityParams params, const Stopwatch& total) {
    auto o = resolvePaged(a, params);
    if (!o) return reportBadInput(kCmd, o.status());
    std::optional<OsmImport> osm;
    if (!a.osmFile.empty()) {
        auto g = importForGen(a, params);
        if (!g) return reportBadInput(kCmd, g.status());
        osm = std::move(*g);
        o->inputs.streets = &osm->streets;
        if (a.osmBuildings == "on") o->inputs.osmBuildings = &osm->buildings;
        o->inputKey = "osm=" + hex64(osm->fileHash) + " osm_buildings=" + a.osmBuildings;
    }
    const double estimateMb = estimatePagedGenMb(o->regionSizeM, params.detail);
    {
        char how[160];
        std::snprintf(how, sizeof(how), "paged: one %g m region at a time at detail %d", o->regionSizeM, params.detail);
        if (Status s = checkGenBudget("--memory-budget", a.budgetGb, estimateMb, how, true); !s)
            return reportBadInput(kCmd, s);
    }
    StderrProgress progress(isatty(2));
    o->progress = a.quiet ? nullptr : &progress;
    OutputBatch batch;  // index and manifest, committed with --stats
    o->batch = &batch;
    auto rep = generatePagedCity(params, *o);
    if (!rep) return reportBadInput(kCmd, rep.status());
    const double totalSeconds = total.ms() / 1000.0;
    if (!a.statsFile.empty()) {
        nlohmann::ordered_json j;
        j["seed"] = params.seed;
        j["size_m"] = params.size_m;
        j["detail"] = params.detail;
        j["region_size_m"] = o->regionSizeM;
        j["shard"] = std::to_string(o->shard.k()) + "/" + std::to_string(o->shard.count);
        j["merge"] = o->merge;
        j["regions"] = rep->regions;
        j["regions_generated"] = rep->generated;
        j["regions_reused"] = rep->reused;
        j["regions_regenerated"] = rep->regenerated;
        j["empty_regions"] = rep->emptyRegions;
        j["index_written"] = rep->indexWritten;
        j["street_edges"] = rep->streetEdges;
        j["blocks"] = rep->blocks;
        j["buildings"] = rep->buildings;
        j["trees"] = rep->trees;
        j["triangles"] = rep->triangles;
        j["bytes"] = rep->bytes;
        j["seconds"] = {{"total", totalSeconds},
                        {"stages",
                         {{"streets and blocks", rep->baseSeconds},
                          {"regions", rep->regionSeconds},
                          {"index", rep->indexSeconds}}}};
        j["peak_rss_mb"] = peakRssMb();
        j["memory"] = {{"estimate_mb", estimateMb},
                       {"budget_gb", a.budgetGb > 0 ? nlohmann::json(a.budgetGb) : nlohmann::json(nullptr)}};
        j["threads"] = params.threads;
        if (rep->xodrWritten) {
            j["seconds"]["stages"]["opendrive"] = rep->xodrSeconds;
            j["opendrive"] = nlohmann::ordered_json::parse(openDriveCountsJson(rep->roads));
        }
        if (osm) j["osm_roads"] = nlohmann::ordered_json::parse(osmRoadTagStatsJson(osm->roadTagStats));
        if (Status s = writeFileAtomic(batch.stage(a.statsFile), j.dump(2) + "\n"); !s) return reportBadInput(kCmd, s);
    }
    if (Status s = batch.commit(); !s) return reportBadInput(kCmd, s);
    if (!a.quiet)
        std::fprintf(
            stderr,
            "wrote %s: %d regions (%d generated, %d reused, %d empty), %zu buildings, %zu trees, %.2f M triangles, "
            "%.1f MB, %s, %.1fs, peak %.0f MiB\n",
            o->dir.c_str(), rep->regions, rep->generated, rep->reused, rep->emptyRegions, rep->buildings, rep->trees,
            rep->triangles / 1e6, rep->bytes / 1e6,
            rep->indexWritten ? "index written" : "no index (shard: run --merge when every shard is done)",
            totalSeconds, peakRssMb());
    if (!a.quiet && rep->xodrWritten)
        std::fprintf(stderr, "wrote %s: %zu roads, %zu junctions, %zu connecting roads\n", a.xodrFile.c_str(),
                     rep->roads.roads, rep->roads.junctions, rep->roads.connectingRoads);
    return 0;
}

// Every output of the command, or none: each is staged, then all renamed
// together; `stats` (called once the others are staged, with the OpenDRIVE
// counts when --xodr was written, else null) gives the stats JSON.
Status writeOutputs(const GenArgs& a, const City& city, const CityParams& params,
                    const std::function<std::string(const OpenDriveCounts*)>& stats) {
    OutputBatch batch;
    OpenDriveCounts roads;
    VISTA_RETURN_IF_ERROR(writeCityFile(city, batch.stage(a.out)));
    if (!a.geojsonFile.empty())
        VISTA_RETURN_IF_ERROR(
            writeFileAtomic(batch.stage(a.geojsonFile),
                            streetGraphToGeoJson(city.streets, params.origin_x, params.origin_y, params.geo)));
    if (!a.gltfFile.empty()) VISTA_RETURN_IF_ERROR(writeGltf(city, batch.stage(a.gltfFile)));
    if (!a.xodrFile.empty()) {
        auto xodr = openDriveXml(city.streets, params, &city.blocks, &roads);
        if (!xodr) return Status::error("option --xodr = '" + a.xodrFile + "': " + xodr.status().message());
        VISTA_RETURN_IF_ERROR(writeFileAtomic(batch.stage(a.xodrFile), *xodr));
    }
    if (!a.statsFile.empty())
        VISTA_RETURN_IF_ERROR(writeFileAtomic(batch.stage(a.statsFile), stats(a.xodrFile.empty() ? nullptr : &roads)));
    return batch.commit();
}

nlohmann::ordered_json statsJson(const City& city, const CityParams& params, const CityCounts& n,
                                 const BakedLightingStats& lighting, double writeSeconds, double total) {
    nlohmann::ordered_json j;
    j["seed"] = params.seed;
    j["size_m"] = params.size_m;
    j["detail"] = params.detail;
    j["street_nodes"] = n.streetNodes;
    j["street_edges"] = n.streetEdges;
    j["blocks"] = n.blocks;
    j["lots"] = n.lots;
    j["buildings"] = n.buildings;
    j["trees"] = n.trees;
    j["cars"] = city.cars.size();
    j["tiles"] = city.tiles.size();
    j["triangles"] = n.triangles;
    j["stored_triangles"] = n.storedTriangles;
    j["vertices"] = n.vertices;
    j["draw_calls"] = n.drawCalls;
    nlohmann::ordered_json st;
    for (const auto& s : city.stageTimes) st[s.name] = s.seconds;
    st["write"] = writeSeconds;
    j["seconds"] = {{"total", total}, {"stages", st}};
    j["effects"] = nlohmann::ordered_json::parse(effectsToJson(params.effects));
    if (lighting.ran)
        j["baked_lighting"] = {{"seconds", lighting.seconds},
                               {"ray_scene_seconds", lighting.sceneSeconds},
                               {"triangles_before", lighting.trianglesBefore},
                               {"triangles_after", lighting.trianglesAfter},
                               {"rays", lighting.rays}};
    if (const OsmBuildingStats& o = city.osmBuildings; o.enabled)
        j["osm_buildings"] = {
            {"ways", o.ways},
            {"relations", o.relations},
            {"candidates", o.candidates},
            {"imported", o.imported},
            {"repaired",
             {{"duplicate_nodes", o.duplicateNodes},
              {"unclosed_rings", o.unclosedRings},
              {"self_intersections", o.selfIntersections},
              {"inner_rings_dropped", o.innerRingsDropped}}},
            {"skipped",
             {{"missing_nodes", o.missingNodes},
              {"too_few_nodes", o.tooFewNodes},
              {"too_small", o.tooSmall},
              {"self_intersecting", o.selfIntersecting},
              {"outside_city", o.outsideCity},
              {"no_outer_ring", o.noOuterRing}}},
            {"height", {{"tag", o.heightFromTag}, {"levels", o.heightFromLevels}, {"procedural", o.heightProcedural}}},
            {"roof", {{"tag", o.roofFromTag}, {"procedural", o.roofProcedural}, {"fallback_flat", o.roofFallbackFlat}}},
            {"lots_dropped", o.lotsDropped},
            {"on_carriageway", o.onCarriageway}};
    j["peak_rss_mb"] = peakRssMb();
    j["threads"] = params.threads;
    return j;
}

}  // namespace

int runGen(int argc, char** argv) {
    CLI::App app(
        "Generate a city (deterministic by seed) and write it as one .osgb scene file, or region by region as a "
        "paged city directory (-o DIR.paged) that resumes after a kill and splits into shards.",
        kCmd);
    GenArgs a;
    CLI::Option* outOpt = declareFlags(app, a);
    if (int rc = parseOrExit(app, argc, argv); rc >= 0) return rc;
    if (a.listParams) {
        printParamTable();
        return 0;
    }
    if (outOpt->count() == 0)
        return reportBadInput(kCmd, Status::error("option -o/--output is required (the .osgb to write)"));
    CommandFiles files;  // held until the outputs are written (the locks)
    if (a.paged()) {
        auto shard = parseShard("--shard", a.shard.empty() ? "1/1" : a.shard);
        files.outputDirectory("-o", a.out).shareOutputs(shard && shard->count > 1 && !a.merge);  // shards side by side
    } else {
        files.output("-o", a.out);
    }
    if (Status s = files.input("--params", a.paramsFile)
                       .input("--osm", a.osmFile)
                       .output("--stats", a.statsFile)
                       .output("--geojson", a.geojsonFile)
                       .output("--gltf", a.gltfFile)
                       .output("--xodr", a.xodrFile)
                       .check();
        !s)
        return reportBadInput(kCmd, s);
    Stopwatch total;
    auto params = resolveParams(a);
    if (!params) return reportBadInput(kCmd, params.status());
    if (a.paged()) return runPaged(a, *params, total);
    StderrProgress progress(isatty(2));
    GenerateOptions opts;
    opts.progress = a.quiet ? nullptr : &progress;
    double estimateMb = -1;  // made only under a budget (the estimate meshes a sample of tiles)
    if (a.budgetGb > 0)
        opts.beforeMeshing = [&](const City& layout) {
            const size_t tris = estimateStoredTriangles(layout);
            estimateMb = estimateGenMb(tris);
            char how[160];
            std::snprintf(how, sizeof(how), "about %.2f M stored triangles x %.0f bytes + %.0f MB", double(tris) / 1e6,
                          kGenBytesPerStoredTriangle, kGenFixedMb);
            return checkGenBudget("--memory-budget", a.budgetGb, estimateMb, how, false);
        };
    double osmSeconds = -1;
    std::optional<OsmRoadTagStats> osmRoads;
    if (!a.osmFile.empty()) {
        Stopwatch osmTime;
        auto g = importForGen(a, *params);
        if (!g) return reportBadInput(kCmd, g.status());
        opts.streets = std::move(g->streets);
        osmRoads = g->roadTagStats;
        if (a.osmBuildings == "on") {
            opts.osmBuildings = std::move(g->buildings);
            opts.osmStats = g->buildingStats;
        }
        osmSeconds = osmTime.ms() / 1000.0;
    }
    auto city = generateCity(*params, opts);
    if (!city) return reportBadInput(kCmd, city.status());
    if (osmSeconds >= 0) city->stageTimes.insert(city->stageTimes.begin(), {"osm import", osmSeconds});
    BakedLightingStats lighting;
    if (bakedLightingCalledFor(*params)) {
        if (opts.progress) opts.progress->begin("lighting");
        Status s = bakeLighting(*city, opts.progress, lighting);
        if (opts.progress) opts.progress->end();
        if (!s) return reportBadInput(kCmd, s);
        city->stageTimes.push_back({"lighting", lighting.seconds});
    }
    Stopwatch write;
    const CityCounts n = countCity(*city);
    double totalSeconds = 0;
    auto stats = [&](const OpenDriveCounts* roads) {
        totalSeconds = total.ms() / 1000.0;
        auto j = statsJson(*city, *params, n, lighting, write.ms() / 1000.0, totalSeconds);
        if (a.budgetGb > 0) j["memory"] = {{"estimate_mb", estimateMb}, {"budget_gb", a.budgetGb}};
        if (osmRoads) j["osm_roads"] = nlohmann::ordered_json::parse(osmRoadTagStatsJson(*osmRoads));
        if (roads) j["opendrive"] = nlohmann::ordered_json::parse(openDriveCountsJson(*roads));
        return j.dump(2) + "\n";
    };
    if (Status s = writeOutputs(a, *city, *params, stats); !s) return reportBadInput(kCmd, s);
    totalSeconds = total.ms() / 1000.0;
    if (!a.quiet)
        std::fprintf(stderr,
                     "wrote %s: %zu street edges, %zu blocks, %zu buildings, %zu trees, %.2f M triangles, %zu draw "
                     "calls, %.1fs, peak %.0f MiB%s%s\n",
                     a.out.c_str(), n.streetEdges, n.blocks, n.buildings, n.trees, n.triangles / 1e6, n.drawCalls,
                     totalSeconds, peakRssMb(), params->effects.any() ? ", effects: " : "",
                     params->effects.any() ? params->effects.list().c_str() : "");
    return 0;
}

}  // namespace vista
