// Streaming a paged city in bench, view and render (paged_stream.h).
#include "cmd/paged_stream.h"

#include <cstdio>

#include "cmd/memory.h"
#include "nodes/render/render_mode.h"

namespace vista {

Result<RegionPagerOptions> pagedStreamOptions(const PagedReach& reach, const PagedStreamFlags& flags, double budgetGb,
                                              double preloadMb) {
    auto budget = streamBudgetBytes("--memory-budget", budgetGb, preloadMb);
    if (!budget) return budget.status();
    RegionPagerOptions o;
    o.radius = reach.radius;
    o.far = reach.far;
    o.prefetchS = flags.prefetchS.value_or(kDefaultPagedPrefetchS);
    o.wait = flags.wait;
    o.budgetBytes = *budget;
    return o;
}

void holdStreamUnder(CityStream& stream, double budgetGb) {
    if (budgetGb > 0 && stream.options().budgetBytes > 0)
        stream.holdProcessUnder(uint64_t(budgetGb * 1024.0 * 1024.0 * 1024.0));
}

Status checkStreamingModes(const std::vector<std::string>& modes) {
    for (const auto& m : modes)
        if (!modeStreams(m))
            return Status::error("mode " + m + " does not stream a paged city (modes that do: " + streamingModeNames() +
                                 ")");
    return Status::ok();
}

Result<bool> choosePagedStream(const char* cmd, const PagedStreamFlags& f, const std::string& city,
                               const std::string& cannotStream, bool quiet) {
    const char* asked = f.stream      ? "--paged-stream"
                        : f.wait      ? "--paged-wait"
                        : f.prefetchS ? "--paged-prefetch"
                                      : nullptr;
    const bool paged = isPagedCityPath(city);
    if (!paged) {
        if (asked || f.preload)
            return Status::error(std::string(asked ? asked : "--paged-preload") + ": '" + city +
                                 "' is a city file; it applies to a paged city (DIR.paged from `vista gen`)");
        return false;
    }
    if (f.preload) return false;
    if (cannotStream.empty()) return true;
    if (asked) return Status::error(std::string(asked) + ": " + cannotStream);
    if (!quiet)
        std::fprintf(stderr, "%s: paged city: preloading the regions around the path (%s)\n", cmd,
                     cannotStream.c_str());
    return false;
}

void StreamDetail::add(const CityStreamFrame& f, double t) {
    if (frames++ == 0) t0 = t;
    if (f.belowDetail <= 0) return;
    ++belowDetail;
    if (t - t0 > 1.0) ++belowDetailAfterFirstSecond;
}

void noteStreamDetail(const char* cmd, const StreamDetail& d) {
    std::fprintf(stderr,
                 "%s: paged stream: %d of %d frames drew a region below the detail its distance asks for (%d after "
                 "the first second)\n",
                 cmd, d.belowDetail, d.frames, d.belowDetailAfterFirstSecond);
}

void notePagedStream(const char* cmd, const PagedManifest& manifest, const RegionPagerOptions& o) {
    std::fprintf(stderr,
                 "%s: paged city: streaming its %d regions around the camera (full detail within %g m, coarse "
                 "within %g m, %g s ahead%s%s)\n",
                 cmd, manifest.nonEmpty(), o.radius, o.far, o.prefetchS,
                 o.wait ? ", every frame waits for its regions" : "",
                 o.budgetBytes ? ", within the memory budget" : "");
}

Result<CityStreamFrame> advancePagedStream(CityStream& stream, const char* cmd, const glm::dvec3& eye,
                                           const glm::dvec3& velocity, std::vector<std::string>* damaged, bool wait) {
    (void)cmd;
    auto f = stream.advance(eye, velocity, wait);
    if (!f) return f.status();
    if (!f->shortfall.empty()) return Status::error("--memory-budget: " + f->shortfall);
    if (!f->damaged.empty()) {
        std::string why = "the stream cannot read " + std::to_string(f->damaged.size()) + " region file" +
                          (f->damaged.size() == 1 ? "" : "s");
        for (const std::string& d : f->damaged) {
            why += "; " + d;
            if (damaged) damaged->push_back(d);
        }
        const bool foreign = why.find("another generation") != std::string::npos;
        return Status::error(why + (foreign ? std::string()
                                            : " (generate the city again, or give --paged-preload to "
                                              "draw the rest of the city)"));
    }
    return f;
}

glm::dvec3 pathVelocity(const Path& path, size_t i) {
    const auto& s = path.samples;
    if (s.size() < 2) return glm::dvec3(0.0);
    const size_t a = i + 1 < s.size() ? i : i - 1;
    const double dt = s[a + 1].t - s[a].t;
    return dt > 0 ? (s[a + 1].position - s[a].position) / dt : glm::dvec3(0.0);
}

nlohmann::json pagedStreamJson(const RegionPagerOptions& o, const RegionPagerStats& s, int framesWithArrivals,
                               const std::vector<std::string>& damaged, const StreamDetail& detail) {
    return {{"radius_m", o.radius},
            {"far_m", o.far},
            {"prefetch_s", o.prefetchS},
            {"lookahead_s_max", s.peakLookaheadS},
            {"full_load_s_max", s.fullLoadSMax},
            {"wait", o.wait},
            {"frames_deterministic", o.wait},
            {"budget_bytes", o.budgetBytes},
            {"bytes_per_file_byte",
             {{"full", o.cost.full},
              {"coarse", o.cost.coarse},
              {"chunk_part", o.cost.chunks},
              {"loading", o.cost.loading}}},
            {"loading_reserve_bytes", s.loadingReserve},
            {"process_overhead_bytes", s.processOverhead},
            {"peak_resident_estimate_bytes", s.peakResidentCost},
            {"resident_estimate_bytes_end", s.residentCost},
            {"peak_resident_file_bytes", s.peakResidentBytes},
            {"resident_file_bytes_end", s.residentBytes},
            {"resident_full_end", s.residentFull},
            {"resident_coarse_end", s.residentCoarse},
            {"chunk_radius_m", o.chunkRadius >= 0 ? nlohmann::json(o.chunkRadius) : nlohmann::json(nullptr)},
            {"resident_chunk_parts_end", s.residentChunks},
            {"loads", s.loads},
            {"chunk_part_loads", s.chunkLoads},
            {"unloads", s.unloads},
            {"discarded", s.discarded},
            {"bytes_read", s.bytesRead},
            {"frames_waited", s.framesWaited},
            {"wait_ms", s.waitMs},
            {"frames_with_arrivals", framesWithArrivals},
            {"frames_below_detail", detail.belowDetail},
            {"frames_below_detail_after_first_second", detail.belowDetailAfterFirstSecond},
            {"budget_limited_updates", s.budgetLimited},
            {"damaged", damaged}};
}

}  // namespace vista
