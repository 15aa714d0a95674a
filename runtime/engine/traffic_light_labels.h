// Traffic-light state labels of one camera frame (docs/formats.md "Traffic-
// light labels"): per traffic-light head the camera sees, its head id, the
// lamp it shows at the frame's time and its 2D box.
//
// trafficLightLabels(): one line per box of `boxes` (boxes.h frameBoxes: the
// instances with pixels in the frame's instance image, sorted by id) whose
// instance kind is TrafficLight, '\n'-terminated, in id order:
//   head state left top right bottom pixels instance_id
// head = the instance index (citygen/labels.h: the OpenDRIVE <signal id>,
// LaneModel::signals index, that SUMO's network links carry); state =
// lampName(head) (the caller's lamp at the frame's time: "green", "amber",
// "red-amber", "red" or "off"); left top right bottom = the visible extent
// (FrameBox visibleU0, visibleV0, visibleU1, visibleV1: inclusive pixel
// indices of the head's pixels); pixels = its visible pixel count;
// instance_id = its 32-bit instance id (the value in the instance image).
// A head whose instance has no pixel in the image (out of view or hidden by
// nearer geometry) has no box and so no line; a frame without a visible
// head gives "". Pure; thread-safe when lampName is.
//
// trafficLightBoxes(): the boxes of the traffic-light instances of an
// instance image (`ids`: width * height instance ids, row 0 at the top), for
// a run without city boxes (the one-camera `vista render`): per id of kind
// TrafficLight, sorted by id, only `id`, the visible extent and `pixels` set.
// VISTA_CHECKs ids.size() == width * height.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "runtime/engine/boxes.h"

namespace vista {

std::string trafficLightLabels(const std::vector<FrameBox>& boxes,
                               const std::function<std::string(uint32_t head)>& lampName);

std::vector<FrameBox> trafficLightBoxes(const std::vector<uint32_t>& ids, int width, int height);

}  // namespace vista
