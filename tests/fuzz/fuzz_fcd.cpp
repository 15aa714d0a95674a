// libFuzzer target: SUMO floating-car data (the fcd.xml of a traffic
// directory, read by `--traffic DIR` and `vista path --traffic`).
// Contract under test: readFcd returns tracks or a Status, never crashes or
// throws; accepted tracks have increasing times, one frame start per time
// (non-decreasing, within the poses), poses sorted by agent inside a frame,
// finite coordinates within the documented range, a type per agent, and
// poseAt() stays finite at and between every sample.
#include <cmath>
#include <cstdlib>
#include <string>

#include "runtime/traffic/traffic_tracks.h"
#include "tests/fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string path = vista::fuzz::inputFile(".fcd.xml", data, size);
    auto t = vista::readFcd(path, 100.0, -50.0);
    if (!t) return 0;
    if (t->frameStart.size() != t->times.size() || t->agentIds.size() != t->agentTypes.size()) std::abort();
    for (size_t f = 0; f < t->frames(); ++f) {
        if (f > 0 && !(t->times[f] > t->times[f - 1])) std::abort();
        const size_t begin = t->frameStart[f];
        const size_t end = f + 1 < t->frames() ? t->frameStart[f + 1] : t->poses.size();
        if (begin > end || end > t->poses.size()) std::abort();
        for (size_t i = begin; i < end; ++i) {
            const vista::AgentPose& p = t->poses[i];
            if (p.agent >= t->agentIds.size()) std::abort();
            if (i > begin && !(t->poses[i - 1].agent < p.agent)) std::abort();
            if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.heading) || !std::isfinite(p.speed))
                std::abort();
            if (std::abs(p.x) > 2.1e7f || std::abs(p.y) > 2.1e7f) std::abort();
            vista::AgentPose q;
            const double t0 = t->times[f];
            const double mid = f + 1 < t->frames() ? 0.5 * (t0 + t->times[f + 1]) : t0;
            for (double at : {t0, mid})
                if (t->poseAt(p.agent, at, &q) &&
                    (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.heading)))
                    std::abort();
        }
    }
    return 0;
}
