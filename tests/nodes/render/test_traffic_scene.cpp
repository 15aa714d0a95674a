// TrafficScene (nodes/render/traffic_scene.h) without GL: hand-made tracks of a
// few agents walked frame by frame as bench walks full and hybrid (setFrame,
// then setSplit): every agent gets its nodes once, the children of node() stay
// the same objects in agent order (a frame changes masks and matrices only),
// the shown children are the agents within the split, the others are in the
// ray scene, hit there with their labels.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include <osg/MatrixTransform>

#include "nodes/render/traffic_scene.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/traffic/agent_models.h"
#include "runtime/traffic/traffic_tracks.h"

using namespace vista;

namespace {

constexpr int kAgents = 6;
constexpr int kFrames = 11;     // samples at t = 0 .. 10 s
constexpr int kLateAgent = 5;   // appears at t = 5 s
constexpr double kSpeed = 1.0;  // m/s along +x

// Agent i at x = 10 + 15 i + t, y = 0, heading +x; even agents cars, odd ones pedestrians.
std::shared_ptr<TrafficTracks> tracks() {
    auto tr = std::make_shared<TrafficTracks>();
    for (int i = 0; i < kAgents; ++i) {
        tr->agentIds.push_back("a" + std::to_string(i));
        tr->agentTypes.push_back(i % 2 == 0 ? AgentType::Car : AgentType::Pedestrian);
    }
    for (int f = 0; f < kFrames; ++f) {
        tr->times.push_back(double(f));
        tr->frameStart.push_back(uint32_t(tr->poses.size()));
        for (int i = 0; i < kAgents; ++i) {
            if (i == kLateAgent && f < 5) continue;
            AgentPose p;
            p.agent = uint32_t(i);
            p.x = float(10.0 + 15.0 * i + kSpeed * f);
            p.y = 0.0f;
            p.heading = 0.0f;
            p.speed = float(kSpeed);
            tr->poses.push_back(p);
        }
    }
    return tr;
}

// A ground slab far below the agents, so the ray scene has a region and a frame.
SceneModel ground() {
    SceneModel c;
    SceneMesh m;
    const glm::vec3 lo(-300, -300, -11), hi(300, 300, -10);
    const glm::vec3 v[4] = {{lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
    for (const auto& p : v) {
        m.positions.push_back(p);
        m.colors.push_back({90, 90, 90, 255});
    }
    m.indices = {0, 1, 2, 0, 2, 3};
    c.meshes.push_back(m);
    return c;
}

std::vector<osg::Node*> children(const osg::Group& g) {
    std::vector<osg::Node*> out;
    for (unsigned i = 0; i < g.getNumChildren(); ++i) out.push_back(const_cast<osg::Node*>(g.getChild(i)));
    return out;
}

}  // namespace

TEST(TrafficScene, FramesMoveTheSameNodesAndSplitThemBetweenGlAndRays) {
    auto tr = tracks();
    CityParams params;  // flat ground at the origin
    auto rs = RayScene::build(ground());
    ASSERT_TRUE(rs.isOk()) << rs.status().message();
    RayScene& rays = **rs;
    TrafficScene ts(tr, params, /*labels=*/true);
    ASSERT_TRUE(ts.attachRays(&rays));
    const glm::dvec3 eye(0.0, 0.0, 1.5);
    const double split = 40.0;
    std::vector<osg::Node*> before;
    for (int step = 0; step < 2 * (kFrames - 1); ++step) {
        const double t = 0.5 * step;
        // full: every agent in GL.
        ASSERT_TRUE(ts.setFrame(t, eye));
        const size_t present = ts.placements().size();
        EXPECT_EQ(present, size_t(t < 5.0 ? kAgents - 1 : kAgents)) << "t " << t;
        EXPECT_EQ(ts.drawnCount(), present);
        EXPECT_EQ(ts.castCount(), 0u);
        EXPECT_EQ(rays.moverCount(), 0u);
        // hybrid: GL within the split, rays beyond.
        ASSERT_TRUE(ts.setSplit(split));
        // One node (and a label twin) per agent that has appeared, never more.
        EXPECT_EQ(ts.nodesMade(), 2 * present) << "t " << t;
        ASSERT_EQ(ts.node()->getNumChildren(), present);
        ASSERT_EQ(ts.labelNode()->getNumChildren(), present);
        // The children of the step before are the same objects, in the same order (the late agent is
        // the last in agent order).
        const std::vector<osg::Node*> now = children(*ts.node());
        if (!before.empty()) {
            ASSERT_GE(now.size(), before.size());
            EXPECT_TRUE(std::equal(before.begin(), before.end(), now.begin())) << "t " << t;
        }
        before = now;
        // Shown children: the agents whose sphere reaches within the split, at their place of time t.
        size_t shown = 0, cast = 0;
        for (const AgentPlacement& a : ts.placements()) {
            const double d = glm::length(a.centre - eye);
            const bool gl = d - a.radius <= split, far = d + a.radius > split;
            auto* x = dynamic_cast<osg::MatrixTransform*>(ts.node()->getChild(a.agent));
            ASSERT_NE(x, nullptr);
            const osg::Vec3d pos = x->getMatrix().getTrans();
            EXPECT_EQ(x->getNodeMask() != 0u, gl) << "agent " << a.agent << " t " << t;
            EXPECT_EQ(ts.labelNode()->getChild(a.agent)->getNodeMask() != 0u, gl);
            if (gl) {
                EXPECT_NEAR(pos.x(),
                            10.0 + 15.0 * a.agent + kSpeed * t -
                                (a.agent % 2 == 0 ? 0.5 * ts.models().models[a.prototype].length : 0.0),
                            1e-4);
                ++shown;
            }
            if (far) {
                // In the ray scene: a ray down onto its centre strikes it first, with its label.
                ++cast;
                const glm::vec3 org(glm::dvec3(a.centre.x, a.centre.y, 30.0) - rays.frameOrigin());
                const RayHit h = rays.intersect(org, glm::vec3(0, 0, -1));
                ASSERT_TRUE(h.hit) << "agent " << a.agent;
                EXPECT_LT(h.t, 30.0f);
                const AgentType type = tr->agentTypes[a.agent];
                EXPECT_EQ(rays.source(h).moverId, agentLabel(type, a.agent)) << "agent " << a.agent;
            }
        }
        EXPECT_EQ(ts.drawnCount(), shown);
        EXPECT_EQ(ts.castCount(), cast);
        EXPECT_EQ(rays.moverCount(), cast);
        EXPECT_GT(shown, 0u);
        EXPECT_GT(cast, 0u);
    }
}

TEST(TrafficScene, WithoutRaysTheAgentsBeyondTheSplitAreNotDrawn) {
    auto tr = tracks();
    CityParams params;
    TrafficScene ts(tr, params, /*labels=*/false);
    const glm::dvec3 eye(0.0, 0.0, 1.5);
    ASSERT_TRUE(ts.setFrame(6.0, eye));
    EXPECT_EQ(ts.drawnCount(), size_t(kAgents));
    ASSERT_TRUE(ts.setSplit(0.0));  // every agent beyond: none in GL, none cast (no ray scene)
    EXPECT_EQ(ts.drawnCount(), 0u);
    EXPECT_EQ(ts.castCount(), 0u);
    for (unsigned i = 0; i < ts.node()->getNumChildren(); ++i) EXPECT_EQ(ts.node()->getChild(i)->getNodeMask(), 0u);
    EXPECT_EQ(ts.nodesMade(), size_t(kAgents));
    ASSERT_TRUE(ts.setSplit(1e300));
    EXPECT_EQ(ts.drawnCount(), size_t(kAgents));
    EXPECT_EQ(ts.nodesMade(), size_t(kAgents));
}
