#include "bake/driver.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>
#include <unistd.h>

#include <nlohmann/json.hpp>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "bake/assembly.h"
#include "bake/bake_cell.h"
#include "foundation/atomic_file.h"
#include "foundation/hash.h"
#include "foundation/number_text.h"
#include "foundation/output_paths.h"
#include "foundation/timing.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/scene_file.h"
#include "runtime/scene/scene_graph.h"

namespace vista {

namespace {

// The job's files; the shards of one bake share the work directory and the
// outputs (their locks are shared), an unsharded run or the merge holds them alone.
CommandFiles bakeFiles(const BakeJob& j) {
    CommandFiles files;
    files.input("city", j.input)
        .output("--output", j.output)
        .output("--stats", j.statsFile)
        .outputDirectory("--work", j.workDir.empty() ? j.output + ".work" : j.workDir)
        .shareOutputs(j.shardN > 1 && !j.merge);
    return files;
}

}  // namespace

Status validateBakeJob(const BakeJob& j) {
    const BakeParams& p = j.params;
    auto range = [](const char* opt, double v, const RealRange& r) -> Status {
        if (r.contains(v)) return Status::ok();
        return Status::error(std::string(opt) + " " + shortNumber(v) + " out of range " + r.text());
    };
    namespace R = bake_range;
    if (j.input.empty()) return Status::error("input city file: no path given");
    if (j.output.empty()) return Status::error("--output: no path given");
    for (Status s :
         {range("--jobs", j.jobs, R::jobs),
          range("--margin", p.far.margin, R::margin),
          range("--far-depth", p.far.farDepth, R::farDepth),
          range("--min-triangles", double(p.far.minTriangles), R::minTriangles),
          range("--oversample", p.sampling.oversample, R::oversample),
          range("--perspective", p.sampling.perspective, R::perspective),
          range("--texel-significance", p.appearance.significance, R::significance),
          range("--pixel-sigma", p.appearance.pixelSigma, R::pixelSigma),
          range("--layers", p.sampling.maxLayers, R::layers),
          range("--max-rays", double(p.sampling.maxRaysPerCamera), R::maxRays),
          range("--mc-threshold", p.appearance.varianceThreshold, R::mcThreshold),
          range("--mc-min", p.appearance.minSamples, R::mcMin),
          range("--mc-max", p.appearance.maxSamples, RealRange::closed(p.appearance.minSamples, R::mcMax.max)),
          range("--single-threshold", p.appearance.singleColorThreshold, R::singleThreshold),
          range("--out-size", p.sampling.outHeight, R::outSize),
          range("--fov", p.sampling.fovYDeg, R::fov),
          range("--texels (A)", p.appearance.texelsX, R::texels),
          range("--texels (B)", p.appearance.texelsY, R::texels),
          range("--triangle-ns", p.placement.triangleNs, R::rasterNs),
          range("--point-ns", p.placement.pointNs, R::rasterNs)})
        if (!s) return s;
    if (p.representation == BakeRepresentation::Mesh)
        for (Status s : {range("--mesh-triangles", p.mesh.maxTriangles, R::meshTriangles),
                         range("--mesh-image", p.mesh.imageSize, R::meshImage),
                         range("--mesh-error", p.mesh.errorPx, R::meshError)})
            if (!s) return s;
    if (j.shardN < 1 || j.shardK < 1 || j.shardK > j.shardN)
        return Status::error("--shard " + std::to_string(j.shardK) + "/" + std::to_string(j.shardN) +
                             ": expected K/N with 1 <= K <= N");
    if (j.merge && j.shardN > 1) return Status::error("--merge and --shard exclude each other");
    CommandFiles files = bakeFiles(j);
    VISTA_RETURN_IF_ERROR(files.check());
    VISTA_RETURN_IF_ERROR(checkWritablePath("--output", j.output));
    if (!j.statsFile.empty()) VISTA_RETURN_IF_ERROR(checkWritablePath("--stats", j.statsFile));
    VISTA_RETURN_IF_ERROR(checkWritableDirectory("--work", j.workDir.empty() ? j.output + ".work" : j.workDir));
    return Status::ok();
}

namespace {

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
    j["memory_mb_uncompressed"] =
        double(r.data.positions.size() * (kPointBytes + 4 * size_t(r.data.texelsX * r.data.texelsY))) /
        (1024.0 * 1024.0);
    j["bake_s"] = s.bakeMs / 1000.0;
    return j;
}

nlohmann::json meshStatsJson(const MeshResult& r) {
    const MeshStats& s = r.stats;
    nlohmann::json j;
    j["cell"] = r.cell;
    j["end"] = int(r.end);
    j["tiles"] = s.tiles;
    j["far_triangles"] = s.farTriangles;
    j["image"] = {s.imageW, s.imageH};
    j["hit_samples"] = s.hits;
    j["leaves"] = s.leaves;
    j["triangles"] = s.triangles;
    j["vertices"] = r.mesh.positions.size();
    j["dropped_triangles"] = s.droppedTriangles;
    j["snapped_vertices"] = s.snapped;
    j["max_leaf_error_px"] = s.maxLeafErrorPx;
    j["memory_mb"] = double(depthMeshBytes(r.mesh)) / (1024.0 * 1024.0);
    j["bake_s"] = s.bakeMs / 1000.0;
    return j;
}

// Area (m^2) of the street graph's bounding box, at least 1 km^2 (the
// automatic storage budget's measure of the city).
double streetArea(const StreetGraph& g) {
    glm::dvec2 lo(1e300), hi(-1e300);
    for (const glm::dvec2& q : g.nodes) {
        lo = glm::min(lo, q);
        hi = glm::max(hi, q);
    }
    return lo.x <= hi.x ? std::max((hi.x - lo.x) * (hi.y - lo.y), 1e6) : 1e6;
}

// Bakes in.cells[todo[k]] on `arena`, each result written atomically as soon
// as it is done; progress from this thread while a worker thread runs the loop.
Status bakeCells(const BakeInput& in, const std::vector<size_t>& todo, const BakeParams& p, uint64_t configHash,
                 const std::string& workDir, tbb::task_arena& arena, Progress* progress) {
    std::atomic<size_t> done{0};
    std::atomic<bool> failed{false};
    std::string failure;
    std::mutex failMu;
    if (progress) progress->begin("bake");
    std::thread worker([&] {
        arena.execute([&] {
            tbb::parallel_for(size_t(0), todo.size(), size_t(1), [&](size_t k) {
                if (failed) return;
                const ViewCell& c = in.cells[todo[k]];
                const CellResult r = bakeCell(in, c, p);
                if (Status s = writeFileAtomic(cellPath(workDir, c.id), encodeCellResult(r, configHash)); !s) {
                    std::lock_guard<std::mutex> l(failMu);
                    failure = s.message();
                    failed = true;
                }
                ++done;
            });
        });
    });
    while (done.load() < todo.size() && !failed) {
        if (progress) progress->update(double(done.load()) / double(std::max<size_t>(todo.size(), 1)));
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    worker.join();
    if (progress) progress->end();
    return failed ? Status::error(failure) : Status::ok();
}

// The cells of the job (indices into in.cells): --cells or all, in order.
Result<std::vector<size_t>> selectCells(const BakeJob& job, const BakeInput& in, size_t edges) {
    std::vector<size_t> selected;
    if (job.cells.empty()) {
        for (size_t i = 0; i < in.cells.size(); ++i) selected.push_back(i);
        return selected;
    }
    for (uint32_t id : job.cells) {
        auto it = std::find_if(in.cells.begin(), in.cells.end(), [&](const ViewCell& c) { return c.id == id; });
        if (it == in.cells.end())
            return Status::error(
                "--cells: cell " + std::to_string(id) + " does not exist (" +
                (edges == 0 ? std::string("the city has no street edges")
                            : "cells are street edges 0.." + std::to_string(edges - 1) + ", minus degenerate ones") +
                ")");
        selected.push_back(size_t(it - in.cells.begin()));
    }
    return selected;
}

// This shard's part of the selected cells (every N-th, starting at K - 1).
std::vector<size_t> shardOf(const BakeJob& job, const std::vector<size_t>& selected) {
    std::vector<size_t> mine;
    for (size_t k = 0; k < selected.size(); ++k)
        if (int(k % size_t(job.shardN)) == job.shardK - 1) mine.push_back(selected[k]);
    return mine;
}

// Bakes the cells of `mine` that have no valid result in the work directory yet.
Status bakeMissingCells(const BakeJob& job, BakeInput& in, const std::vector<size_t>& mine, const BakeParams& p,
                        uint64_t configHash, BakeReport& rep, Progress* progress,
                        const std::function<void(const std::string&)>& log) {
    std::vector<size_t> todo;
    for (size_t ci : mine) {
        auto b = readAll(cellPath(rep.workDir, in.cells[ci].id));
        if (b && decodeCellResult(*b, configHash, "").isOk()) continue;
        todo.push_back(ci);
    }
    rep.baked = todo.size();
    rep.resumed = mine.size() - todo.size();
    if (log)
        log(std::to_string(mine.size()) + " cells (" + std::to_string(todo.size()) + " in this run, " +
            std::to_string(rep.resumed) + " already done), " + std::to_string(in.skipped.size()) +
            " degenerate edges skipped");
    tbb::task_arena arena(job.jobs > 0 ? job.jobs : tbb::task_arena::automatic);
    if (!todo.empty() && p.representation == BakeRepresentation::Points && p.placement.byCost &&
        p.placement.budgetMb > 0 && in.cityRays) {
        // The storage budget ranks every street end of the city, so every run
        // (shard, resume) plans the whole city the same way.
        std::atomic<size_t> done{0};
        PlacementPlan plan;
        if (progress) progress->begin("plan");
        std::thread worker([&] { arena.execute([&] { plan = planPlacement(in, p, &done); }); });
        while (done.load() < in.cells.size()) {
            if (progress) progress->update(double(done.load()) / double(std::max<size_t>(in.cells.size(), 1)));
            std::this_thread::sleep_for(std::chrono::milliseconds(100));
        }
        worker.join();
        if (progress) progress->end();
        if (log) {
            char buf[200];
            std::snprintf(buf, sizeof buf,
                          "storage budget %.1f MB: %zu of %zu street ends that pay (%.1f of %.1f MB predicted)",
                          p.placement.budgetMb, plan.chosen, plan.paying, plan.chosenMb, plan.payingMb);
            log(buf);
        }
        in.plan = std::make_shared<const PlacementPlan>(std::move(plan));
    }
    return bakeCells(in, todo, p, configHash, rep.workDir, arena, progress);
}

// Every selected cell's result from the work directory, sorted by cell id;
// an error listing the missing or stale ones.
Result<std::vector<CellResult>> readCellResults(const BakeInput& in, const std::vector<size_t>& selected,
                                                uint64_t configHash, const std::string& workDir) {
    std::vector<CellResult> results;
    std::vector<uint32_t> missing;
    for (size_t ci : selected) {
        const uint32_t id = in.cells[ci].id;
        auto b = readAll(cellPath(workDir, id));
        auto r = b ? decodeCellResult(*b, configHash, cellPath(workDir, id)) : Result<CellResult>(b.status());
        if (r) results.push_back(std::move(*r));
        else missing.push_back(id);
    }
    if (!missing.empty()) {
        std::string list;
        for (size_t i = 0; i < missing.size() && i < 20; ++i) list += (i ? "," : "") + std::to_string(missing[i]);
        if (missing.size() > 20) list += ",...";
        return Status::error(std::to_string(missing.size()) + " cell results missing or stale in '" + workDir +
                             "' (cells " + list + "); bake them first (all shards with the same parameters)");
    }
    std::sort(results.begin(), results.end(), [](const CellResult& a, const CellResult& b) { return a.cell < b.cell; });
    return results;
}

// Totals of the assembled results into `rep`; the per-impostor statistics as JSON.
nlohmann::json tallyResults(const std::vector<CellResult>& results, BakeReport& rep) {
    double cellMs = 0;
    nlohmann::json js = nlohmann::json::array();
    for (const auto& r : results) {
        cellMs += r.bakeMs;
        for (const auto& n : r.notes) rep.notes.push_back("cell " + std::to_string(r.cell) + ": " + n);
        for (const auto& im : r.impostors) {
            ++rep.impostors;
            rep.points += im.stats.points;
            js.push_back(statsJson(im));
        }
        for (const auto& m : r.meshes) {
            ++rep.meshes;
            rep.meshTriangles += m.mesh.triangleCount();
            js.push_back(meshStatsJson(m));
        }
    }
    rep.cellBakeS = cellMs / 1000.0;
    return js;
}

Status writeStatsFile(const BakeJob& job, const std::string& path, const BakeReport& rep, size_t cells,
                      const std::string& canon, nlohmann::json impostorStats) {
    nlohmann::json top;
    top["input"] = job.input;
    top["cells"] = cells;
    top["impostors"] = rep.impostors;
    top["points"] = rep.points;
    if (job.params.representation == BakeRepresentation::Mesh) {
        top["representation"] = "mesh";
        top["meshes"] = rep.meshes;
        top["mesh_triangles"] = rep.meshTriangles;
    }
    top["cell_bake_s_sum"] = rep.cellBakeS;
    top["wall_s"] = rep.wallS;
    top["output_bytes"] = rep.outputBytes;
    top["params"] = canon;
    if (job.params.representation == BakeRepresentation::Points && job.params.placement.byCost)
        top["storage_budget_mb"] = rep.budgetMb;
    top["impostor_stats"] = std::move(impostorStats);
    top["notes"] = rep.notes;
    return writeFileAtomic(path, top.dump(1));
}

}  // namespace

Result<BakeReport> runBakeJob(const BakeJob& job, Progress* progress,
                              const std::function<void(const std::string&)>& log) {
    VISTA_RETURN_IF_ERROR(validateBakeJob(job));
    CommandFiles files = bakeFiles(job);  // held until the outputs are written (the locks)
    VISTA_RETURN_IF_ERROR(files.check());
    const Stopwatch wall;
    BakeReport rep;
    rep.workDir = job.workDir.empty() ? job.output + ".work" : job.workDir;
    auto city = loadCityFile(job.input);
    if (!city) return city.status();
    if (dynamic_cast<ViewCellSwitch*>(sceneRoot(*city)))
        return Status::error("'" + job.input + "' is already baked; bake the plain city file");
    BakeParams p = job.params;
    p.seed = city->params.seed;
    if (p.placement.budgetMbPerKm2 > 0)
        p.placement.budgetMb = p.placement.budgetMbPerKm2 * streetArea(city->streets) * 1e-6;
    const std::string canon = p.canonical();
    uint64_t configHash = 0;  // of the input's bytes and the parameters: a cell result is reused only under both
    {
        auto bytes = readAll(job.input);
        if (!bytes) return bytes.status();
        configHash = hashBytes64(bytes->data(), bytes->size(), hashBytes64(canon.data(), canon.size()));
    }
    BakeInput in = prepareBake(*city, p);
    rep.skippedEdges = in.skipped.size();
    rep.budgetMb = p.placement.budgetMb;

    auto selected = selectCells(job, in, city->streets.edges.size());
    if (!selected) return selected.status();
    const std::vector<size_t> mine = shardOf(job, *selected);
    rep.cells = selected->size();
    rep.shardCells = mine.size();
    std::error_code ec;
    CreatedDirectories made;  // a run that leaves the work directory it made empty removes it
    VISTA_RETURN_IF_ERROR(made.create("--work", rep.workDir));
    if (access(rep.workDir.c_str(), W_OK) != 0)
        return Status::error("--work '" + rep.workDir + "': cannot write the directory: " + errnoText());

    if (!job.merge) {
        VISTA_RETURN_IF_ERROR(bakeMissingCells(job, in, mine, p, configHash, rep, progress, log));
        made.keep();
        if (job.shardN > 1) {  // a shard bakes; --merge assembles
            rep.wallS = wall.ms() / 1000.0;
            return rep;
        }
    }

    auto results = readCellResults(in, *selected, configHash, rep.workDir);
    if (!results) return results.status();
    auto sourceHash = sceneFileContentHash(job.input);  // recorded so that readers can refuse a bake of another city
    if (!sourceHash) return sourceHash.status();
    osg::ref_ptr<ViewCellSwitch> root =
        assembleBakedScene(*city, in.cells, *results, canon, p.representation, *sourceHash);
    // The baked file and the stats: both or neither.
    OutputBatch batch;
    const std::string staged = batch.stage(job.output);
    VISTA_RETURN_IF_ERROR(writeSceneFile(*root, staged, false));
    nlohmann::json impostorStats = tallyResults(*results, rep);
    const auto size = std::filesystem::file_size(staged, ec);
    rep.outputBytes = ec ? 0 : uint64_t(size);
    rep.wallS = wall.ms() / 1000.0;
    if (!job.statsFile.empty())
        VISTA_RETURN_IF_ERROR(
            writeStatsFile(job, batch.stage(job.statsFile), rep, results->size(), canon, std::move(impostorStats)));
    VISTA_RETURN_IF_ERROR(batch.commit());
    rep.assembled = true;
    if (!job.keepWork) {
        for (size_t ci : *selected) std::filesystem::remove(cellPath(rep.workDir, in.cells[ci].id), ec);
        std::filesystem::remove(rep.workDir, ec);  // only if empty
    }
    return rep;
}

}  // namespace vista
