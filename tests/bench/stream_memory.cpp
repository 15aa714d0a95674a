// Stream memory: what a streamed region costs in resident memory per byte of
// its file, for each kind of load a CityStream makes (the weights of the
// streaming memory budget, nodes/render/city_stream.h kStream*PerFileByte;
// docs/measurements/paging.md). A measurement driver, not a test: it asserts
// nothing.
//
// Each configuration runs in a child process of its own (fork before any
// thread exists), so that one configuration's freed heap does not lend its
// pages to the next: the child makes a CityStream, takes its resident set
// size, loads every region level wanted around the eye (one advance that
// waits) and takes the resident set size again, each time after handing the
// heap's free pages back to the system (malloc_trim): the growth is what the
// loads keep, not the passing peak of decoding them. The configurations:
//   rays            full levels, Embree scene only (StreamGraph::None: `raycast`)
//   rays-coarse     coarse levels within the radius (radius 0: the regions that touch the eye
//                   stay full), and rays-coarse-far within twice it: their difference prices a
//                   coarse level apart from the full ones and from what a first load sets up
//   band-0          rays, near field, chunk parts within 0 m (the hybrid modes' levels)
//   band-all        rays, near field, chunk parts for every full level
//   graph           every level's chunks, no rays (`full`, `near`); graph-coarse and
//                   graph-coarse-far as rays-coarse and rays-coarse-far
//   graph-labels    every level's chunks and their label twins (`vista render` ground truth)
//   every-hybrid    rays, near field and every level's chunks (hybrid beside full or near)
//   largest-band    the largest region alone, its level and chunk part (band 0): the passing
//                   peak of decoding and preparing a load, beyond what it keeps
// The peak is the process's VmHWM, reset (clear_refs) before the loads.
// Each prints one CSV line: config, full and coarse levels resident, chunk parts resident,
// their file bytes (levels full, levels coarse, chunk parts), the RSS growth and the peak
// growth (MB). The
// last lines solve for the bytes per file byte of each kind.
//   usage: stream_memory CITY.paged [RADIUS_M] [X Y]   (eye default: the middle of the city)
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "foundation/process_memory.h"
#include "nodes/render/city_stream.h"
#include "runtime/scene/paged_load.h"

namespace {

// The resident set once the heap's free pages are handed back (malloc_trim): what the loads
// keep, not the decoding's passing peak, whose freed pages would otherwise stay resident.
double rssBytes() {
    vista::releaseFreeMemory();
    return double(vista::residentSetBytes());
}

// The peak resident set since the last resetPeak() (VmHWM).
double peakBytes() {
    std::ifstream f("/proc/self/status");
    std::string key;
    while (f >> key) {
        if (key == "VmHWM:") {
            double kb = 0;
            f >> kb;
            return kb * 1024.0;
        }
        f.ignore(1 << 20, '\n');
    }
    return 0.0;
}
void resetPeak() { std::ofstream("/proc/self/clear_refs") << "5"; }

struct Config {
    const char* name;
    bool rays, nearField, labels;
    vista::StreamGraph graph;
    double radius, band;   // radius < 0: the driver's radius; band < 0: the driver's radius
    double far = 1.0;      // coarse levels within far times the driver's radius (where radius is smaller)
    bool largest = false;  // the eye at the middle of the city's largest region (radius 0, no coarse)
};

struct Row {
    double fullBytes = 0, coarseBytes = 0, chunkBytes = 0, growth = 0, peak = 0;
};

// Runs one configuration in this (child) process and prints its line.
int measure(const vista::PagedManifest& m, const Config& c, double radius, glm::dvec3 eye) {
    using namespace vista;
    if (c.largest) {
        size_t big = 0;
        for (size_t i = 0; i < m.regions.size(); ++i)
            if (!m.regions[i].empty && m.regions[i].bytes > m.regions[big].bytes) big = i;
        eye = glm::dvec3(0.5 * (glm::dvec2(m.regions[big].lo) + glm::dvec2(m.regions[big].hi)), 0.0);
    }
    RegionPagerOptions o;
    o.radius = c.radius < 0 ? radius : c.radius;
    o.far = c.far * radius;  // coarse levels only where the radius is smaller
    o.prefetchS = 0;
    o.workers = 1;  // as the commands stream
    auto s = CityStream::create(m, o, c.rays, {}, c.labels);
    if (!s) {
        std::fprintf(stderr, "stream_memory: %s\n", s.status().message().c_str());
        return 1;
    }
    if (c.nearField) (*s)->enableNearField(0);
    (*s)->setGraphLevels(c.graph, c.band < 0 ? radius : c.band);
    const double before = rssBytes();
    resetPeak();
    auto f = (*s)->advance(eye, glm::dvec3(0.0), /*wait=*/true);
    const double peak = peakBytes();
    if (!f) {
        std::fprintf(stderr, "stream_memory: %s\n", f.status().message().c_str());
        return 1;
    }
    const double after = rssBytes();
    const std::vector<uint8_t> held = (*s)->held();
    const RegionPagerStats st = (*s)->stats();
    double full = 0, coarse = 0;
    int nFull = 0, nCoarse = 0;
    for (size_t i = 0; i < held.size(); ++i) {
        if (held[i] == 2) full += double(m.regions[i].bytes), ++nFull;
        if (held[i] == 1) coarse += double(m.regions[i].coarseBytes), ++nCoarse;
    }
    const double chunkBytes = double(st.residentBytes) - full - coarse;
    std::printf("%s,%d,%d,%d,%.0f,%.0f,%.0f,%.1f,%.1f\n", c.name, nFull, nCoarse, st.residentChunks, full, coarse,
                chunkBytes, (after - before) / 1048576.0, (peak - before) / 1048576.0);
    std::fflush(stdout);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    using namespace vista;
    if (argc < 2) {
        std::fprintf(stderr, "usage: stream_memory CITY.paged [RADIUS_M] [X Y]\n");
        return 2;
    }
    auto m = readPagedManifest(argv[1]);
    if (!m) {
        std::fprintf(stderr, "stream_memory: %s\n", m.status().message().c_str());
        return 2;
    }
    const double radius = argc > 2 ? std::atof(argv[2]) : 3000.0;
    glm::dvec3 eye(0.0);
    if (argc > 4) {
        eye = glm::dvec3(std::atof(argv[3]), std::atof(argv[4]), 0.0);
    } else {
        glm::dvec2 lo(1e300), hi(-1e300);
        for (const PagedRegionEntry& r : m->regions) {
            if (r.empty) continue;
            lo = glm::min(lo, glm::dvec2(r.lo));
            hi = glm::max(hi, glm::dvec2(r.hi));
        }
        eye = glm::dvec3(0.5 * (lo + hi), 0.0);
    }
    const std::vector<Config> configs = {
        {"rays", true, false, false, StreamGraph::None, -1, 0},
        {"rays-coarse", true, false, false, StreamGraph::None, 0, 0, 1.0},
        {"rays-coarse-far", true, false, false, StreamGraph::None, 0, 0, 2.0},
        {"band-0", true, true, false, StreamGraph::NearBand, -1, 0},
        {"band-all", true, true, false, StreamGraph::NearBand, -1, -1},
        {"graph", false, false, false, StreamGraph::EveryLevel, -1, 0},
        {"graph-coarse", false, false, false, StreamGraph::EveryLevel, 0, 0, 1.0},
        {"graph-coarse-far", false, false, false, StreamGraph::EveryLevel, 0, 0, 2.0},
        {"graph-labels", false, false, true, StreamGraph::EveryLevel, -1, 0},
        {"every-hybrid", true, true, false, StreamGraph::EveryLevel, -1, 0},
        {"largest-band", true, true, false, StreamGraph::NearBand, 0, 0, 0.0, true},
    };
    std::printf(
        "config,full_levels,coarse_levels,chunk_parts,full_file_bytes,coarse_file_bytes,"
        "chunk_part_file_bytes,rss_growth_mb,peak_growth_mb\n");
    std::fflush(stdout);
    std::map<std::string, Row> rows;
    for (const Config& c : configs) {
        int fds[2];
        if (pipe(fds) != 0) return 1;
        std::fflush(stdout);  // else the child inherits what is buffered and writes it again
        const pid_t pid = fork();
        if (pid == 0) {
            close(fds[0]);
            dup2(fds[1], STDOUT_FILENO);
            _exit(measure(*m, c, radius, eye));
        }
        close(fds[1]);
        std::string line;
        char buf[512];
        ssize_t n;
        while ((n = read(fds[0], buf, sizeof(buf))) > 0) line.append(buf, size_t(n));
        close(fds[0]);
        int status = 0;
        waitpid(pid, &status, 0);
        if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
            std::fprintf(stderr, "stream_memory: configuration %s failed\n", c.name);
            return 1;
        }
        std::fputs(line.c_str(), stdout);
        Row r;
        char name[64];
        int a, b, k;
        if (std::sscanf(line.c_str(), "%63[^,],%d,%d,%d,%lf,%lf,%lf,%lf,%lf", name, &a, &b, &k, &r.fullBytes,
                        &r.coarseBytes, &r.chunkBytes, &r.growth, &r.peak) == 9)
            rows[c.name] = r;
    }
    // Bytes of resident memory per file byte, kind by kind.
    const double mb = 1048576.0;
    auto per = [&](double growthMb, double bytes) { return bytes > 0 ? growthMb * mb / bytes : 0.0; };
    // A coarse level: the growth between two reaches of coarse levels over their coarse file bytes.
    auto coarse = [&](const Row& a, const Row& b) {
        return b.coarseBytes > a.coarseBytes ? (b.growth - a.growth) * mb / (b.coarseBytes - a.coarseBytes) : 0.0;
    };
    const Row& rays = rows["rays"];
    const double fRays = per(rays.growth, rays.fullBytes);
    const double fCoarse = coarse(rows["rays-coarse"], rows["rays-coarse-far"]);
    const Row& b0 = rows["band-0"];
    const Row& ba = rows["band-all"];
    const double fChunks =
        ba.chunkBytes > b0.chunkBytes ? (ba.growth - b0.growth) * mb / (ba.chunkBytes - b0.chunkBytes) : 0.0;
    const double fBandLevel = per(b0.growth - fChunks * b0.chunkBytes / mb, b0.fullBytes);
    const Row& g = rows["graph"];
    const Row& gl = rows["graph-labels"];
    const Row& eh = rows["every-hybrid"];
    // Loading: the peak above what the largest region's level and chunk part keep, per byte of its file.
    const Row& lb = rows["largest-band"];
    const double fLoading = per(lb.peak - lb.growth, lb.fullBytes);
    std::printf(
        "# bytes per file byte: full level, rays %.2f; coarse level, rays %.2f; hybrid level (rays and "
        "height patch) %.2f; chunk part %.2f; full level, graph %.2f; coarse level, graph %.2f; full level, "
        "graph and labels %.2f; hybrid level with chunks %.2f; loading (the passing peak of decoding and "
        "preparing the largest region, beyond what it keeps) %.2f\n",
        fRays, fCoarse, fBandLevel, fChunks, per(g.growth, g.fullBytes + g.coarseBytes),
        coarse(rows["graph-coarse"], rows["graph-coarse-far"]), per(gl.growth, gl.fullBytes + gl.coarseBytes),
        per(eh.growth, eh.fullBytes + eh.coarseBytes), fLoading);
    return 0;
}
