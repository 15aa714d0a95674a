// vista bake: view cells + point impostors at street ends (docs/bake.md).
// Parses the options into a BakeJob and runs it (bake/driver.h).
#include <cstdio>
#include <unistd.h>

#include "bake/driver.h"
#include "cmd/cli.h"
#include "cmd/commands.h"
#include "cmd/options.h"
#include "foundation/shard.h"

namespace vista {

int runBake(int argc, char** argv) {
    const std::string cmd = "vista bake";
    CLI::App app{"Bake view cells (from street segments) and point-based impostors at street ends into a baked city file.",
                 cmd};
    BakeJob job;
    BakeParams& p = job.params;
    std::string cellList, shard, texels = "8x2", representation = "points", placement = "cost", budget = "auto",
                visibility = "image";
    bool quiet = false, noRemoval = false;
    app.add_option("city", job.input, "input city file (.osgb from 'vista gen')")->required();
    app.add_option("-o,--output", job.output, "baked output file (.osgb)")->required();
    app.add_option("--jobs", job.jobs, "worker threads (0 = all cores)");
    app.add_option("--cells", cellList, "bake only these cell ids (= street edge ids), e.g. 3,7,10-20");
    app.add_option("--shard", shard, "bake shard K of N (K = 1..N) of the cells into the work directory; assemble with --merge");
    app.add_flag("--merge", job.merge, "assemble the output from the work directory (after sharded bakes)");
    app.add_option("--work", job.workDir, "work directory for per-cell results (default: OUTPUT.work)");
    app.add_flag("--keep-work", job.keepWork, "keep the work directory after a successful assembly");
    app.add_option("--stats", job.statsFile, "write per-impostor statistics (JSON)");
    app.add_flag("-q,--quiet", quiet, "no progress output");
    app.add_option("--margin", p.far.margin, "far field starts this many metres beyond the street end")->capture_default_str();
    app.add_option("--far-depth", p.far.farDepth, "metres of far field beyond the margin")->capture_default_str();
    app.add_option("--min-triangles", p.far.minTriangles, "skip street ends whose far field has fewer triangles")->capture_default_str();
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
    app.add_option("--representation", representation,
                   "far-field representation per view cell: points (point impostors, thesis ch. 5) or mesh (textured depth meshes, "
                   "Chen et al. 2003)")
        ->capture_default_str();
    app.add_option("--placement", placement,
                   "points: cost = an impostor only where it saves more raster time than its points cost (bake/placement.h); "
                   "all = at every street end with a far field")
        ->capture_default_str();
    app.add_option("--triangle-ns", p.placement.triangleNs, "placement: raster cost of a triangle, ns (measured here)")->capture_default_str();
    app.add_option("--point-ns", p.placement.pointNs, "placement: raster cost of a point, ns (measured here)")->capture_default_str();
    app.add_option("--storage-budget", budget,
                   "points: auto (" + std::to_string(int(kAutoBudgetMbPerKm2)) +
                       " MB per km2 of the street graph's bounding box), off, or MB: impostors only at the street ends that save the "
                       "most raster time per predicted MB, until the budget is spent")
        ->capture_default_str();
    app.add_option("--visibility", visibility,
                   "points: how the cell's viewpoints test the baked points: image (a depth image per viewpoint, then rays for the "
                   "points it leaves) or rays (one occlusion ray per point and viewpoint)")
        ->capture_default_str();
    app.add_option("--mesh-triangles", p.mesh.maxTriangles, "mesh: triangle budget per view cell (half per street end)")
        ->capture_default_str();
    app.add_option("--mesh-image", p.mesh.imageSize, "mesh: largest side of the far-field image in pixels")->capture_default_str();
    app.add_option("--mesh-error", p.mesh.errorPx, "mesh: stop refining below this parallax error (pixels, for a viewer at the cell's corner)")
        ->capture_default_str();
    const int rc = parseOrExit(app, argc, argv);
    if (rc >= 0) return rc;
    p.sampling.outWidth = p.sampling.outHeight * 4 / 3;
    p.sampling.removeRedundant = !noRemoval;

    if (Status s = parseTexels(texels, p.appearance.texelsX, p.appearance.texelsY); !s) return reportBadInput(cmd, s);
    auto repr = parseRepresentation(representation);
    if (!repr) return reportBadInput(cmd, repr.status());
    p.representation = *repr;
    if (placement != "cost" && placement != "all")
        return reportBadInput(cmd, Status::error("--placement '" + placement + "': unknown (allowed: cost, all)"));
    p.placement.byCost = placement == "cost";
    if (!(p.placement.triangleNs > 0 && p.placement.triangleNs < 1e9) || !(p.placement.pointNs > 0 && p.placement.pointNs < 1e9))
        return reportBadInput(cmd, Status::error("--triangle-ns / --point-ns: " + std::to_string(p.placement.triangleNs) + " / " +
                                                 std::to_string(p.placement.pointNs) + " out of range (0, 1e9) ns"));
    if (visibility != "image" && visibility != "rays")
        return reportBadInput(cmd, Status::error("--visibility '" + visibility + "': unknown (allowed: image, rays)"));
    p.placement.visByImage = visibility == "image";
    auto mb = parseStorageBudget(budget);
    if (!mb) return reportBadInput(cmd, mb.status());
    if (*mb < 0) p.placement.budgetMbPerKm2 = kAutoBudgetMbPerKm2;
    else p.placement.budgetMb = *mb;
    if (Status s = validateBakeJob(job); !s) return reportBadInput(cmd, s);
    if (!shard.empty()) {
        auto sh = parseShard("--shard", shard);
        if (!sh) return reportBadInput(cmd, sh.status());
        job.shardK = sh->k();
        job.shardN = sh->count;
    }
    if (job.merge && !shard.empty()) return reportBadInput(cmd, Status::error("--merge and --shard exclude each other"));
    if (!cellList.empty()) {
        auto ids = parseCellList(cellList);
        if (!ids) return reportBadInput(cmd, ids.status());
        job.cells = std::move(*ids);
    }

    StderrProgress progress(isatty(2) != 0);
    auto log = [](const std::string& line) { std::fprintf(stderr, "vista bake: %s\n", line.c_str()); };
    auto report = runBakeJob(job, quiet ? nullptr : &progress, quiet ? nullptr : std::function<void(const std::string&)>(log));
    if (!report) return reportBadInput(cmd, report.status());
    const BakeReport& r = *report;
    if (quiet) return 0;
    if (!r.assembled)
        std::fprintf(stderr, "vista bake: shard %d/%d done (%zu cells) in %s; assemble with 'vista bake %s -o %s --merge%s'\n", job.shardK,
                     job.shardN, r.shardCells, r.workDir.c_str(), job.input.c_str(), job.output.c_str(),
                     cellList.empty() ? "" : (" --cells " + cellList).c_str());
    else if (p.representation == BakeRepresentation::Mesh)
        std::fprintf(stderr, "vista bake: wrote %s: %zu cells, %zu textured depth meshes, %zu triangles, %.1f MB, %.1f s (cell bake time %.1f s)\n",
                     job.output.c_str(), r.cells, r.meshes, r.meshTriangles, double(r.outputBytes) / 1048576.0, r.wallS, r.cellBakeS);
    else
        std::fprintf(stderr, "vista bake: wrote %s: %zu cells, %zu impostors, %zu points, %.1f MB, %.1f s (cell bake time %.1f s)\n",
                     job.output.c_str(), r.cells, r.impostors, r.points, double(r.outputBytes) / 1048576.0, r.wallS, r.cellBakeS);
    return 0;
}

}  // namespace vista
