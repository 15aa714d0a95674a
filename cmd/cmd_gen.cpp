// vista gen: params -> city.osgb (+ optional GeoJSON streets, glTF, stats).
#include <chrono>
#include <cstdio>
#include <fstream>
#include <optional>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "citygen/generate.h"
#include "foundation/atomic_file.h"
#include "citygen/streets.h"
#include "runtime/scene/city_file.h"
#include "cmd/cli.h"
#include "cmd/commands.h"

namespace vista {

int runGen(int argc, char** argv) {
    CLI::App app("Generate a city (deterministic by seed) and write it as one .osgb scene file.", "vista gen");
    std::string paramsFile, out, statsFile, osmFile, geojsonFile, gltfFile;
    std::optional<uint64_t> seed;
    std::optional<double> size;
    std::optional<int> detail, threads;
    bool quiet = false, listParams = false;
    app.add_option("--params", paramsFile, "JSON parameter file (see docs/params.md; examples in data/)");
    app.add_option("--seed", seed, "random seed (overrides the params file)");
    app.add_option("--size", size, "side of the square city area in metres, 100..16000 (default 2000)");
    app.add_option("--detail", detail, "facade detail 0..3 (0 = plain boxes, default 2)");
    app.add_option("--threads", threads, "worker threads (0 = all; output never depends on it)");
    app.add_option("--osm", osmFile, "take the streets from an OpenStreetMap extract (.osm/.osm.pbf, highway=* ways)");
    app.add_option("--geojson", geojsonFile, "also write the street graph as GeoJSON");
    app.add_option("--gltf", gltfFile, "also write the city as binary glTF 2.0 (.glb)");
    app.add_option("--stats", statsFile, "write statistics (counts, timings, peak memory) as JSON");
    auto* outOpt = app.add_option("-o,--output", out, "output scene file (.osgb)");
    app.add_flag("--list-params", listParams, "print every parameter with unit, range and default (Markdown) and exit");
    app.add_flag("-q,--quiet", quiet, "no progress on stderr");
    int rc = parseOrExit(app, argc, argv);
    if (rc >= 0) return rc;
    const std::string cmd = "vista gen";
    if (listParams) {
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
        return 0;
    }
    if (outOpt->count() == 0) return reportBadInput(cmd, Status::error("option -o/--output is required (the .osgb to write)"));

    auto t0 = std::chrono::steady_clock::now();
    CityParams params;
    if (!paramsFile.empty()) {
        auto r = loadParamsFile(paramsFile);
        if (!r) return reportBadInput(cmd, r.status());
        params = *r;
    }
    if (seed) params.seed = *seed;
    if (size) params.size_m = *size;
    if (detail) params.detail = *detail;
    if (threads) params.threads = *threads;
    if (Status s = validateParams(params); !s) {
        std::string m = s.message();
        if (size && m.find("'size_m'") != std::string::npos) m = "option --size: " + m;
        return reportBadInput(cmd, Status::error(m));
    }
    if (out.size() < 5 || out.substr(out.size() - 5) != ".osgb")
        return reportBadInput(cmd, Status::error("option -o = '" + out + "': the output must end in .osgb"));
    for (auto [opt, path] : {std::pair<const char*, std::string*>{"-o", &out}, {"--stats", &statsFile},
                             {"--geojson", &geojsonFile}, {"--gltf", &gltfFile}}) {
        if (path->empty()) continue;
        if (Status s = checkWritablePath(opt, *path); !s) return reportBadInput(cmd, s);
    }

    StderrProgress progress(isatty(2));
    GenerateOptions opts;
    opts.progress = quiet ? nullptr : &progress;
    if (!osmFile.empty()) {
        auto g = importOsm(osmFile, params);
        if (!g) return reportBadInput(cmd, g.status());
        opts.streets = std::move(*g);
    }
    auto city = generateCity(params, opts);
    if (!city) return reportBadInput(cmd, city.status());

    auto tw = std::chrono::steady_clock::now();
    if (Status s = writeCityFile(*city, out); !s) return reportBadInput(cmd, s);
    if (!geojsonFile.empty()) {
        if (Status s = writeFileAtomic(geojsonFile, streetGraphToGeoJson(city->streets, params.origin_x, params.origin_y)); !s)
            return reportBadInput(cmd, s);
    }
    if (!gltfFile.empty()) {
        if (Status s = writeGltf(*city, gltfFile); !s) return reportBadInput(cmd, s);
    }
    double writeSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - tw).count();
    double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    CityCounts n = countCity(*city);
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
    j["tiles"] = city->tiles.size();
    j["triangles"] = n.triangles;
    j["stored_triangles"] = n.storedTriangles;
    j["vertices"] = n.vertices;
    j["draw_calls"] = n.drawCalls;
    nlohmann::ordered_json st;
    for (const auto& s : city->stageTimes) st[s.name] = s.seconds;
    st["write"] = writeSeconds;
    j["seconds"] = {{"total", total}, {"stages", st}};
    j["peak_rss_mb"] = peakRssMb();
    j["threads"] = params.threads;
    if (!statsFile.empty()) {
        if (Status s = writeFileAtomic(statsFile, j.dump(2) + "\n"); !s) return reportBadInput(cmd, s);
    }
    if (!quiet)
        std::fprintf(stderr, "wrote %s: %zu street edges, %zu blocks, %zu buildings, %zu trees, %.2f M triangles, %zu draw calls, %.1fs, peak %.0f MiB\n",
                     out.c_str(), n.streetEdges, n.blocks, n.buildings, n.trees, n.triangles / 1e6, n.drawCalls, total,
                     peakRssMb());
    return 0;
}

}  // namespace vista
