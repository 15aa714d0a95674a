// vista traffic: moving vehicles and pedestrians for a city, simulated by
// SUMO (runtime/traffic/traffic_run.h): the city's OpenDRIVE → netconvert →
// seeded demand → sumo → a traffic directory (docs/formats.md "Traffic
// directory") that bench, view and render draw.
#include <unistd.h>

#include <cstdio>
#include <string>

#include "cmd/cli.h"
#include "cmd/commands.h"
#include "cmd/options.h"
#include "foundation/output_paths.h"
#include "foundation/progress.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/city_opendrive.h"
#include "runtime/scene/paged_load.h"
#include "runtime/scene/paged_walkthrough.h"
#include "runtime/traffic/sumo_process.h"
#include "runtime/traffic/traffic_run.h"

namespace vista {

int runTraffic(int argc, char** argv) {
    const std::string cmd = "vista traffic";
    CLI::App app{
        "Simulate traffic on a city with SUMO: vehicles (cars, vans, buses, trucks, bicycles) and "
        "pedestrians, kept as SUMO's floating-car data and traffic-light states in a directory.",
        cmd};
    std::string city, out;
    TrafficOptions opt;
    bool quiet = false;
    app.add_option("city", city,
                   "input scene file (.osgb from 'vista gen' or 'vista bake'), or a paged city directory (DIR.paged)")
        ->required();
    app.add_option("-o,--out", out, "the traffic directory to write (must not exist)")->required();
    addSeedOption(app, "--seed", opt.demand.seed, "random seed of the demand and of SUMO (default 1)");
    addNumberOption(app, "--vehicles", opt.demand.vehicles, 0, kMaxTrafficAgents,
                    "vehicles departing over the run, 0 .. 100000 (default 300)");
    addNumberOption(app, "--pedestrians", opt.demand.pedestrians, 0, kMaxTrafficAgents,
                    "pedestrians departing over the run, 0 .. 100000 (default 300)");
    addNumberOption(app, "--duration", opt.demand.durationS, RealRange::closed(1.0, kMaxTrafficDurationS),
                    "simulated seconds, 1 .. 86400 (default 600)");
    addNumberOption(app, "--step", opt.stepS, RealRange::closed(kMinTrafficStepS, kMaxTrafficStepS),
                    "SUMO's step and the sample interval of the output, seconds, 0.05 .. 2 (default 0.5)");
    app.add_flag("-q,--quiet", quiet, "no progress or summary on stderr");
    if (int rc = parseOrExit(app, argc, argv); rc >= 0) return rc;
    if (Status s = checkTrafficOptions(opt); !s) return reportBadInput(cmd, s);
    CommandFiles files;  // held until the directory is written (its lock)
    if (Status s = files.input("city", city).outputDirectory("-o", out).check(); !s) return reportBadInput(cmd, s);
    if (Status s = checkWritableDirectory("-o", out); !s) return reportBadInput(cmd, s);
    // SUMO is looked up before any work, so a missing install costs nothing.
    if (auto tools = findSumo(); !tools) return reportBadInput(cmd, tools.status());
    Result<SceneModel> model = Status::error("no city");
    if (isPagedCityPath(city)) {  // a paged city: its street graph grown again from the manifest's params
        auto paged = openPagedCity(city, true);
        if (!paged) return reportBadInput(cmd, paged.status());
        model = std::move(paged->stub);
    } else {
        model = loadCityFile(city);
    }
    if (!model) return reportBadInput(cmd, model.status());
    auto xodr = cityOpenDrive(*model, city);
    if (!xodr) return reportBadInput(cmd, xodr.status());
    StderrProgress stderrProgress(isatty(2) != 0);
    Progress silent;
    TrafficRunSummary sum;
    if (Status s = makeTraffic(*xodr, opt, out, quiet ? silent : stderrProgress, &sum); !s)
        return reportBadInput(cmd, s);
    if (!quiet)
        std::fprintf(stderr,
                     "wrote %s: %d vehicles inserted, %d pedestrians, over %g s (SUMO %s): %d collisions (%d "
                     "vehicle-pedestrian, %d vehicle-vehicle records in collisions.xml), %d teleports, %d "
                     "emergency stops\n",
                     out.c_str(), sum.vehiclesInserted, sum.personsInserted, opt.demand.durationS,
                     sum.sumoVersion.c_str(), sum.collisions, sum.collisionEvents.withPedestrians,
                     sum.collisionEvents.betweenVehicles, sum.teleports, sum.emergencyStops);
    return 0;
}

}  // namespace vista
