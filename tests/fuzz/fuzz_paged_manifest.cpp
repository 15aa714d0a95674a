// libFuzzer target: a paged city's manifest.json (`vista bench/view/render
// DIR.paged`), read from a directory of its own.
// Contract under test: readPagedManifest returns a manifest or a Status,
// never crashes, throws or recurses without bound; an accepted manifest has
// a grid within kMaxManifestRegionsPerSide, one entry per region in order,
// at least one non-empty region, positive region size, and file names that
// are plain names inside the directory (no '/', not '.' or '..').
#include <cstdio>
#include <cstdlib>
#include <string>

#include <sys/stat.h>
#include <unistd.h>

#include "runtime/scene/paged_load.h"

namespace {

struct Dir {
    std::string path;
    Dir() {
        const char* tmp = std::getenv("TMPDIR");
        path = std::string(tmp && *tmp ? tmp : "/tmp") + "/vista_fuzz_paged_" + std::to_string(::getpid());
        ::mkdir(path.c_str(), 0700);
    }
    ~Dir() {
        std::remove((path + "/manifest.json").c_str());
        ::rmdir(path.c_str());
    }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const Dir dir;
    FILE* f = std::fopen((dir.path + "/manifest.json").c_str(), "wb");
    if (!f) return 0;
    if (size) std::fwrite(data, 1, size, f);
    std::fclose(f);
    auto m = vista::readPagedManifest(dir.path);
    if (!m) return 0;
    if (m->regionsX < 1 || m->regionsY < 1 || m->regionsX > vista::kMaxManifestRegionsPerSide ||
        m->regionsY > vista::kMaxManifestRegionsPerSide)
        std::abort();
    if (m->regions.size() != size_t(m->regionsX) * size_t(m->regionsY) || !(m->regionSizeM > 0) || m->nonEmpty() < 1)
        std::abort();
    for (size_t i = 0; i < m->regions.size(); ++i) {
        const vista::PagedRegionEntry& r = m->regions[i];
        if (r.region != int(i)) std::abort();
        for (const std::string* name : {&r.file, &r.coarseFile})
            if (name->find('/') != std::string::npos || *name == "." || *name == "..") std::abort();
    }
    return 0;
}
