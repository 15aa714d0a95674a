// vista bake: view cells + point impostors at street ends (docs/bake.md).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>
#include <unistd.h>

#include <nlohmann/json.hpp>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "bake/bake.h"
#include "foundation/progress.h"
#include "runtime/scene/scene_file.h"
#include "runtime/scene/scene_graph.h"
#include "foundation/atomic_file.h"
#include "cmd/cli.h"
#include "cmd/commands.h"

namespace vista {
namespace {

Result<std::vector<uint32_t>> parseCellList(const std::string& s) {
    std::vector<uint32_t> out;
    std::stringstream ss(s);
    std::string item;
    while (std::getline(ss, item, ',')) {
        if (item.empty()) continue;
        char* end = nullptr;
        const size_t dash = item.find('-');
        long a = std::strtol(item.c_str(), &end, 10);
        long b = a;
        bool ok = end && end != item.c_str();
        if (dash != std::string::npos && dash > 0) {
            ok = ok && size_t(end - item.c_str()) == dash;
            char* e2 = nullptr;
            b = std::strtol(item.c_str() + dash + 1, &e2, 10);
            ok = ok && e2 && *e2 == 0 && e2 != item.c_str() + dash + 1;
        } else {
            ok = ok && *end == 0;
        }
        if (!ok || a < 0 || b < a || b > 100000000)
            return Status::error("--cells '" + s + "': bad item '" + item + "' (expected ids or ranges like 3,7,10-20)");
        for (long v = a; v <= b; ++v) out.push_back(uint32_t(v));
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    if (out.empty()) return Status::error("--cells '" + s + "': no cell id given");
    return out;
}

Status parseTexels(const std::string& s, int& x, int& y) {
    if (s == "1") { x = y = 1; return Status::ok(); }
    int a = 0, b = 0;
    char c = 0;
    if (std::sscanf(s.c_str(), "%d%c%d", &a, &c, &b) == 3 && (c == 'x' || c == 'X') && a >= 1 && b >= 1 && a <= 32 && b <= 32) {
        x = a; y = b;
        return Status::ok();
    }
    return Status::error("--texels '" + s + "': expected 1 or AxB with 1 <= A, B <= 32 (e.g. 8x2, 4x1)");
}

Result<std::string> readAll(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) return Status::error("cannot read '" + path + "'");
    std::ostringstream o;
    o << f.rdbuf();
    return o.str();
}

std::string cellPath(const std::string& dir, uint32_t id) { return dir + "/cell_" + std::to_string(id) + ".vbc"; }

nlohmann::json statsJson(const ImpostorResult& r) {
    const ImpostorStats& s = r.stats;
    nlohmann::json j;
    j["cell"] = r.cell;
    j["end"] = int(r.end);
    j["tiles"] = s.tiles;
    j["far_triangles"] = s.farTriangles;
    j["ldi_cameras"] = {{s.camW[0], s.camH[0]}, {s.camW[1], s.camH[1]}, {s.camW[2], s.camH[2]}};
    j["ldi_step_required"] = s.requiredStep;
    j["ldi_step_used"] = s.usedStep;
    j["ldi_rays"] = s.ldiRays;
    j["ldi_samples"] = s.ldiSamples;
    j["after_removal"] = s.afterRemoval;
    j["points"] = s.points;
    j["textured_points"] = s.textured;
    j["dropped_invisible"] = s.dropped;
    j["noise_single_points"] = s.noiseSingle;
    j["mc_rays"] = s.mcRays;
    j["mc_samples"] = s.mcSamples;
    j["screen_pixels"] = s.screenPixels;
    j["screen_bbox_pixels"] = s.screenBBoxPixels;
    j["points_per_screen_pixel"] = s.screenPixels ? double(s.points) / double(s.screenPixels) : 0.0;
    const size_t bytes = r.data.positions.size() * kPointBytes + r.data.texels.size() * 4;
    j["memory_mb"] = double(bytes) / (1024.0 * 1024.0);
    j["memory_mb_uncompressed"] = double(r.data.positions.size() * (kPointBytes + 4 * size_t(r.data.texelsX * r.data.texelsY))) / (1024.0 * 1024.0);
    j["bake_s"] = s.bakeMs / 1000.0;
    return j;
}

}  // namespace

int runBake(int argc, char** argv) {
    const std::string cmd = "vista bake";
    CLI::App app{"Bake view cells (from street segments) and point-based impostors at street ends into a baked city file.",
                 cmd};
    std::string input, output, cellList, shard, workDir, statsFile, texels = "8x2";
    int jobs = 0;
    bool merge = false, keepWork = false, quiet = false;
    BakeParams p;
    app.add_option("city", input, "input city file (.osgb from 'vista gen')")->required();
    app.add_option("-o,--output", output, "baked output file (.osgb)")->required();
    app.add_option("--jobs", jobs, "worker threads (0 = all cores)");
    app.add_option("--cells", cellList, "bake only these cell ids (= street edge ids), e.g. 3,7,10-20");
    app.add_option("--shard", shard, "bake shard K of N (K = 1..N) of the cells into the work directory; assemble with --merge");
    app.add_flag("--merge", merge, "assemble the output from the work directory (after sharded bakes)");
    app.add_option("--work", workDir, "work directory for per-cell results (default: OUTPUT.work)");
    app.add_flag("--keep-work", keepWork, "keep the work directory after a successful assembly");
    app.add_option("--stats", statsFile, "write per-impostor statistics (JSON)");
    app.add_flag("-q,--quiet", quiet, "no progress output");
    app.add_option("--margin", p.margin, "far field starts this many metres beyond the street end")->capture_default_str();
    app.add_option("--far-depth", p.farDepth, "metres of far field beyond the margin")->capture_default_str();
    app.add_option("--min-triangles", p.minTriangles, "skip street ends whose far field has fewer triangles")->capture_default_str();
    app.add_option("--oversample", p.sampling.oversample, "LDI resolution factor over the criterion")->capture_default_str();
    app.add_option("--perspective", p.sampling.perspective, "perspective factor fp of the sampling criterion (thesis: 1.17)")
        ->capture_default_str();
    app.add_option("--texel-significance", p.appearance.significance,
                   "F-test level for view-dependent texels (0 = off: the colour spread alone decides)")
        ->capture_default_str();
    app.add_option("--pixel-sigma", p.appearance.pixelSigma,
                   "Monte Carlo pixel filter: Gaussian sigma in output pixels added to the box (the monitor filter; 0 = box only)")
        ->capture_default_str();
    app.add_option("--layers", p.sampling.maxLayers, "LDI layers per pixel")->capture_default_str();
    app.add_option("--max-rays", p.sampling.maxRaysPerCamera, "cap on LDI rays per camera")->capture_default_str();
    bool noRemoval = false;
    app.add_flag("--no-removal", noRemoval, "keep points sampled better by another camera");
    app.add_option("--texels", texels, "texels per point: 1, 4x1, 8x2 (default 8x2)");
    app.add_option("--mc-threshold", p.appearance.varianceThreshold, "Monte Carlo stop: std error of a texel's luma (0..1)")
        ->capture_default_str();
    app.add_option("--mc-min", p.appearance.minSamples, "Monte Carlo samples per texel, first pass")->capture_default_str();
    app.add_option("--mc-max", p.appearance.maxSamples, "Monte Carlo samples per texel, maximum")->capture_default_str();
    app.add_option("--single-threshold", p.appearance.singleColorThreshold, "colour std dev (0..1) for single-colour points")
        ->capture_default_str();
    app.add_option("--out-size", p.sampling.outHeight, "target output height in pixels (width = 4/3 height)")->capture_default_str();
    app.add_option("--fov", p.sampling.fovYDeg, "target output vertical field of view, degrees")->capture_default_str();
    const int rc = parseOrExit(app, argc, argv);
    if (rc >= 0) return rc;
    p.sampling.outWidth = p.sampling.outHeight * 4 / 3;
    p.sampling.removeRedundant = !noRemoval;

    // ---- validate
    if (Status s = parseTexels(texels, p.appearance.texelsX, p.appearance.texelsY); !s) return reportBadInput(cmd, s);
    auto range = [&](const char* opt, double v, double lo, double hi) -> Status {
        if (v >= lo && v <= hi) return Status::ok();
        return Status::error(std::string(opt) + " " + std::to_string(v) + " out of range [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    };
    for (Status s : {range("--jobs", jobs, 0, 1024), range("--margin", p.margin, 0, 1e5), range("--far-depth", p.farDepth, 1, 1e6),
                     range("--oversample", p.sampling.oversample, 0.05, 16), range("--perspective", p.sampling.perspective, 1, 4),
                     range("--texel-significance", p.appearance.significance, 0, 0.5),
                     range("--pixel-sigma", p.appearance.pixelSigma, 0, 4), range("--layers", p.sampling.maxLayers, 1, 64),
                     range("--max-rays", double(p.sampling.maxRaysPerCamera), 1, 1e9),
                     range("--mc-threshold", p.appearance.varianceThreshold, 0, 1), range("--mc-min", p.appearance.minSamples, 1, 4096),
                     range("--mc-max", p.appearance.maxSamples, p.appearance.minSamples, 65536),
                     range("--single-threshold", p.appearance.singleColorThreshold, 0, 1), range("--out-size", p.sampling.outHeight, 16, 8192),
                     range("--fov", p.sampling.fovYDeg, 1, 170)})
        if (!s) return reportBadInput(cmd, s);
    int shardK = 1, shardN = 1;
    if (!shard.empty()) {
        char slash = 0;
        if (std::sscanf(shard.c_str(), "%d%c%d", &shardK, &slash, &shardN) != 3 || slash != '/' || shardN < 1 || shardK < 1 || shardK > shardN)
            return reportBadInput(cmd, Status::error("--shard '" + shard + "': expected K/N with 1 <= K <= N (e.g. 2/4)"));
    }
    if (merge && !shard.empty()) return reportBadInput(cmd, Status::error("--merge and --shard exclude each other"));
    if (Status s = checkWritablePath("--output", output); !s) return reportBadInput(cmd, s);
    if (workDir.empty()) workDir = output + ".work";
    if (!statsFile.empty())
        if (Status s = checkWritablePath("--stats", statsFile); !s) return reportBadInput(cmd, s);

    const auto tStart = std::chrono::steady_clock::now();
    auto city = loadCityFile(input);
    if (!city) return reportBadInput(cmd, city.status());
    if (dynamic_cast<ViewCellSwitch*>(sceneRoot(*city)))
        return reportBadInput(cmd, Status::error("'" + input + "' is already baked; bake the plain city file"));
    auto bytes = readAll(input);
    if (!bytes) return reportBadInput(cmd, bytes.status());
    p.seed = city->params.seed;
    const std::string canon = p.canonical();
    const uint64_t configHash = hashBytes64(bytes->data(), bytes->size(), hashBytes64(canon.data(), canon.size()));
    bytes->clear();
    bytes->shrink_to_fit();
    BakeInput in = prepareBake(*city, p);

    // ---- cell selection
    std::vector<size_t> selected;  // indices into in.cells
    if (!cellList.empty()) {
        auto ids = parseCellList(cellList);
        if (!ids) return reportBadInput(cmd, ids.status());
        for (uint32_t id : *ids) {
            auto it = std::find_if(in.cells.begin(), in.cells.end(), [&](const ViewCell& c) { return c.id == id; });
            if (it == in.cells.end())
                return reportBadInput(cmd, Status::error("--cells: cell " + std::to_string(id) + " does not exist (cells are street edges 0.." +
                                                         std::to_string(city->streets.edges.size()) + ", minus degenerate ones)"));
            selected.push_back(size_t(it - in.cells.begin()));
        }
    } else {
        for (size_t i = 0; i < in.cells.size(); ++i) selected.push_back(i);
    }
    std::vector<size_t> mine;
    for (size_t k = 0; k < selected.size(); ++k)
        if (int(k % size_t(shardN)) == shardK - 1) mine.push_back(selected[k]);

    std::error_code ec;
    std::filesystem::create_directories(workDir, ec);
    if (ec || access(workDir.c_str(), W_OK) != 0)
        return reportBadInput(cmd, Status::error("--work '" + workDir + "': cannot create or write the directory"));

    std::unique_ptr<tbb::global_control> gc;
    if (jobs > 0) gc.reset(new tbb::global_control(tbb::global_control::max_allowed_parallelism, size_t(jobs)));

    // ---- bake the missing cells of this shard
    if (!merge) {
        std::vector<size_t> todo;
        for (size_t ci : mine) {
            auto b = readAll(cellPath(workDir, in.cells[ci].id));
            if (b && decodeCellResult(*b, configHash, "").isOk()) continue;
            todo.push_back(ci);
        }
        if (!quiet)
            std::fprintf(stderr, "vista bake: %zu cells (%zu in this run, %zu already done), %zu degenerate edges skipped\n", mine.size(),
                         todo.size(), mine.size() - todo.size(), in.skipped.size());
        std::atomic<size_t> done{0};
        std::atomic<bool> failed{false};
        std::string failure;
        std::mutex failMu;
        StderrProgress prog(isatty(2) != 0);
        if (!quiet) prog.begin("bake");
        std::thread worker([&] {
            tbb::parallel_for(size_t(0), todo.size(), size_t(1), [&](size_t k) {
                if (failed) return;
                const ViewCell& c = in.cells[todo[k]];
                CellResult r = bakeCell(in, c, p);
                Status s = writeFileAtomic(cellPath(workDir, c.id), encodeCellResult(r, configHash));
                if (!s) {
                    std::lock_guard<std::mutex> l(failMu);
                    failure = s.message();
                    failed = true;
                }
                ++done;
            });
        });
        while (done.load() < todo.size() && !failed) {
            if (!quiet) prog.update(double(done.load()) / double(std::max<size_t>(todo.size(), 1)));
            std::this_thread::sleep_for(std::chrono::milliseconds(100));
        }
        worker.join();
        if (!quiet) prog.end();
        if (failed) {
            std::fprintf(stderr, "%s: %s\n", cmd.c_str(), failure.c_str());
            return 1;
        }
        if (shardN > 1) {
            if (!quiet)
                std::fprintf(stderr, "vista bake: shard %d/%d done (%zu cells) in %s; assemble with 'vista bake %s -o %s --merge%s'\n", shardK,
                             shardN, mine.size(), workDir.c_str(), input.c_str(), output.c_str(),
                             cellList.empty() ? "" : (" --cells " + cellList).c_str());
            return 0;
        }
    }

    // ---- assemble
    std::vector<CellResult> results;
    std::vector<uint32_t> missing;
    for (size_t ci : selected) {
        const uint32_t id = in.cells[ci].id;
        auto b = readAll(cellPath(workDir, id));
        if (!b) { missing.push_back(id); continue; }
        auto r = decodeCellResult(*b, configHash, cellPath(workDir, id));
        if (!r) { missing.push_back(id); continue; }
        results.push_back(std::move(*r));
    }
    if (!missing.empty()) {
        std::string list;
        for (size_t i = 0; i < missing.size() && i < 20; ++i) list += (i ? "," : "") + std::to_string(missing[i]);
        if (missing.size() > 20) list += ",...";
        return reportBadInput(cmd, Status::error(std::to_string(missing.size()) + " cell results missing or stale in '" + workDir +
                                                 "' (cells " + list + "); bake them first (all shards with the same parameters)"));
    }
    std::sort(results.begin(), results.end(), [](const CellResult& a, const CellResult& b) { return a.cell < b.cell; });
    osg::ref_ptr<ViewCellSwitch> root = assembleBakedScene(*city, in.cells, results, canon);
    if (Status s = writeSceneFile(*root, output, false); !s) {
        std::fprintf(stderr, "%s: %s\n", cmd.c_str(), s.message().c_str());
        return 1;
    }
    size_t imps = 0, points = 0;
    double cellMs = 0;
    nlohmann::json js = nlohmann::json::array();
    for (const auto& r : results) {
        cellMs += r.bakeMs;
        for (const auto& im : r.impostors) {
            ++imps;
            points += im.stats.points;
            js.push_back(statsJson(im));
        }
    }
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - tStart).count();
    const auto size = std::filesystem::file_size(output, ec);
    if (!statsFile.empty()) {
        nlohmann::json top;
        top["input"] = input;
        top["cells"] = results.size();
        top["impostors"] = imps;
        top["points"] = points;
        top["cell_bake_s_sum"] = cellMs / 1000.0;
        top["wall_s"] = wall;
        top["output_bytes"] = ec ? 0 : size;
        top["params"] = canon;
        top["impostor_stats"] = js;
        if (Status s = writeFileAtomic(statsFile, top.dump(1)); !s) {
            std::fprintf(stderr, "%s: %s\n", cmd.c_str(), s.message().c_str());
            return 1;
        }
    }
    if (!quiet)
        std::fprintf(stderr, "vista bake: wrote %s: %zu cells, %zu impostors, %zu points, %.1f MB, %.1f s (cell bake time %.1f s)\n",
                     output.c_str(), results.size(), imps, points, ec ? 0.0 : double(size) / 1048576.0, wall, cellMs / 1000.0);
    if (!keepWork) {
        for (size_t ci : selected) std::filesystem::remove(cellPath(workDir, in.cells[ci].id), ec);
        std::filesystem::remove(workDir, ec);  // only if empty
    }
    return 0;
}

}  // namespace vista
