// vista: procedural cities and fast walkthroughs. Git-style subcommands.
#include <cstdio>
#include <cstring>
#include <string>

#include "cmd/commands.h"
#include "foundation/version.h"

namespace {

struct Command {
    const char* name;
    int (*run)(int, char**);
    const char* summary;
};

const Command kCommands[] = {
    {"gen", vista::runGen, "generate a city: params -> city.osgb (+ GeoJSON, glTF, stats) or a paged city DIR.paged"},
    {"path", vista::runPath, "make a deterministic walkthrough path along the streets (CSV)"},
    {"bench", vista::runBench, "headless walkthrough: render modes side by side, write CSV/JSON/PNG"},
    {"view", vista::runView, "interactive viewer (window; works under Xvfb)"},
    {"bake", vista::runBake, "bake view cells and point impostors into city.baked.osgb"},
    {"export", vista::runExport, "export a scene file's road network (OpenDRIVE .xodr)"},
    {"render", vista::runRender, "ground truth per frame: rgb, depth, semantic, instance (+ cameras.json)"},
    {"traffic", vista::runTraffic, "simulate vehicles and pedestrians on a city with SUMO (FCD + signal states)"},
};

void usage(FILE* f) {
    std::fprintf(f, "usage: vista <command> [options]\n\ncommands:\n");
    for (const auto& c : kCommands) std::fprintf(f, "  %-8s %s\n", c.name, c.summary);
    std::fprintf(f, "  help     show this list, or `vista help <command>` for a command's options\n");
    std::fprintf(f, "\nRun `vista <command> --help` for the options of one command.\n");
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    std::string cmd = argv[1];
    if (cmd == "help" || cmd == "--help" || cmd == "-h") {
        if (argc >= 3) {
            for (const auto& c : kCommands)
                if (std::strcmp(argv[2], c.name) == 0) {
                    char* args[] = {argv[2], const_cast<char*>("--help"), nullptr};
                    return c.run(2, args);
                }
            std::fprintf(stderr, "vista: unknown command '%s'\n", argv[2]);
            return 2;
        }
        usage(stdout);
        return 0;
    }
    if (cmd == "--version") {
        std::printf("vista %s\n", vista::version());
        return 0;
    }
    for (const auto& c : kCommands)
        if (cmd == c.name) return c.run(argc - 1, argv + 1);
    std::fprintf(stderr, "vista: unknown command '%s'\n\n", cmd.c_str());
    usage(stderr);
    return 2;
}
