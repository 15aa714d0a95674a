// Bounding boxes for dataset ground truth: an upright oriented 3D box per
// object instance of a city (computed once), and per frame and camera the
// 2D boxes of the instances an instance image shows, with their visible
// fraction; writers for one frame's boxes (JSON, KITTI label lines) and a
// KITTI calibration file (docs/formats.md "Boxes").
//
// Instances: the triangles labelled with an instance id (the id of a
// triangle's first vertex, as ground_truth.h rayLabel labels a hit) of the
// tile meshes, and the tree instances (their prototype mesh through the
// instance's transform; coarse-level impostors only for trees without a full
// instance). Only object kinds get boxes (isObjectKind: buildings, trees,
// street lights, traffic lights, traffic signs, parked cars, and the moving
// vehicles and pedestrians of a traffic run); roads, junctions, sidewalks and
// parks are surfaces and get none.
//
// Moving objects (MovingObject): the agents of a traffic run are not part of
// the city; a frame passes them in, each with its instance id, class, world
// box and velocity at the frame's time and its mesh (model frame) with the
// model -> world transform. frameBoxes() boxes an id of the instance image
// from the city's boxes or, when the city has none, from the moving objects
// (sorted by id), rasterising the moving object's mesh for its unoccluded
// pixels as it does a city instance's triangles.
//
// 3D box (OrientedBox), world frame (x east, y north, z up, metres, double):
// upright, z extent = the instance's vertices' z range; in plan the rectangle
// of minimal area around the footprint's convex hull (one side lies on a hull
// edge, Freeman & Shapira, so each hull edge's direction is tried). size.x is
// the length (along yaw), size.y the width (size.x >= size.y), size.z the
// height; yaw = radians counter-clockwise from +x to the length axis, in
// (-pi/2, pi/2] (a box has no front). The box contains every vertex of its
// instance.
//
// Cameras (BoxCamera): a position, the axes of the camera's OpenCV frame
// (x right, y down, z forward) in the world, a camera model
// (runtime/scene/camera_model.h: a pinhole with any fx, fy, cx, cy, or an
// equidistant fisheye) and, for a pinhole, a near plane zNear. A vista
// `Camera` converts to one (boxCamera): fx = fy = height / (2 tan(fovY /
// 2)), cx = (width - 1) / 2, cy = (height - 1) / 2, its zNear; every
// function taking a `Camera` is that conversion and the BoxCamera function.
//
// 2D boxes (frameBoxes): pixel coordinates of the OpenCV convention that
// cameras.json and the rig files use: u = column, v = row from the top,
// pixel centres at integers; the image spans [-0.5, width - 0.5] x [-0.5,
// height - 0.5]. `visible` = the first and last column and row (inclusive
// pixel indices) of the instance's pixels in the instance image, `pixels`
// their count. `full` = the extent of the instance's whole geometry as
// projected by the camera, clipped to the image: the box an unoccluded
// instance would have. `boxExtent` = the same for its 3D box.
// `unoccludedPixels` = the pixels whose centre the instance's own
// front-facing triangles cover, with nothing else in the scene: its
// triangles rasterised into a mask on the CPU (pixel-centre sampling, back
// faces culled as the label pass and the label rays do). Rasterising rather
// than ray casting the instance alone costs its triangles plus the pixels
// it covers, needs no per-instance acceleration structure and no GL
// context, and samples the same points as the instance image.
// visibleFraction = pixels / unoccludedPixels, clamped to [0, 1] (edge
// pixels may differ by the fill rule); `truncated` = 1 - the share of the
// projected geometry's extent (area) inside the image.
// Pinhole: every triangle is clipped against the near plane z = zNear
// before it is projected (u = cx + fx x / z, v = cy + fy y / z), so
// geometry behind the camera never inverts a box; the projected box is that
// of its 8 corners and 12 edges, clipped the same way. Fisheye (r = f
// theta): the model projects every direction but the one straight behind,
// and a pixel sees only directions within the image circle (theta <=
// maxFovDeg / 2), so geometry is clipped against that cone instead: a
// triangle's projected extent is that of its edges' images inside the cone
// (each edge sampled at most 1 px apart in the image, plus the points where
// it crosses the cone) and of the image circle's four extreme points
// (theta = maxFov / 2, azimuth 0, 90, 180, 270 degrees) whose ray passes
// through the triangle: the image of a triangle within the cone is bounded
// by those edge pieces and arcs of the circle, and an arc's extent is its
// end points' or the circle's extreme points'. The sampling of an edge's
// curved image errs by well under 0.1 px (inside). Shortcuts that keep the
// result to the bit (extents are minima and maxima, so points within the
// extent so far change nothing): a triangle whose conservative bound (the
// image of a cap around its directions, computed without sampling) lies
// within the extent of the instance's triangles so far is not sampled, and
// a run of up to 32 samples of an edge (at least 4: the edge's last ones)
// whose cap lies inside the cone and whose image lies within the extent so
// far is not sampled (a run that fails the test is sampled and not tested
// again); the cone test decides by cosines where they differ by far more
// than rounding, else by the angle; the extent starts
// from the in-cone vertices of every fourth triangle (each vertex is its
// edge's first sample). The fisheye mask
// tests each pixel centre of a front-facing triangle's extent (or that
// bound, when samples were skipped): its ray (pixelRay, from
// FrameBoxOptions::rays when given) passes through the triangle; tile by
// tile (camera_ray_table.h), a tile whose directions all lie beyond one of
// the triangle's planes by a margin far above rounding is skipped, one
// whose directions all lie within the three is marked whole, and one whose
// pixels inside the circle are all marked already (by the instance's
// earlier triangles) is skipped, so the marked pixels are those of the
// per-pixel test. The projected 3D box is the
// extent of its 12 triangles (with the same shortcuts).
//
// Vehicle frame (boxInVehicleFrame): x forward, y left, z up (LidarPose's
// convention, KITTI's velodyne frame). The centre is exact for any pose;
// the yaw is that of the box's length axis projected onto the vehicle's xy
// plane (exact for a level vehicle; the box is upright in the world).
//
// Thread safety: pure functions on const inputs; CityBoxes is immutable
// after build and may be shared. Parallel over `threads` workers (0 = all):
// frameBoxes counts the instance image's pixels in bands of rows and
// rasterises the instances in parallel (those with the most triangles
// first), isolated (tbb::this_task_arena::isolate): a thread waiting for
// these tasks runs none of the caller's other work, such as the next
// camera's casting in a rig run; the results do not depend on the thread
// count. Contract violations
// (an instance image whose size differs from the camera's, a pinhole
// zNear <= 0) are VISTA_CHECKs.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "citygen/labels.h"
#include "citygen/mesh.h"
#include "runtime/engine/lidar.h"
#include "runtime/engine/camera_ray_table.h"
#include "runtime/scene/camera.h"
#include "runtime/scene/camera_model.h"
#include "runtime/scene/scene_model.h"

namespace vista {

// True for the kinds that get boxes (objects, not surfaces).
bool isObjectKind(InstanceKind k);

struct OrientedBox {
    glm::dvec3 center{0.0};  // metres
    glm::dvec3 size{0.0};    // length (along yaw), width, height; metres
    double yaw = 0;          // radians counter-clockwise from +x, (-pi/2, pi/2]
    // Unit length axis (cos yaw, sin yaw, 0) and width axis (-sin yaw, cos yaw, 0).
    glm::dvec3 lengthAxis() const;
    glm::dvec3 widthAxis() const;
    // Corners: bottom face (z = centre - height / 2) counter-clockwise from
    // (-length, -width) / 2 seen from above, then the top face in the same order.
    std::array<glm::dvec3, 8> corners() const;
    // True when p lies inside, grown by `margin` metres on every side.
    bool contains(const glm::dvec3& p, double margin = 0.0) const;
};

// The minimal-area upright box around world points (the footprint's convex
// hull, rotating each hull edge). Empty input: a zero box at the origin.
OrientedBox fitUprightBox(const std::vector<glm::dvec3>& points);

struct InstanceBox {
    uint32_t id = 0;                                // instance id (citygen/labels.h)
    OrientedBox box;                                // world frame
    uint32_t firstTriangle = 0, triangleCount = 0;  // its mesh triangles in CityBoxes::triangles
    std::vector<uint32_t> trees;                    // indices into SceneModel::instances
    std::vector<uint32_t> impostors;                // indices into SceneModel::impostors
};

struct MeshTriangle {
    uint32_t mesh = 0, prim = 0;  // SceneModel::meshes index, triangle index in it
};

struct CityBoxes {
    std::vector<InstanceBox> boxes;              // sorted by id, one per object instance
    std::vector<MeshTriangle> triangles;         // grouped by box (InstanceBox::firstTriangle)
    const InstanceBox* find(uint32_t id) const;  // null when the id has no box
};

// The boxes of every object instance of `city` (deterministic).
CityBoxes buildCityBoxes(const SceneModel& city, int threads = 0);

// The world points of an instance's geometry (each triangle's 3 vertices,
// tree prototypes transformed), in triangle order; duplicates kept.
std::vector<glm::dvec3> instancePoints(const SceneModel& city, const CityBoxes& boxes, const InstanceBox& box);

// The box in the vehicle frame of `pose` (see the contract above).
OrientedBox boxInVehicleFrame(const OrientedBox& world, const LidarPose& pose);

// Pinhole intrinsics of a camera, OpenCV convention (see above).
struct PinholeIntrinsics {
    double fx = 0, fy = 0, cx = 0, cy = 0;
};
PinholeIntrinsics pinholeIntrinsics(const Camera& camera);

// A camera as the boxes see it (see above).
struct BoxCamera {
    glm::dvec3 eye{0.0};   // world, metres
    glm::dmat3 axes{1.0};  // columns: the camera's x (right), y (down), z (forward) in the world; a rotation
    CameraModel model;
    double zNear = 0.3;  // pinhole near plane, metres (> 0); the fisheye has none
    // A world point in camera coordinates: x right, y down, z forward (metres).
    glm::dvec3 toCamera(const glm::dvec3& world) const { return glm::transpose(axes) * (world - eye); }
};
BoxCamera boxCamera(const Camera& camera);

// A world point in camera coordinates: x right, y down, z forward (metres).
glm::dvec3 cameraPoint(const Camera& camera, const glm::dvec3& world);

// A 2D extent in pixels (u0 <= u1, v0 <= v1 when valid).
struct PixelBox {
    double u0 = 0, v0 = 0, u1 = -1, v1 = -1;
    bool valid() const { return u0 <= u1 && v0 <= v1; }
    double area() const { return valid() ? (u1 - u0) * (v1 - v0) : 0.0; }
};
// The projected extent of a convex polyhedron given by its vertices and
// edges (pairs of vertex indices) in a pinhole camera, its edges clipped
// against the near plane z = zNear: not clipped to the image; invalid when
// nothing lies in front of the near plane. A fisheye camera is a contract
// violation (projectedBox handles both).
PixelBox projectedExtent(const BoxCamera& camera, const std::vector<glm::dvec3>& vertices,
                         const std::vector<std::array<int, 2>>& edges);
PixelBox projectedExtent(const Camera& camera, const std::vector<glm::dvec3>& vertices,
                         const std::vector<std::array<int, 2>>& edges);
// The projected extent of the box (see above), not clipped to the image;
// invalid when none of it can be seen (behind a pinhole's near plane,
// outside a fisheye's cone).
PixelBox projectedBox(const BoxCamera& camera, const OrientedBox& box);
PixelBox projectedBox(const Camera& camera, const OrientedBox& box);
// The extent clipped to the image [-0.5, width - 0.5] x [-0.5, height - 0.5] (invalid when outside).
PixelBox clipToImage(const PixelBox& b, int width, int height);
PixelBox clipToImage(const PixelBox& b, const Camera& camera);

// A moving object at one frame's time (see above).
struct MovingObject {
    uint32_t id = 0;             // instance id (labels.h)
    uint8_t semantic = 0;        // its SemanticClass
    OrientedBox box;             // world frame
    glm::dvec3 velocity{0.0};    // of the box centre, world frame, m/s
    const Mesh* mesh = nullptr;  // model frame; not owned (outlives the frame's boxes)
    glm::dmat4 toWorld{1.0};     // model frame -> world
};
// The moving object with `id` in `movers` (sorted by id), null when none.
const MovingObject* findMover(const std::vector<MovingObject>& movers, uint32_t id);

struct FrameBox {
    uint32_t id = 0;
    OrientedBox box;                                                   // world frame
    int visibleU0 = 0, visibleV0 = 0, visibleU1 = -1, visibleV1 = -1;  // inclusive pixel indices
    uint32_t pixels = 0;                                               // visible pixels
    PixelBox full;                                                     // projected geometry, clipped to the image
    PixelBox boxExtent;                                                // projected 3D box, clipped to the image
    uint32_t unoccludedPixels = 0;                                     // the instance's mask alone
    double visibleFraction = 0;                                        // pixels / unoccludedPixels in [0, 1]
    double truncated = 0;                                              // 0 .. 1
    uint8_t semantic = 255;    // a moving object's class; 255: a city instance (type by its kind)
    glm::dvec3 velocity{0.0};  // world m/s (0 for city instances)
};

struct FrameBoxOptions {
    uint32_t minPixels = 1;  // instances with fewer visible pixels get no box
    int threads = 0;
    // The camera model's pixel rays (camera_ray_table.h), shared across frames: the
    // fisheye masks read them instead of calling pixelRay per tested pixel
    // (the same directions, so the same boxes). Null, or a table of another
    // model: frameBoxes builds one for the call.
    const CameraRayTable* rays = nullptr;
};

// The 2D boxes of one frame: every object instance with at least minPixels
// pixels in `ids` (the instance image: width * height ids of the camera's
// model, row 0 at the top), sorted by id.
std::vector<FrameBox> frameBoxes(const SceneModel& city, const CityBoxes& boxes, const BoxCamera& camera,
                                 const std::vector<uint32_t>& ids, const FrameBoxOptions& options = {});
// The same with the frame's moving objects (sorted by id) boxed too.
std::vector<FrameBox> frameBoxes(const SceneModel& city, const CityBoxes& boxes,
                                 const std::vector<MovingObject>& movers, const BoxCamera& camera,
                                 const std::vector<uint32_t>& ids, const FrameBoxOptions& options = {});
std::vector<FrameBox> frameBoxes(const SceneModel& city, const CityBoxes& boxes, const Camera& camera,
                                 const std::vector<uint32_t>& ids, const FrameBoxOptions& options = {});

// One frame's boxes as JSON text (docs/formats.md "Boxes"): world
// positions minus `worldOffset` (cameras.json's world_offset), the camera's
// model and intrinsics (and its name when `cameraName` is not empty), and
// per box its 2D extents and its 3D box in the world and camera frames.
std::string frameBoxesJson(const std::vector<FrameBox>& boxes, const BoxCamera& camera, const glm::dvec3& worldOffset,
                           const std::string& cameraName = "");
std::string frameBoxesJson(const std::vector<FrameBox>& boxes, const Camera& camera, const glm::dvec3& worldOffset);

// KITTI object label lines (one per box, '\n'-terminated): type, truncated,
// occluded (0: visibleFraction >= 0.8, 1: >= 0.4, 2: less), alpha, bbox
// (the visible extent, inclusive pixel indices), dimensions (height, width,
// length), location (bottom centre in camera coordinates), rotation_y.
// For a level pinhole camera (pitch and roll 0) as KITTI assumes.
std::string kittiLabels(const std::vector<FrameBox>& boxes, const BoxCamera& camera);
std::string kittiLabels(const std::vector<FrameBox>& boxes, const Camera& camera);
const char* kittiType(InstanceKind k);  // "Car", "Building", "Tree", ...
// A box's KITTI type: of its class for a moving object (car "Car", van "Van",
// truck "Truck", bus "Bus", bicycle "Cyclist", pedestrian "Pedestrian", other
// vehicles "Misc"), else of its instance kind.
const char* kittiType(const FrameBox& box);

// A KITTI calibration file: P0..P3 = the camera's pinhole matrix, R0_rect =
// identity, Tr_velo_to_cam = the LiDAR (pose `lidar`, x forward, y left,
// z up) to camera transform, Tr_imu_to_velo = identity.
std::string kittiCalib(const Camera& camera, const LidarPose& lidar);

}  // namespace vista
