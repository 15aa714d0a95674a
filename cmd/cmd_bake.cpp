// vista bake: view cells + point impostors at street ends (docs/bake.md).
// Parses the options into a BakeJob and runs it (bake/driver.h).
#include <cstdio>
#include <optional>
#include <unistd.h>

#include "bake/driver.h"
#include "cmd/cli.h"
#include "cmd/commands.h"
#include "cmd/options.h"
#include "foundation/shard.h"

namespace vista {

namespace {

const char* const kCmd = "vista bake";

struct BakeArgs {
    BakeJob job;
    std::optional<std::string> cellList;  // unset: every cell
    std::string shard, texels = "8x2", representation = "points", placement = "cost", budget = "auto",
                       visibility = "image";
    bool quiet = false, noRemoval = false;
};

// A whole-number flag within its bake_range (bake/driver.h).
template <class T>
CLI::Option* addWhole(CLI::App& app, const std::string& name, T& value, const RealRange& r, const std::string& help) {
    return addNumberOption(app, name, value, T(r.min), T(r.max), help);
}

void declareFlags(CLI::App& app, BakeArgs& a) {
    BakeJob& job = a.job;
    BakeParams& p = job.params;
    namespace R = bake_range;
    app.add_option("city", job.input, "input city file (.osgb from 'vista gen')")->required();
    app.add_option("-o,--output", job.output, "baked output file (.osgb)")->required();
    addWhole(app, "--jobs", job.jobs, R::jobs, "worker threads, 0 .. 1024 (0 = all cores)");
    app.add_option("--cells", a.cellList, "bake only these cell ids (= street edge ids), e.g. 3,7,10-20");
    app.add_option("--shard", a.shard,
                   "bake shard K of N (K = 1..N) of the cells into the work directory; assemble with --merge");
    app.add_flag("--merge", job.merge, "assemble the output from the work directory (after sharded bakes)");
    app.add_option("--work", job.workDir, "work directory for per-cell results (default: OUTPUT.work)");
    app.add_flag("--keep-work", job.keepWork, "keep the work directory after a successful assembly");
    app.add_option("--stats", job.statsFile, "write per-impostor statistics (JSON)");
    app.add_flag("-q,--quiet", a.quiet, "no progress output");
    addNumberOption(app, "--margin", p.far.margin, R::margin,
                    "far field starts this many metres beyond the street end, 0 .. 100000")
        ->capture_default_str();
    addNumberOption(app, "--far-depth", p.far.farDepth, R::farDepth,
                    "metres of far field beyond the margin, 1 .. 1000000")
        ->capture_default_str();
    addWhole(app, "--min-triangles", p.far.minTriangles, R::minTriangles,
             "skip street ends whose far field has fewer triangles, 0 .. 1000000000")
        ->capture_default_str();
    addNumberOption(app, "--oversample", p.sampling.oversample, R::oversample,
                    "LDI resolution factor over the criterion, 0.05 .. 16")
        ->capture_default_str();
    addNumberOption(app, "--perspective", p.sampling.perspective, R::perspective,
                    "perspective factor fp of the sampling criterion, 1 .. 4 (thesis: 1.17)")
        ->capture_default_str();
    addNumberOption(app, "--texel-significance", p.appearance.significance, R::significance,
                    "F-test level for view-dependent texels, 0 .. 0.5 (0 = off: the colour spread alone decides)")
        ->capture_default_str();
    addNumberOption(app, "--pixel-sigma", p.appearance.pixelSigma, R::pixelSigma,
                    "Monte Carlo pixel filter: Gaussian sigma in output pixels added to the box, 0 .. 4 (the monitor "
                    "filter; 0 = box only)")
        ->capture_default_str();
    addWhole(app, "--layers", p.sampling.maxLayers, R::layers, "LDI layers per pixel, 1 .. 64")->capture_default_str();
    addWhole(app, "--max-rays", p.sampling.maxRaysPerCamera, R::maxRays, "cap on LDI rays per camera, 1 .. 1000000000")
        ->capture_default_str();
    app.add_flag("--no-removal", a.noRemoval, "keep points sampled better by another camera");
    app.add_option("--texels", a.texels, "texels per point: 1, 4x1, 8x2 (default 8x2)");
    addNumberOption(app, "--mc-threshold", p.appearance.varianceThreshold, R::mcThreshold,
                    "Monte Carlo stop: std error of a texel's luma (0..1)")
        ->capture_default_str();
    addWhole(app, "--mc-min", p.appearance.minSamples, R::mcMin, "Monte Carlo samples per texel, first pass, 1 .. 4096")
        ->capture_default_str();
    addWhole(app, "--mc-max", p.appearance.maxSamples, R::mcMax,
             "Monte Carlo samples per texel, maximum, --mc-min .. 65536")
        ->capture_default_str();
    addNumberOption(app, "--single-threshold", p.appearance.singleColorThreshold, R::singleThreshold,
                    "colour std dev (0..1) for single-colour points")
        ->capture_default_str();
    addWhole(app, "--out-size", p.sampling.outHeight, R::outSize,
             "target output height in pixels, 16 .. 8192 (width = 4/3 height)")
        ->capture_default_str();
    addNumberOption(app, "--fov", p.sampling.fovYDeg, R::fov, "target output vertical field of view, degrees, 1 .. 170")
        ->capture_default_str();
    app.add_option("--representation", a.representation,
                   "far-field representation per view cell: points (point impostors, thesis ch. 5) or mesh (textured "
                   "depth meshes, "
                   "Chen et al. 2003)")
        ->capture_default_str();
    app.add_option(
           "--placement", a.placement,
           "points: cost = an impostor only where it saves more raster time than its points cost (bake/placement.h); "
           "all = at every street end with a far field")
        ->capture_default_str();
    addNumberOption(app, "--triangle-ns", p.placement.triangleNs, R::rasterNs,
                    "placement: raster cost of a triangle, ns, (0, 1e9) (measured here)")
        ->capture_default_str();
    addNumberOption(app, "--point-ns", p.placement.pointNs, R::rasterNs,
                    "placement: raster cost of a point, ns, (0, 1e9) (measured here)")
        ->capture_default_str();
    app.add_option("--storage-budget", a.budget,
                   "points: auto (" + std::to_string(int(kAutoBudgetMbPerKm2)) +
                       " MB per km2 of the street graph's bounding box), off, or MB: impostors only at the street ends "
                       "that save the "
                       "most raster time per predicted MB, until the budget is spent")
        ->capture_default_str();
    app.add_option("--visibility", a.visibility,
                   "points: how the cell's viewpoints test the baked points: image (a depth image per viewpoint, then "
                   "rays for the "
                   "points it leaves) or rays (one occlusion ray per point and viewpoint)")
        ->capture_default_str();
    addWhole(app, "--mesh-triangles", p.mesh.maxTriangles, R::meshTriangles,
             "mesh: triangle budget per view cell (half per street end), 1024 .. 10000000")
        ->capture_default_str();
    addWhole(app, "--mesh-image", p.mesh.imageSize, R::meshImage,
             "mesh: largest side of the far-field image in pixels, 64 .. 4096")
        ->capture_default_str();
    addNumberOption(app, "--mesh-error", p.mesh.errorPx, R::meshError,
                    "mesh: stop refining below this parallax error, 0 .. 100 (pixels, for a viewer at the cell's "
                    "corner)")
        ->capture_default_str();
}

// The flags into the job; errors name the flag.
Status configure(BakeArgs& a) {
    BakeJob& job = a.job;
    BakeParams& p = job.params;
    p.sampling.outWidth = p.sampling.outHeight * 4 / 3;
    p.sampling.removeRedundant = !a.noRemoval;

    VISTA_RETURN_IF_ERROR(parseTexels(a.texels, p.appearance.texelsX, p.appearance.texelsY));
    auto repr = parseRepresentation(a.representation);
    if (!repr) return repr.status();
    p.representation = *repr;
    if (a.placement != "cost" && a.placement != "all")
        return Status::error("--placement '" + a.placement + "': unknown (allowed: cost, all)");
    p.placement.byCost = a.placement == "cost";
    if (a.visibility != "image" && a.visibility != "rays")
        return Status::error("--visibility '" + a.visibility + "': unknown (allowed: image, rays)");
    p.placement.visByImage = a.visibility == "image";
    auto mb = parseStorageBudget(a.budget);
    if (!mb) return mb.status();
    if (*mb < 0) p.placement.budgetMbPerKm2 = kAutoBudgetMbPerKm2;
    else p.placement.budgetMb = *mb;
    VISTA_RETURN_IF_ERROR(validateBakeJob(job));
    if (!a.shard.empty()) {
        auto sh = parseShard("--shard", a.shard);
        if (!sh) return sh.status();
        job.shardK = sh->k();
        job.shardN = sh->count;
    }
    if (job.merge && !a.shard.empty()) return Status::error("--merge and --shard exclude each other");
    if (a.cellList) {
        auto ids = parseCellList(*a.cellList);
        if (!ids) return ids.status();
        job.cells = std::move(*ids);
    }
    return Status::ok();
}

// The closing line on stderr: a shard's cells and how to assemble, or the output's counts.
void printReport(const BakeArgs& a, const BakeReport& r) {
    const BakeJob& job = a.job;
    const std::string cellList = a.cellList.value_or("");
    if (!r.assembled)
        std::fprintf(stderr,
                     "vista bake: shard %d/%d done (%zu cells) in %s; assemble with 'vista bake %s -o %s --merge%s'\n",
                     job.shardK, job.shardN, r.shardCells, r.workDir.c_str(), job.input.c_str(), job.output.c_str(),
                     cellList.empty() ? "" : (" --cells " + cellList).c_str());
    else if (job.params.representation == BakeRepresentation::Mesh)
        std::fprintf(stderr,
                     "vista bake: wrote %s: %zu cells, %zu textured depth meshes, %zu triangles, %.1f MB, %.1f s (cell "
                     "bake time %.1f s)\n",
                     job.output.c_str(), r.cells, r.meshes, r.meshTriangles, double(r.outputBytes) / 1048576.0, r.wallS,
                     r.cellBakeS);
    else
        std::fprintf(
            stderr,
            "vista bake: wrote %s: %zu cells, %zu impostors, %zu points, %.1f MB, %.1f s (cell bake time %.1f s)\n",
            job.output.c_str(), r.cells, r.impostors, r.points, double(r.outputBytes) / 1048576.0, r.wallS,
            r.cellBakeS);
}

}  // namespace

// The steps: flags, job, bake (bake/driver.h), report.
int runBake(int argc, char** argv) {
    CLI::App app{
        "Bake view cells (from street segments) and point-based impostors at street ends into a baked city file.",
        kCmd};
    BakeArgs a;
    declareFlags(app, a);
    const int rc = parseOrExit(app, argc, argv);
    if (rc >= 0) return rc;
    if (Status s = configure(a); !s) return reportBadInput(kCmd, s);
    StderrProgress progress(isatty(2) != 0);
    auto log = [](const std::string& line) { std::fprintf(stderr, "vista bake: %s\n", line.c_str()); };
    auto report = runBakeJob(a.job, a.quiet ? nullptr : &progress,
                             a.quiet ? nullptr : std::function<void(const std::string&)>(log));
    if (!report) return reportBadInput(kCmd, report.status());
    if (!a.quiet) printReport(a, *report);
    return 0;
}

}  // namespace vista
