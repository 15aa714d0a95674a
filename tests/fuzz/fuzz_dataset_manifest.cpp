// libFuzzer target: a dataset manifest (`vista render --dataset M.json`).
// Contract under test: parseDatasetManifest returns a manifest or a Status,
// never crashes or throws; an accepted manifest has non-empty city, path and
// rig lists with unique, well-formed names, at most kMaxDatasetDrives drives,
// frames in 1 .. 1000000 when given, and drive names "city/path/rig".
#include <cstdlib>
#include <set>
#include <string>

#include "runtime/scene/dataset_manifest.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    auto m = vista::parseDatasetManifest(text, "fuzz.json", "base");
    if (!m) {
        if (m.status().message().empty()) std::abort();
        return 0;
    }
    if (m->cities.empty() || m->paths.empty() || m->rigs.empty()) std::abort();
    if (m->options.frames && (*m->options.frames < 1 || *m->options.frames > 1000000)) std::abort();
    auto unique = [](const auto& list) {
        std::set<std::string> names;
        for (const auto& e : list)
            if (e.name.empty() || e.name.size() > 64 || e.name[0] == '.' || e.name.find('/') != std::string::npos ||
                !names.insert(e.name).second)
                std::abort();
    };
    unique(m->cities), unique(m->paths), unique(m->rigs);
    const double drives = double(m->cities.size()) * double(m->paths.size()) * double(m->rigs.size());
    if (drives > double(vista::kMaxDatasetDrives)) std::abort();
    if (drives <= 1000)
        for (const auto& d : m->drives())
            if (d.name != m->cities[d.city].name + "/" + m->paths[d.path].name + "/" + m->rigs[d.rig].name)
                std::abort();
    return 0;
}
