// A test fixture holding one small paged city, generated once per test suite
// by the built `vista` tool: 1.5 km in 500 m regions (3 x 3), facade detail 1
// to keep it quick. dir() is its DIR.paged; each test gets its own TempDir
// `tmp` for outputs.
#pragma once
#include <string>

#include <gtest/gtest.h>

#include "tests/common/run_vista.h"
#include "tests/common/temp_dir.h"

namespace vista::test {

class SmallPagedCity : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        ref = new TempDir("vista_paged_ref");
        const CliRun r =
            runVista("gen --size 1500 --seed 4 --detail 1 --region-size 500 -q -o " + ref->file("city.paged"));
        ASSERT_EQ(r.code, 0) << r.err;
    }
    static void TearDownTestSuite() {
        delete ref;
        ref = nullptr;
    }
    static std::string dir() { return ref->file("city.paged"); }
    static inline TempDir* ref = nullptr;
    TempDir tmp{"vista_paged"};
};

}  // namespace vista::test
