// TrafficScene: a traffic run's moving agents (runtime/traffic) drawn in a
// walkthrough: in the near field as OSG geometry and in the ray-cast far
// field as Embree instances (RayScene::placeMovers), one frame time at a time.
//
// Contract:
// - The agent meshes (agent_models.h) become one shared osg::Geometry per
//   prototype (VBOs, prelit colours, lighting off, back faces culled, as the
//   city root); each agent drawn in GL gets an osg::MatrixTransform (double:
//   model frame -> world) over its prototype, made when the agent is first
//   drawn and kept for the run as a child of node() (children in agent-number
//   order); an agent not drawn at a frame has node mask 0, so a frame sets
//   masks and the matrices that changed, and never rebuilds the children.
//   With labels, a label twin per agent (the same vertex arrays; per-vertex
//   attributes kLabelAttrib = the agent's instance id, kLabelClassAttrib =
//   its class, nodes/label_pass.h) under labelNode(), shown alike.
// - setFrame(t, eye) places the agents of time t (placeAgents) and draws
//   every one of them in GL (node(), labelNode()); setSplit(d) then keeps in
//   GL only the agents whose bounding sphere reaches within d metres of the
//   eye (none for d <= 0) and hands to the attached ray scene those whose
//   sphere reaches beyond d (d = 0: every agent ray-cast, +inf: none). An
//   agent wholly inside the near field is never ray-cast; one straddling d
//   is in both, as a straddling chunk is: GL draws it up to the far plane
//   at d and the far field's rays, which start there, the rest. Without an
//   attached ray scene the agents beyond d are simply not drawn. A call that
//   changes nothing does no work; the ray scene's movers are placed (one
//   RayScene::placeMovers call) only when what it shows changes.
//   setFrame(t, eye, splitFollows = true) only moves the agents and lamps to
//   time t: the GL masks and the ray scene wait for the setSplit(d) that the
//   caller makes next (a frame with a split: one placement, not two).
// - An agent whose body (its model's box grown by 0.3 m) holds the eye is
//   the camera's carrier (the vehicle `vista path --traffic` rides) and is
//   drawn nowhere: a vehicle's cameras do not see it from inside.
// - Traffic-light heads (signal_heads.h): with the tracks' signal states
//   (TrafficTracks::signals), after showCitySignals() or setSignalHeads(),
//   every head gets a MatrixTransform (head frame ->
//   world) over one of the shared lamp overlays (lampOverlay(), one per
//   LampState) under signalNode(), the last child of node(); setFrame(t)
//   switches each head's overlay to SignalStates::lampAt(head, t), and the
//   split treats a head as an agent (its sphere: lampOverlayCentre(),
//   kLampOverlayRadius): within d in GL, beyond d a still object of the ray
//   scene (RayScene::placeMovers' `still` list, slot = head index; prototype
//   after the agents' ones, labelled as the head's static geometry:
//   InstanceKind::TrafficLight, class TrafficLight). A head's slot is
//   re-placed only when its lamp or its side of the split changes, so the
//   far field's cache serves its pixels on the other frames (far_field.h,
//   FarFieldOptions::cacheMovers). At a time
//   outside the run (before the tracks' first or after their last time) no
//   overlay is shown or cast: the static lamps show, as without traffic.
//   The label pass draws no overlay (the static head under it carries the
//   label).
//   Without signal states nothing of this exists (signalNode() is null).
// - The same time gives the same placements in every mode, face and run.
// Not thread-safe: the frame thread calls it between frames (no ray query
// may run meanwhile).
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <osg/Group>
#include <osg/ref_ptr>

#include "citygen/params.h"
#include "foundation/status.h"
#include "nodes/render/signal_heads.h"
#include "runtime/scene/paged_load.h"
#include "runtime/scene/scene_model.h"
#include "runtime/traffic/agent_models.h"
#include "runtime/traffic/traffic_tracks.h"

namespace vista {

class RayScene;

class TrafficScene {
public:
    // labels: also build the label twins (vista render). No traffic-light
    // head is shown until showCitySignals() or setSignalHeads().
    TrafficScene(std::shared_ptr<const TrafficTracks> tracks, const CityParams& params, bool labels);
    ~TrafficScene();
    // Shows the heads of `city` lit from the tracks' signal states (none
    // without them): signalHeads() of the street graph whose lane model
    // numbered the heads of the traffic's OpenDRIVE (`vista traffic`). That
    // is a city file's own graph; for a paged city (`paged`: its manifest,
    // loaded or streamed) the whole city's graph of pagedPathStreets(), as
    // `vista traffic` reads it: the graph merged from the loaded regions is
    // ordered otherwise, and a streamed city's model may hold no streets.
    // Errors: those of pagedPathStreets() and attachRays().
    Status showCitySignals(const SceneModel& city, const PagedManifest* paged);
    // The ray scene that shows the agents beyond the split (its prototypes are
    // added now); null detaches. Errors: those of RayScene::setMoverPrototypes.
    Status attachRays(RayScene* rays);
    RayScene* rays() const { return _rays; }
    Status setFrame(double t, const glm::dvec3& eye, bool splitFollows = false);
    Status setSplit(double nearDistance);
    // Shows `heads` lit from `states` (replacing any heads before; null
    // states or no heads: none). Errors: those of attachRays().
    Status setSignalHeads(std::shared_ptr<const SignalStates> states, std::vector<SignalHead> heads);
    osg::Group* signalNode() const { return _signalNode.get(); }
    const std::vector<SignalHead>& heads() const { return _heads; }
    // The lamp each head shows at the current time (heads() order).
    const std::vector<LampState>& lamps() const { return _lamps; }
    size_t headsDrawn() const { return _headsDrawn; }  // heads in GL this frame
    size_t headsCast() const { return _headsCast; }    // heads in the ray scene this frame
    double time() const { return _t; }
    osg::Group* node() const { return _node.get(); }
    osg::Group* labelNode() const { return _labelNode.get(); }
    const TrafficTracks& tracks() const { return *_tracks; }
    // The agents placed at the current time (agent number order).
    const std::vector<AgentPlacement>& placements() const { return _placed; }
    const AgentModels& models() const { return _models; }
    double tallestAgent() const;                  // metres: the tallest model's height
    size_t drawnCount() const { return _drawn; }  // agents in GL this frame
    size_t castCount() const { return _cast; }    // agents in the ray scene this frame
    // MatrixTransforms made so far (an agent's and its label twin's, once per run).
    size_t nodesMade() const;

private:
    Status apply();
    void show(uint32_t agent, uint32_t prototype, const glm::dmat4& transform);
    std::shared_ptr<const TrafficTracks> _tracks;
    CityParams _params;
    bool _labels;
    AgentModels _models;
    RayScene* _rays = nullptr;
    double _t = -1e300;
    glm::dvec3 _eye{0.0};
    double _split = 1e300;
    bool _placedValid = false;
    std::vector<AgentPlacement> _placed;
    std::vector<uint8_t> _inGl;  // per placement: drawn by GL (after apply)
    size_t _drawn = 0, _cast = 0;
    std::vector<uint32_t> _castAgents;  // agents in the ray scene, in order (change detection)
    std::vector<glm::dmat4> _castTransforms;
    struct Impl;
    std::unique_ptr<Impl> _impl;
    osg::ref_ptr<osg::Group> _node, _labelNode, _signalNode;
    std::shared_ptr<const SignalStates> _signals;
    std::vector<SignalHead> _heads;
    std::vector<LampState> _lamps;
    size_t _headsDrawn = 0, _headsCast = 0;
    void updateLamps();
};

}  // namespace vista
