// Shared setup of the tests that run SUMO: whether it is installed, and the
// small cities they simulate. Header-only; the library helpers need
// vista::citygen, the CLI helper the built `vista` tool (run_vista.h).
//
// haveSumo(): whether both `sumo` and `netconvert` are on PATH (Debian's sumo
// and sumo-tools packages; .ci/setup.sh installs them). Asked of the shell on
// every call.
// VISTA_SKIP_WITHOUT_SUMO(): in a test body or a fixture's SetUp, skips the
// test with a message naming what is missing when haveSumo() is false.
// sumoCityParams(): the library tests' city: 800 m side, seed 11, detail 0,
// other parameters at their defaults (a caller may change more before
// generating).
// xodrCity(params): generates the city of `params` and its OpenDRIVE text
// (the blocks extracted again from the streets for the sidewalks); the
// generator's or the writer's error otherwise.
// genTrafficCity(osgb): `vista gen` of the CLI tests' city (700 m side,
// seed 5, detail 0, quiet) into the file `osgb`; the run's exit code and stderr.
#pragma once
#include <cstdlib>
#include <string>
#include <vector>

#include "citygen/blocks.h"
#include "citygen/city.h"
#include "citygen/generate.h"
#include "citygen/opendrive.h"
#include "citygen/params.h"
#include "foundation/status.h"
#include "tests/common/run_vista.h"

namespace vista::test {

inline bool haveSumo() {
    return std::system("command -v sumo >/dev/null 2>&1 && command -v netconvert >/dev/null 2>&1") == 0;
}

#define VISTA_SKIP_WITHOUT_SUMO()                                                                 \
    do {                                                                                          \
        if (!::vista::test::haveSumo())                                                           \
            GTEST_SKIP() << "SUMO (sumo, netconvert) is not installed; .ci/setup.sh installs it"; \
    } while (0)

inline CityParams sumoCityParams() {
    CityParams params;
    params.size_m = 800.0;
    params.seed = 11;
    params.detail = 0;
    return params;
}

struct XodrCity {
    City city;
    std::string xodr;  // the city's OpenDRIVE text
};

inline Result<XodrCity> xodrCity(const CityParams& params) {
    auto city = generateCity(params);
    if (!city) return city.status();
    const std::vector<Block> blocks = extractBlocks(city->streets, params, nullptr);
    auto xodr = openDriveXml(city->streets, params, &blocks);
    if (!xodr) return xodr.status();
    return XodrCity{std::move(*city), std::move(*xodr)};
}

inline CliRun genTrafficCity(const std::string& osgb) {
    return runVista("gen --size 700 --detail 0 --seed 5 -q -o " + osgb);
}

}  // namespace vista::test
