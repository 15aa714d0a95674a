// `vista render CITY --rig rig.json`: a sensor rig (runtime/engine/rig.h)
// driven along the walkthrough path, every sensor cast into the city's
// Embree scene at its own rate, written KITTI-style with vista's rig.json
// (docs/formats.md "Sensor rigs"). Resumable as the one-camera run is
// (cmd/render_work_dir.h): a kill -9 and the same command give the bytes of
// an uninterrupted run.
#pragma once
#include <string>

#include "cmd/options.h"

namespace vista {

struct RigRunRequest {
    std::string city, rig, out, command;
    std::string sampling = "spread";
    int frames = 60;
    bool repeats = false;  // --allow-repeated-frames
    bool stats = false, quiet = false, restart = false;
    PathFlags path;
    ModeFlags modeFlags;  // --threads only; checkRunFiles reads the baked-file flags
};

// The whole run; returns the exit code (0, or 2 after printing the message).
int runRigRender(const RigRunRequest& request);

}  // namespace vista
