// vista export: a scene file's road network in an exchange format (today:
// ASAM OpenDRIVE, --xodr; docs/formats.md "OpenDRIVE"). Reads the street
// graph and parameters the scene file carries (blocks, which decide the
// sidewalk sides, are derived again from them), so the output equals
// `vista gen ... --xodr` of the same city byte for byte.
#include <cstdio>
#include <string>

#include "citygen/blocks.h"
#include "citygen/opendrive.h"
#include "cmd/cli.h"
#include "cmd/commands.h"
#include "foundation/atomic_file.h"
#include "foundation/output_paths.h"
#include "runtime/scene/city_file.h"

namespace vista {

namespace {

bool endsWith(const std::string& s, const std::string& tail) {
    return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

}  // namespace

// `option` names the flag for the messages.
Status checkXodrPath(const std::string& option, const std::string& path) {
    if (!endsWith(path, ".xodr"))
        return Status::error("option " + option + " = '" + path + "': the OpenDRIVE output must end in .xodr");
    return checkWritablePath(option, path);
}

int runExport(int argc, char** argv) {
    const std::string cmd = "vista export";
    CLI::App app{"Export the road network of a scene file (streets, lanes, junctions) for driving simulators.", cmd};
    std::string input, xodr, statsFile;
    bool quiet = false;
    app.add_option("city", input, "input scene file (.osgb from 'vista gen' or 'vista bake')")->required();
    app.add_option("--xodr", xodr, "write the road network as ASAM OpenDRIVE 1.6 (.xodr)");
    app.add_option("--stats", statsFile,
                   "write the network's counts (roads, junctions, lanes, signals, turns dropped, ...) as JSON");
    app.add_flag("-q,--quiet", quiet, "no summary on stderr");
    if (int rc = parseOrExit(app, argc, argv); rc >= 0) return rc;
    if (xodr.empty()) return reportBadInput(cmd, Status::error("nothing to export: give --xodr FILE.xodr"));
    if (Status s = checkXodrPath("--xodr", xodr); !s) return reportBadInput(cmd, s);
    CommandFiles files;  // held until the output is written (its lock)
    if (Status s = files.input("city", input).output("--xodr", xodr).output("--stats", statsFile).check(); !s)
        return reportBadInput(cmd, s);
    auto model = loadCityFile(input);
    if (!model) return reportBadInput(cmd, model.status());
    if (model->streets.edges.empty())
        return reportBadInput(cmd,
                              Status::error("scene file '" + input + "' has no street graph (no streets to export)"));
    // The blocks decide the sidewalk sides; they are a function of (streets, params).
    const std::vector<Block> blocks = extractBlocks(model->streets, model->params, nullptr);
    OpenDriveCounts n;
    auto text = openDriveXml(model->streets, model->params, &blocks, &n);
    if (!text) return reportBadInput(cmd, Status::error("scene file '" + input + "': " + text.status().message()));
    OutputBatch batch;  // the network and its stats, or neither
    if (Status s = writeFileAtomic(batch.stage(xodr), *text); !s) return reportBadInput(cmd, s);
    if (!statsFile.empty())
        if (Status s = writeFileAtomic(batch.stage(statsFile), openDriveCountsJson(n) + "\n"); !s)
            return reportBadInput(cmd, s);
    if (Status s = batch.commit(); !s) return reportBadInput(cmd, s);
    if (!quiet)
        std::fprintf(stderr,
                     "wrote %s: %zu roads, %zu transitions, %zu junctions (%zu connecting roads), %zu driving lanes, "
                     "%zu sidewalks, %zu traffic lights, %zu signs, %zu crosswalks; %zu corners too sharp to link, "
                     "%zu turns dropped, %zu turns below the turning radius, %zu turns crossing other roads, "
                     "%zu arm pairs left overlapping, %zu incoming lanes without a connection, %zu outgoing lanes fed "
                     "by none, %zu lanes tapering in or out inside a link road\n",
                     xodr.c_str(), n.roads, n.transitions, n.junctions, n.connectingRoads, n.drivingLanes, n.sidewalks,
                     n.trafficLights, n.signs, n.crosswalks, n.sharpCorners, n.droppedTurns, n.tightTurns,
                     n.crossingTurns, n.overlappingArms, n.unlinkedLanes, n.unfedLanes, n.taperedLanes);
    return 0;
}

}  // namespace vista
