// Traffic-light state labels (traffic_light_labels.h) from hand-made frame
// boxes: only traffic-light instances with pixels get a line, in id order,
// with the head's lamp from the caller, its visible extent, pixel count and
// instance id; other kinds and an empty frame give no line. The boxes of an
// instance image are the extents and counts of its traffic-light ids,
// counted here pixel by pixel.
#include <gtest/gtest.h>

#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "citygen/labels.h"
#include "runtime/engine/traffic_light_labels.h"

using namespace vista;

namespace {

FrameBox box(InstanceKind kind, uint32_t index, int u0, int v0, int u1, int v1, uint32_t pixels) {
    FrameBox b;
    b.id = makeInstanceId(kind, index);
    b.visibleU0 = u0, b.visibleV0 = v0, b.visibleU1 = u1, b.visibleV1 = v1;
    b.pixels = pixels;
    return b;
}

TEST(TrafficLightLabels, OneLinePerVisibleHeadWithItsLamp) {
    // frameBoxes sorts by id: a building (kind 1) before the lights (kind 8) before a sign.
    const std::vector<FrameBox> boxes = {
        box(InstanceKind::Building, 3, 0, 0, 9, 9, 100), box(InstanceKind::TrafficLight, 4, 10, 2, 12, 7, 11),
        box(InstanceKind::TrafficLight, 9, 30, 1, 30, 1, 0), box(InstanceKind::TrafficLight, 17, 40, 5, 44, 20, 52),
        box(InstanceKind::TrafficSign, 4, 50, 5, 52, 9, 8)};
    const std::map<uint32_t, std::string> lamps = {{4, "red"}, {9, "green"}, {17, "red-amber"}};
    std::vector<uint32_t> asked;
    const std::string text = trafficLightLabels(boxes, [&](uint32_t head) {
        asked.push_back(head);
        return lamps.at(head);
    });
    std::istringstream in(text);
    std::string line;
    std::vector<std::string> lines;
    while (std::getline(in, line)) lines.push_back(line);
    ASSERT_EQ(lines.size(), 2u) << text;
    EXPECT_EQ(asked, (std::vector<uint32_t>{4, 17})) << "a head without pixels is not asked for";
    const uint32_t id4 = (uint32_t(InstanceKind::TrafficLight) << kInstanceIndexBits) | 4u;
    const uint32_t id17 = (uint32_t(InstanceKind::TrafficLight) << kInstanceIndexBits) | 17u;
    EXPECT_EQ(lines[0], "4 red 10 2 12 7 11 " + std::to_string(id4));
    EXPECT_EQ(lines[1], "17 red-amber 40 5 44 20 52 " + std::to_string(id17));
    EXPECT_EQ(text.back(), '\n');
    EXPECT_EQ(trafficLightLabels({boxes[0], boxes[4]}, [](uint32_t) { return std::string("green"); }), "");
}

TEST(TrafficLightLabels, BoxesOfAnInstanceImageAreItsTrafficLightPixels) {
    const int w = 7, h = 5;
    const uint32_t light3 = makeInstanceId(InstanceKind::TrafficLight, 3);
    const uint32_t light1 = makeInstanceId(InstanceKind::TrafficLight, 1);
    const uint32_t wall = makeInstanceId(InstanceKind::Building, 3);
    std::vector<uint32_t> ids(size_t(w * h), wall);
    ids[size_t(1 * w + 5)] = light3, ids[size_t(3 * w + 2)] = light3, ids[size_t(2 * w + 4)] = light3;
    ids[size_t(4 * w + 0)] = light1;
    const std::vector<FrameBox> boxes = trafficLightBoxes(ids, w, h);
    ASSERT_EQ(boxes.size(), 2u);
    EXPECT_EQ(boxes[0].id, light1);  // sorted by id
    EXPECT_EQ(boxes[0].visibleU0, 0);
    EXPECT_EQ(boxes[0].visibleU1, 0);
    EXPECT_EQ(boxes[0].visibleV0, 4);
    EXPECT_EQ(boxes[0].visibleV1, 4);
    EXPECT_EQ(boxes[0].pixels, 1u);
    EXPECT_EQ(boxes[1].id, light3);
    EXPECT_EQ(boxes[1].visibleU0, 2);
    EXPECT_EQ(boxes[1].visibleU1, 5);
    EXPECT_EQ(boxes[1].visibleV0, 1);
    EXPECT_EQ(boxes[1].visibleV1, 3);
    EXPECT_EQ(boxes[1].pixels, 3u);
    EXPECT_EQ(trafficLightLabels(boxes, [](uint32_t) { return std::string("off"); }),
              "1 off 0 4 0 4 1 " + std::to_string(light1) + "\n3 off 2 1 5 3 3 " + std::to_string(light3) + "\n");
    EXPECT_TRUE(trafficLightBoxes(std::vector<uint32_t>(size_t(w * h), wall), w, h).empty());
}

}  // namespace
