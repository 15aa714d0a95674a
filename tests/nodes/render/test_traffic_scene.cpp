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

#include <fstream>

#include <osg/Geode>
#include <osg/Geometry>
#include <osg/MatrixTransform>

#include "citygen/labels.h"
#include "citygen/traffic_signals.h"
#include "nodes/render/signal_heads.h"
#include "runtime/traffic/signal_states.h"
#include "runtime/scene/city_file.h"
#include "runtime/scene/paged_load.h"
#include "tests/common/run_vista.h"
#include "tests/common/small_paged_city.h"
#include "tests/common/temp_dir.h"

#include "nodes/render/effects_mode.h"
#include "nodes/render/render_mode.h"
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

// Traffic-light heads: two hand-placed heads facing an eye at the origin, lit
// from a hand-written signals.xml of one light whose two links are the heads'
// (SumoNet::signalLinks), walked through its switches in GL and in the ray scene.
namespace {

constexpr uint32_t kHeadA = 7, kHeadB = 9;  // OpenDRIVE signal ids

// A head at (x, y) on flat ground, facing -x (toward the origin).
SignalHead headAt(uint32_t signal, double x, double y) {
    SignalHead h;
    h.signal = signal;
    h.frame[0] = glm::dvec4(0, -1, 0, 0);  // x: the right hand of traffic looking along +x at it
    h.frame[1] = glm::dvec4(0, 0, 1, 0);
    h.frame[2] = glm::dvec4(-1, 0, 0, 0);
    h.frame[3] = glm::dvec4(x, y, 0, 1);
    return h;
}

// The light "J0": link 0 is head A's, link 1 head B's.
Result<SignalStates> states(const std::string& dir) {
    SumoNet net;
    net.trafficLights = {"J0"};
    net.signalLinks = {{kHeadA, 0, 0}, {kHeadB, 0, 1}};
    const std::string path = dir + "/signals.xml";
    std::ofstream(path) << "<tlsStates>\n"
                           "  <tlsState time=\"0.00\" id=\"J0\" programID=\"0\" phase=\"0\" state=\"Gr\"/>\n"
                           "  <tlsState time=\"4.00\" id=\"J0\" programID=\"0\" phase=\"1\" state=\"yr\"/>\n"
                           "  <tlsState time=\"6.00\" id=\"J0\" programID=\"0\" phase=\"2\" state=\"ru\"/>\n"
                           "  <tlsState time=\"8.00\" id=\"J0\" programID=\"0\" phase=\"3\" state=\"rG\"/>\n"
                           "</tlsStates>\n";
    return readSignalStates(net, path);
}

// Which of the three discs (0 red at the top, 1 amber, 2 green) of a head's
// overlay geometry are lit: a disc is lit when its brightest channel is
// above 200 (the dark ones stay below 80), read from the drawn vertex colours.
std::vector<bool> litDiscs(const osg::MatrixTransform& head) {
    const auto* geode = dynamic_cast<const osg::Geode*>(head.getChild(0));
    EXPECT_NE(geode, nullptr);
    const auto* g = geode ? dynamic_cast<const osg::Geometry*>(geode->getDrawable(0)) : nullptr;
    EXPECT_NE(g, nullptr);
    if (!g) return {};
    const auto* v = static_cast<const osg::Vec3Array*>(g->getVertexArray());
    const auto* c = static_cast<const osg::Vec4ubArray*>(g->getColorArray());
    // Disc by height: the discs' centres are 0.3 m apart, the top one highest
    // (its top vertex about 0.1 m above its centre).
    float top = -1e9f;
    for (const osg::Vec3& p : *v) top = std::max(top, p.y());
    std::vector<int> bright(3, 0), dark(3, 0);
    for (size_t i = 0; i < v->size(); ++i) {
        const int disc = std::clamp(int(std::lround((top - (*v)[i].y() - 0.1f) / 0.3f)), 0, 2);
        const osg::Vec4ub& col = (*c)[i];
        const int m = std::max({int(col.r()), int(col.g()), int(col.b())});
        if (m > 200) ++bright[size_t(disc)];
        else if (m < 80) ++dark[size_t(disc)];
    }
    std::vector<bool> lit(3);
    for (int k = 0; k < 3; ++k) {
        EXPECT_TRUE(bright[size_t(k)] == 0 || dark[size_t(k)] == 0) << "disc " << k << " half lit";
        lit[size_t(k)] = bright[size_t(k)] > 0;
    }
    return lit;
}

}  // namespace

TEST(TrafficScene, SignalHeadsShowSumosLampAtTheFrameTime) {
    vista::test::TempDir tmp("vista_traffic_heads");
    auto st = states(tmp.path());
    ASSERT_TRUE(st) << st.status().message();
    auto signals = std::make_shared<SignalStates>(std::move(*st));
    auto rs = RayScene::build(ground());
    ASSERT_TRUE(rs.isOk()) << rs.status().message();
    RayScene& rays = **rs;
    CityParams params;
    TrafficScene ts(tracks(), params, /*labels=*/false);
    ASSERT_TRUE(ts.attachRays(&rays));
    ASSERT_TRUE(ts.setSignalHeads(signals, {headAt(kHeadA, 20.0, 0.0), headAt(kHeadB, 60.0, 0.0)}));
    ASSERT_NE(ts.signalNode(), nullptr);
    ASSERT_EQ(ts.signalNode()->getNumChildren(), 2u);
    // The heads' group is node()'s last child whatever agents appear.
    const glm::dvec3 eye(0.0, 0.0, 1.5);
    struct Case {
        double t;
        LampState a, b;
        std::vector<bool> litA, litB;
    };
    const std::vector<Case> cases = {
        {2.0, LampState::Green, LampState::Red, {false, false, true}, {true, false, false}},
        {4.5, LampState::Amber, LampState::Red, {false, true, false}, {true, false, false}},
        {7.0, LampState::Red, LampState::RedAmber, {true, false, false}, {true, true, false}},
        {9.5, LampState::Red, LampState::Green, {true, false, false}, {false, false, true}},
    };
    for (const Case& c : cases) {
        ASSERT_TRUE(ts.setFrame(c.t, eye));
        ASSERT_TRUE(ts.setSplit(40.0));  // head A in GL, head B beyond (a mover)
        EXPECT_EQ(ts.node()->getChild(ts.node()->getNumChildren() - 1), ts.signalNode());
        ASSERT_EQ(ts.lamps().size(), 2u);
        EXPECT_EQ(ts.lamps()[0], c.a) << "t " << c.t;
        EXPECT_EQ(ts.lamps()[1], c.b) << "t " << c.t;
        // The lamp from SUMO's letters, read a second way: the link's letter at t.
        EXPECT_EQ(ts.lamps()[0], signals->lampAt(kHeadA, c.t));
        auto* a = dynamic_cast<osg::MatrixTransform*>(ts.signalNode()->getChild(0));
        auto* b = dynamic_cast<osg::MatrixTransform*>(ts.signalNode()->getChild(1));
        ASSERT_TRUE(a && b);
        EXPECT_EQ(litDiscs(*a), c.litA) << "t " << c.t;
        EXPECT_EQ(litDiscs(*b), c.litB) << "t " << c.t;
        EXPECT_NE(a->getNodeMask(), 0u);
        EXPECT_EQ(b->getNodeMask(), 0u);
        EXPECT_EQ(ts.headsDrawn(), 1u);
        EXPECT_EQ(ts.headsCast(), 1u);
        // The far head in the ray scene: a ray from the eye to its lit lamp's
        // centre meets the overlay, coloured as that lamp is lit.
        const int litLamp = c.b == LampState::Green ? 2 : 0;
        const glm::dvec3 target(60.0 - 0.5 * kSignalPoleWidth - kTrafficLightDepth - 0.01, 0.0,
                                kTrafficLightBottom + kTrafficLightHeight - (litLamp + 0.5) * kTrafficLightHeight / 3);
        const glm::dvec3 dir = glm::normalize(target - eye);
        const RayHit h = rays.intersect(glm::vec3(eye - rays.frameOrigin()), glm::vec3(dir));
        ASSERT_TRUE(h.hit) << "t " << c.t;
        EXPECT_NEAR(h.t, glm::length(target - eye), 0.05);
        EXPECT_EQ(rays.source(h).moverId, makeInstanceId(InstanceKind::TrafficLight, kHeadB));
        if (litLamp == 2) {
            EXPECT_GT(int(h.color.y), 200);
            EXPECT_LT(int(h.color.x), 100);
        } else {
            EXPECT_GT(int(h.color.x), 200);
            EXPECT_LT(int(h.color.y), 100);
        }
    }
    // Everything in GL (full): no head in the ray scene.
    ASSERT_TRUE(ts.setFrame(9.5, eye));
    EXPECT_EQ(ts.headsDrawn(), 2u);
    EXPECT_EQ(ts.headsCast(), 0u);
    // After the run (tracks end at 10 s): no overlay anywhere, the static lamps show.
    for (double split : {1e300, 40.0, 0.0}) {
        ASSERT_TRUE(ts.setFrame(12.0, eye));
        ASSERT_TRUE(ts.setSplit(split));
        EXPECT_EQ(ts.headsDrawn(), 0u);
        EXPECT_EQ(ts.headsCast(), 0u);
        for (unsigned i = 0; i < ts.signalNode()->getNumChildren(); ++i)
            EXPECT_EQ(ts.signalNode()->getChild(i)->getNodeMask(), 0u);
    }
}

TEST(TrafficScene, WithoutSignalStatesNoHeadNodeExists) {
    CityParams params;
    auto tr = tracks();  // no signals
    SceneModel none;
    TrafficScene ts(tr, params, /*labels=*/false);
    ASSERT_TRUE(ts.showCitySignals(none, nullptr));
    EXPECT_EQ(ts.signalNode(), nullptr);
    EXPECT_TRUE(ts.heads().empty());
    ASSERT_TRUE(ts.setFrame(6.0, glm::dvec3(0, 0, 1.5)));
    EXPECT_EQ(ts.node()->getNumChildren(), size_t(kAgents));
    EXPECT_EQ(ts.headsDrawn(), 0u);
    // States without heads: none either.
    ASSERT_TRUE(ts.setSignalHeads(nullptr, {headAt(kHeadA, 20.0, 0.0)}));
    EXPECT_EQ(ts.signalNode(), nullptr);
    EXPECT_EQ(ts.node()->getNumChildren(), size_t(kAgents));
}

// A frame places the ray scene's movers once: the effects wrapper only moves
// the traffic to the frame's time when the mode splits it (hybrid, raycast),
// and the mode's setSplit places it. The heads' still slots change only on
// the frames where a lamp changes (or a head crosses the split).
namespace {

// A mode that splits the traffic at 40 m, as hybrid does at its near distance.
class SplittingMode : public RenderMode {
public:
    SplittingMode(ModeContext& ctx, bool splits) : _ctx(ctx), _splits(splits) {}
    std::string name() const override { return "splitting"; }
    Status renderFrame(const Camera&, Image&, FrameStats&) override {
        return _splits ? _ctx.traffic->setSplit(40.0) : Status::ok();
    }
    osg::Node* viewerScene() override { return nullptr; }
    bool splitsTraffic() const override { return _splits; }

private:
    ModeContext& _ctx;
    bool _splits;
};

}  // namespace

TEST(TrafficScene, AFramePlacesTheMoversOnceAndTheHeadsOnlyWhenALampChanges) {
    vista::test::TempDir tmp("vista_traffic_place_once");
    auto st = states(tmp.path());
    ASSERT_TRUE(st) << st.status().message();
    auto signals = std::make_shared<SignalStates>(std::move(*st));
    auto rs = RayScene::build(ground());
    ASSERT_TRUE(rs.isOk()) << rs.status().message();
    RayScene& rays = **rs;
    CityParams params;
    TrafficScene ts(tracks(), params, /*labels=*/false);
    ASSERT_TRUE(ts.attachRays(&rays));
    ASSERT_TRUE(ts.setSignalHeads(signals, {headAt(kHeadA, 20.0, 0.0), headAt(kHeadB, 60.0, 0.0)}));
    for (const bool splits : {true, false}) {
        ModeContext ctx;
        ctx.traffic = &ts;
        std::unique_ptr<RenderMode> mode = withEffects(std::make_unique<SplittingMode>(ctx, splits), ctx);
        Camera c;
        c.eye = glm::dvec3(0.0, 0.0, 1.5);
        c.width = c.height = 16;
        Image img(16, 16);
        int lampChanges = 0;
        std::vector<LampState> before;
        // Frames 0.5 s apart through the run: the agents move every frame; head B (beyond 40 m)
        // changes its lamp at 6 s (red to red-amber) and 8 s (green).
        for (double t = 0.25; t < 10.0; t += 0.5) {
            c.time = t;
            const uint64_t commits = rays.moverCommits(), serial = rays.stillSerial();
            FrameStats fs;
            ASSERT_TRUE(mode->renderFrame(c, img, fs));
            EXPECT_LE(rays.moverCommits(), commits + 1) << "t " << t;
            if (!splits) {
                EXPECT_EQ(ts.headsCast(), 0u);  // everything in GL: nothing of the heads in the ray scene
                EXPECT_EQ(ts.castCount(), 0u);
                continue;
            }
            EXPECT_EQ(rays.moverCommits(), commits + 1) << "t " << t;  // the agents moved
            EXPECT_EQ(ts.headsCast(), 1u);
            const bool changed = !before.empty() && before[1] != ts.lamps()[1];
            if (!before.empty()) { EXPECT_EQ(rays.stillSerial() != serial, changed) << "t " << t; }
            lampChanges += changed ? 1 : 0;
            before = ts.lamps();
        }
        if (splits) { EXPECT_EQ(lampChanges, 2); }
    }
}

// A paged city's heads are those of the single-file city of the same input,
// whose lane model numbers the signals of the traffic's OpenDRIVE (`vista
// traffic`): the same ids at the same places, whether the walkthrough's model
// is merged from the regions (their street graph has another order) or is a
// streamed city's stub without streets.
TEST(PagedTrafficHeads, HaveTheIdsAndPlacesOfTheSingleFileCitysHeads) {
    const auto& paged = vista::test::smallPagedCity();
    auto m = readPagedManifest(paged.dir);
    ASSERT_TRUE(m) << m.status().message();
    vista::test::TempDir tmp("vista_paged_heads");
    // The single-file city of the small paged city's size and seed (its streets do not depend on the detail).
    const vista::test::CliRun gen =
        vista::test::runVista("gen --size 1500 --seed 4 --detail 0 -q -o " + tmp.path() + "/city.osgb");
    ASSERT_EQ(gen.code, 0) << gen.err;
    auto single = loadCityFile(tmp.path() + "/city.osgb");
    ASSERT_TRUE(single) << single.status().message();
    auto st = states(tmp.path());
    ASSERT_TRUE(st) << st.status().message();
    auto tr = tracks();
    tr->signals = std::make_shared<SignalStates>(std::move(*st));
    auto byId = [](std::vector<SignalHead> h) {
        std::sort(h.begin(), h.end(), [](const SignalHead& a, const SignalHead& b) { return a.signal < b.signal; });
        return h;
    };
    TrafficScene reference(tr, single->params, false);
    ASSERT_TRUE(reference.showCitySignals(*single, nullptr));
    const std::vector<SignalHead> expect = byId(reference.heads());
    ASSERT_GT(expect.size(), 3u) << "the small paged city has signalised junctions";

    std::vector<int> all(m->regions.size());
    for (size_t i = 0; i < all.size(); ++i) all[i] = int(i);
    auto merged = loadPagedCity(*m, all, kMaxPagedRadiusM);
    ASSERT_TRUE(merged) << merged.status().message();
    ASSERT_FALSE(merged->regions.empty());
    SceneModel stub;  // a streamed city with a path from a CSV file: params, no streets
    stub.params = m->params;
    for (const SceneModel* city : {&*merged, &stub}) {
        TrafficScene ts(tr, m->params, false);
        ASSERT_TRUE(ts.showCitySignals(*city, &*m));
        const std::vector<SignalHead> got = byId(ts.heads());
        ASSERT_EQ(got.size(), expect.size()) << (city == &stub ? "stub" : "merged");
        for (size_t i = 0; i < got.size(); ++i) {
            EXPECT_EQ(got[i].signal, expect[i].signal) << i;
            EXPECT_LT(glm::length(glm::dvec3(got[i].frame[3]) - glm::dvec3(expect[i].frame[3])), 1e-6) << i;
        }
    }
}
