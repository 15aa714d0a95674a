// Memory as a measured budget: the process's resident memory per phase and
// an up-front estimate checked against `--memory-budget GB`.
//
// The estimate of a run that loads a city file (bench, view, bake) is linear
// in the file's size, from peaks measured on this machine (docs/performance.md
// "Memory"): the loaded scene graph, the decoded model and the 40 m chunks
// come to about 4 bytes per file byte, the Embree ray scene to about 1.7 more
// (modes that cast rays), plus a fixed 200 MB (GL context, TBB, libraries).
// It is an estimate, not a bound: summary.json reports it beside the measured
// peak so that its error is on record for every run.
#pragma once
#include <cstdint>
#include <string>

#include "foundation/number_text.h"
#include "foundation/status.h"

namespace vista {

struct MemoryPhase {
    std::string name;
    double peakRssMb = 0;  // peak resident set size of the process so far (MiB)
    double rssMb = 0;      // resident set size at the end of the phase (MiB)
};
// The phase just ended, measured now.
MemoryPhase memoryPhase(const std::string& name);

// --memory-budget GB of bench, view and gen (addNumberOption): a number of GB
// in (0, 65536]; not given = no budget (0).
constexpr RealRange kMemoryBudgetGbRange = RealRange::openMin(0, 65536);
// Estimated peak (MiB) of a run on a city file of `fileBytes` bytes.
double estimateCityRunMb(uint64_t fileBytes, bool rayScene);
// Ok when there is no budget or the estimate fits it; otherwise an error that
// gives the estimate, what it is made of and the budget.
Status checkMemoryBudget(const std::string& option, double budgetGb, double estimateMb, uint64_t fileBytes,
                         bool rayScene);

// The streamed regions' share of a budget (--paged-stream): what is left of
// `budgetGb` after `preloadMb` (the estimate of what is held before the first
// frame) or the run's own fixed memory (kStreamFixedMb, 700 MB), the larger,
// in bytes: the pager's unit (region_pager.h budgetBytes), which
// weighs each load's file bytes by what the stream makes of them
// (nodes/render/city_stream.h streamRegionCost). 0 = no budget. An error
// naming the option when nothing is left.
Result<uint64_t> streamBudgetBytes(const std::string& option, double budgetGb, double preloadMb);

// `vista gen` to one file: peak about kGenBytesPerStoredTriangle per stored
// triangle (measured 152 to 177 on the 0.5 to 8 km cities of
// docs/performance.md) + kGenFixedMb; the triangles come from
// estimateStoredTriangles() on the laid-out city, before its meshes are made.
constexpr double kGenBytesPerStoredTriangle = 180.0, kGenFixedMb = 100.0;
double estimateGenMb(size_t storedTriangles);
// `vista gen -o DIR.paged`: one region at a time, so the peak follows the
// region, not the city (measured 401 to 431 MB for 2 km regions of 4 to 64 km
// cities at detail 2): kPagedGenFixedMb + kPagedGenMbPerKm2 per km² of region,
// scaled by the facade detail (0.3, 0.35, 1, 1.8 for detail 0..3).
constexpr double kPagedGenFixedMb = 150.0, kPagedGenMbPerKm2 = 70.0;
double estimatePagedGenMb(double regionSizeM, int detail);
// The gen budget check: Ok without a budget or when the estimate fits; else
// an error naming the option, the budget, the estimate and what it is made of (`how`).
Status checkGenBudget(const std::string& option, double budgetGb, double estimateMb, const std::string& how,
                      bool paged);

}  // namespace vista
