// The bake driver: a whole bake (`vista bake`) as one library call
// (docs/reference/bake.md "Work directory, resume, shards").
//
// runBakeJob() loads the city file, selects the cells (job.cells, or all;
// then every shardN-th from offset shardK - 1), bakes those of this shard
// whose result file WORK/cell_ID.vbc is missing, stale (other config hash) or
// damaged — each written atomically when done, `jobs` threads — and then,
// unless it is one shard of several, assembles the output from the work
// directory (every selected cell must be there) with the input's content
// hash as vista.source_city_hash (sceneFileContentHash), writes it atomically,
// writes the stats JSON and removes the cell files (and the work directory
// when empty) unless keepWork. With merge it bakes nothing, only assembles.
// Storage budget (points, placement by cost, params.placement.budgetMb > 0,
// or budgetMbPerKm2 > 0: budgetMb = that x the street graph's bounding box
// area, at least 1 km2): before baking, a run with cells to bake plans the
// whole city (planPlacement, progress stage "plan"); every run plans alike.
// Config hash = hash(input file bytes, params.canonical()); the canonical
// text names the representation and the mesh parameters of a mesh bake.
// Determinism: output bytes depend only on (input file, params, cells), not
// on jobs, shards, interruptions or resumption. A kill at any moment leaves
// only whole cell files.
// Errors (Status naming the option, value and range, or the file): every
// value of the job (validateBakeJob; it also refuses an output, stats or work
// path that cannot be written, before the input is read), a missing, baked or
// malformed input, a cell that does not exist, cell results missing at
// assembly, failed writes (with the cause, e.g. a full disk).
// progress: begin/update (fraction of this run's cells; ETA)/end, called from
// the calling thread. log: one line before baking (cells, already done,
// skipped edges). One writer per output: runBakeJob holds the locks of the
// output, stats and work directory (foundation/output_lock.h) for the whole
// run, shared among the shards of one bake; another bake of them exits at once.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "bake/bake_params.h"
#include "foundation/number_text.h"
#include "foundation/progress.h"
#include "foundation/status.h"

namespace vista {

struct BakeJob {
    std::string input;            // city file from `vista gen`
    std::string output;           // baked file
    std::string workDir;          // per-cell results; "" = output + ".work"
    std::string statsFile;        // per-impostor statistics (JSON); "" = none
    std::vector<uint32_t> cells;  // cell ids (= street edge ids) to bake; empty = all
    int shardK = 1, shardN = 1;   // this run bakes shard K of N (1 <= K <= N)
    bool merge = false;           // only assemble from the work directory
    bool keepWork = false;        // keep the work directory after assembly
    int jobs = 0;                 // worker threads, 0 = all cores (0 .. 1024)
    BakeParams params;            // params.seed is taken from the city file
};

struct BakeReport {
    std::string workDir;                   // as resolved
    size_t cells = 0;                      // selected cells
    size_t shardCells = 0;                 // cells of this shard
    size_t baked = 0, resumed = 0;         // of this shard: baked now / found done in the work directory
    size_t skippedEdges = 0;               // degenerate street edges (no cell)
    bool assembled = false;                // false after one shard of several
    size_t impostors = 0, points = 0;      // in the output
    size_t meshes = 0, meshTriangles = 0;  // in the output (--representation mesh)
    uint64_t outputBytes = 0;
    double wallS = 0;                // this call
    double cellBakeS = 0;            // sum of the assembled cells' bake times
    std::vector<std::string> notes;  // the assembled cells' notes, "cell C: end E: ..." (--stats "notes")
    double budgetMb = 0;             // the storage budget as resolved (0: none)
};

// The range of each number of a job, named by its `vista bake` flag:
// validateBakeJob checks them and the command reads its flags within them
// (integers have whole bounds). --mc-max is also at least --mc-min; the mesh
// ranges are checked for a mesh bake.
namespace bake_range {
constexpr RealRange jobs = RealRange::closed(0, 1024), margin = RealRange::closed(0, 1e5),
                    farDepth = RealRange::closed(1, 1e6), minTriangles = RealRange::closed(0, 1e9),
                    oversample = RealRange::closed(0.05, 16), perspective = RealRange::closed(1, 4),
                    significance = RealRange::closed(0, 0.5), pixelSigma = RealRange::closed(0, 4),
                    layers = RealRange::closed(1, 64), maxRays = RealRange::closed(1, 1e9),
                    mcThreshold = RealRange::closed(0, 1), mcMin = RealRange::closed(1, 4096),
                    mcMax = RealRange::closed(1, 65536), singleThreshold = RealRange::closed(0, 1),
                    outSize = RealRange::closed(16, 8192), fov = RealRange::closed(1, 170),
                    texels = RealRange::closed(1, 32), rasterNs = RealRange::open(0, 1e9),
                    meshTriangles = RealRange::closed(1024, 1e7), meshImage = RealRange::closed(64, 4096),
                    meshError = RealRange::closed(0, 100);
}  // namespace bake_range

Status validateBakeJob(const BakeJob& job);
Result<BakeReport> runBakeJob(const BakeJob& job, Progress* progress = nullptr,
                              const std::function<void(const std::string&)>& log = {});

}  // namespace vista
