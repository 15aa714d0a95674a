// Memory phases, the city-run estimate and the budget check (memory.h).
#include "cmd/memory.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "cmd/cli.h"
#include "foundation/process_memory.h"

namespace vista {

namespace {

constexpr double kSceneBytesPerFileByte = 4.1;  // measured: 4.03 (2 km city), 3.76 (8 km)
constexpr double kRaysBytesPerFileByte = 1.7;   // measured: 1.63 (2 km), see docs/performance.md
constexpr double kFixedMb = 200.0;
// A streamed run's own memory beside what its regions keep (GL context, frame buffers, the ray
// scene's top level, the far field's cache, the paged city's height lattice, what the heap keeps
// between live blocks, an arrival being spliced in): measured 375 to 600 MB for a hybrid at
// 640x480 on llvmpipe (docs/measurements/paging.md, memory budget). A starting figure: a run
// held under its budget measures its own (CityStream::holdProcessUnder) and keeps the larger.
constexpr double kStreamFixedMb = 700.0;
constexpr double kMb = 1024.0 * 1024.0;

double currentRssMb() { return double(residentSetBytes()) / kMb; }

}  // namespace

MemoryPhase memoryPhase(const std::string& name) { return {name, peakRssMb(), currentRssMb()}; }

double estimateCityRunMb(uint64_t fileBytes, bool rayScene) {
    const double f = double(fileBytes) / kMb;
    return kFixedMb + kSceneBytesPerFileByte * f + (rayScene ? kRaysBytesPerFileByte * f : 0.0);
}

Status checkMemoryBudget(const std::string& option, double budgetGb, double estimateMb, uint64_t fileBytes,
                         bool rayScene) {
    if (budgetGb <= 0 || estimateMb <= budgetGb * 1024.0) return Status::ok();
    char buf[512];
    std::snprintf(
        buf, sizeof(buf),
        "option %s = %g GB: this run is estimated to peak at %.1f GB (%.0f MB city file x %.1f for the scene%s, "
        "+ %.0f MB fixed; docs/performance.md \"Memory\"); give a larger budget or a smaller city",
        option.c_str(), budgetGb, estimateMb / 1024.0, double(fileBytes) / kMb, kSceneBytesPerFileByte,
        rayScene ? " + 1.7 for the ray scene" : "", kFixedMb);
    return Status::error(buf);
}

Result<uint64_t> streamBudgetBytes(const std::string& option, double budgetGb, double preloadMb) {
    if (budgetGb <= 0) return uint64_t(0);
    preloadMb = std::max(preloadMb, kStreamFixedMb);
    const double leftMb = budgetGb * 1024.0 - preloadMb;
    if (leftMb <= 0) {
        char buf[320];
        std::snprintf(buf, sizeof(buf),
                      "option %s = %g GB: what is loaded before the first frame is estimated at %.2f GB, which leaves "
                      "nothing for the streamed regions; give a larger budget",
                      option.c_str(), budgetGb, preloadMb / 1024.0);
        return Status::error(buf);
    }
    return std::max<uint64_t>(1, uint64_t(leftMb * kMb));
}

double estimateGenMb(size_t storedTriangles) {
    return kGenFixedMb + kGenBytesPerStoredTriangle * double(storedTriangles) / kMb;
}

double estimatePagedGenMb(double regionSizeM, int detail) {
    static const double kDetail[] = {0.3, 0.35, 1.0, 1.8};
    const double km2 = regionSizeM * regionSizeM / 1e6;
    return kPagedGenFixedMb + kPagedGenMbPerKm2 * km2 * kDetail[std::clamp(detail, 0, 3)];
}

Status checkGenBudget(const std::string& option, double budgetGb, double estimateMb, const std::string& how,
                      bool paged) {
    if (budgetGb <= 0 || estimateMb <= budgetGb * 1024.0) return Status::ok();
    char buf[640];
    std::snprintf(
        buf, sizeof(buf),
        "option %s = %g GB: this generation is estimated to peak at %.2f GB (%s; docs/performance.md \"Memory\"); "
        "nothing was written. Give a larger budget%s",
        option.c_str(), budgetGb, estimateMb / 1024.0, how.c_str(),
        paged ? " or a smaller --region-size"
              : ", a smaller city, or paged output (-o DIR.paged, whose peak follows --region-size)");
    return Status::error(buf);
}

}  // namespace vista
