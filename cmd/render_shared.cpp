// Pieces shared by the two kinds of `vista render` run (render_shared.h).
#include "cmd/render_shared.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <vector>

#include "citygen/labels.h"
#include "cmd/options.h"
#include "foundation/atomic_file.h"
#include "foundation/format.h"
#include "foundation/hash.h"
#include "foundation/statistics.h"

namespace vista {

std::string frameName(size_t f) {
    char b[24];  // up to 20 digits of a size_t
    std::snprintf(b, sizeof b, "%06zu", f);
    return b;
}

// World xy of every path sample inside the city square (params.origin +- size/2) grown by kPathMargin.
Status checkPathInCity(const Path& path, const SceneModel& city) {
    const double half = 0.5 * city.params.size_m + kPathMargin;
    for (size_t i = 0; i < path.samples.size(); ++i) {
        const PathSample& s = path.samples[i];
        const double x = s.position.x - city.params.origin_x, y = s.position.y - city.params.origin_y;
        if (!(std::abs(x) <= half && std::abs(y) <= half)) {
            char b[320];
            std::snprintf(b, sizeof b,
                          "path sample %zu (t = %.6g s) at city-frame (%.1f, %.1f) m lies outside the city square "
                          "grown by %.0f m: x and y in [-%.0f, %.0f] m",
                          i, s.t, x, y, kPathMargin, half, half);
            return Status::error(b);
        }
    }
    return Status::ok();
}

nlohmann::json classesJson() {
    nlohmann::json classes = nlohmann::json::array();
    for (int c = 0; c < kSemanticClassCount; ++c) {
        uint8_t rgb[3];
        semanticClassColor(SemanticClass(c), rgb);
        classes.push_back(
            {{"id", c}, {"name", semanticClassName(SemanticClass(c))}, {"color", {rgb[0], rgb[1], rgb[2]}}});
    }
    nlohmann::json kinds = nlohmann::json::array();
    for (uint32_t k = 0; k < uint32_t(InstanceKind::Count); ++k)
        kinds.push_back({{"kind", k}, {"name", instanceKindName(InstanceKind(k))}});
    return {{"semantic_classes", classes},
            {"semantic_unknown", 255},
            {"instance_encoding", "id = kind << 28 | index (uint32); 0 = sky or terrain"},
            {"instance_kinds", kinds}};
}

// Content hash of a file's bytes (hex), streamed.
Result<std::string> fileHash(const std::string& path, uint64_t& bytes) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return Status::error("cannot read '" + path + "': " + errnoText());
    Hasher64 h;
    std::vector<unsigned char> buf(1 << 20);
    bytes = 0;
    size_t n;
    while ((n = std::fread(buf.data(), 1, buf.size(), f)) > 0) {
        h.update(buf.data(), n);
        bytes += n;
    }
    const bool bad = std::ferror(f) != 0;
    std::fclose(f);
    if (bad) return Status::error("cannot read '" + path + "': read error");
    return hex64(h.finish());
}

Result<std::string> trafficHash(const TrafficTracks& t, const std::string& trafficDir) {
    uint64_t h = hashBytes64(t.poses.data(), t.poses.size() * sizeof(AgentPose));
    h = hashBytes64(t.times.data(), t.times.size() * sizeof(double), h);
    h = hashBytes64(t.agentTypes.data(), t.agentTypes.size() * sizeof(AgentType), h);
    if (!t.signals) return hex64(h);
    uint64_t bytes = 0;
    auto signals = fileHash((std::filesystem::path(trafficDir) / "signals.xml").string(), bytes);
    if (!signals) return Status::error("--traffic = '" + trafficDir + "': " + signals.status().message());
    return hex64(hashBytes64(signals->data(), signals->size(), h));
}

// Hash of the frames' camera poses (path index, time, eye, heading, pitch):
// whatever chose them (--path file, --seed/--kind/--duration/--run-up,
// --frames, --sampling), equal poses give equal frames.
std::string posesHash(const Path& path, const std::vector<size_t>& idx) {
    Hasher64 h;
    auto put = [&](uint64_t v) {
        unsigned char b[8];
        storeLE64(b, v);
        h.update(b, 8);
    };
    auto putD = [&](double d) {
        uint64_t v;
        std::memcpy(&v, &d, 8);
        put(v);
    };
    for (size_t i : idx) {
        const PathSample& s = path.samples[i];
        put(i);
        putD(s.t), putD(s.position.x), putD(s.position.y), putD(s.position.z), putD(s.heading), putD(s.pitch);
    }
    return hex64(h.finish());
}

std::string manifestNumber(double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%.17g", v);
    return b;
}

// Test hook (docs/formats.md): VISTA_RENDER_KILL_AFTER_FRAMES=N makes the run
// kill itself with SIGKILL after it finished N frames, as an interruption would.
long killAfterFrames() {
    const char* e = std::getenv("VISTA_RENDER_KILL_AFTER_FRAMES");
    return e && *e ? std::atol(e) : 0;
}

nlohmann::json medianOf(const std::vector<double>& v) {
    return v.empty() ? nlohmann::json(nullptr) : nlohmann::json(median(v));
}

WalkthroughRequest renderRequest(const std::string& city, const std::string& pathFile, const PathOptions& pathOptions,
                                 int frames, int sampleRuns, bool repeats, const std::string& labelsFor,
                                 std::vector<size_t>& idx) {
    WalkthroughRequest req;
    req.city = city;
    req.cmd = "vista render";
    req.quiet = true;
    req.allowPaged = false;
    req.pathNeedsStreets = pathFile.empty();
    req.checkCity = [city, labelsFor](const SceneModel& model) {
        if (!labelsFor.empty() && !model.labelled)
            return Status::error("city file '" + city +
                                 "' has no ground-truth labels (written by an older vista): regenerate the city "
                                 "with this version (`vista gen`) for " +
                                 labelsFor);
        return Status::ok();
    };
    req.makePath = [pathFile, pathOptions, frames, sampleRuns, repeats, &idx](const SceneModel& model) -> Result<Path> {
        auto path = walkthroughPath(pathFile, pathOptions, model);
        if (!path) return path;
        if (path->samples.empty()) return Status::error("the walkthrough path has no samples");
        VISTA_RETURN_IF_ERROR(checkFrameCount(frames, path->samples.size(), repeats));
        idx = path->frames(size_t(frames), sampleRuns);
        VISTA_RETURN_IF_ERROR(checkPathInCity(*path, model));
        return path;
    };
    return req;
}

}  // namespace vista
