// Shared scenes of the split tests: a random ray scene, square objects, a small camera and
// options priced on measurements only.
#pragma once

#include <memory>
#include <vector>

#include "foundation/status.h"
#include "runtime/engine/adaptive_split.h"
#include "runtime/engine/ray_scene.h"
#include "tests/runtime/engine/fixtures.h"

namespace vista::test {

// A random 800 m city of 150 boxes as a ray scene, and one split object over it.
struct ProbeScene {
    std::unique_ptr<RayScene> rays;
    std::vector<SplitObject> objs;
};
inline ProbeScene probeScene(uint32_t seed) {
    auto rs = RayScene::build(randomCity(seed, 150, 800.0));
    VISTA_CHECK(rs.isOk());
    return ProbeScene{std::move(rs.value()), {splitBox({-400, -400, 0}, {400, 400, 60}, 1000)}};
}
// One object per 50 m square of an 800 m city, 1000 triangles each.
inline std::vector<SplitObject> squareObjects() {
    std::vector<SplitObject> objs;
    for (int x = -8; x < 8; ++x)
        for (int y = -8; y < 8; ++y)
            objs.push_back(splitBox({x * 50.0, y * 50.0, 0}, {x * 50.0 + 50, y * 50.0 + 50, 60}, 1000));
    return objs;
}
// A 64x48 camera at `eye`, looking along +y.
inline Camera smallCamera(const glm::dvec3& eye) {
    Camera c;
    c.eye = eye;
    c.width = 64;
    c.height = 48;
    return c;
}
// No exploration and no probe timing: the costs a test records are the only measurements.
inline AdaptiveSplitOptions measuredOnly() {
    AdaptiveSplitOptions o;
    o.exploreEvery = 0;
    o.timeProbe = false;
    return o;
}

}  // namespace vista::test
