// A traffic run's agents in the near field and the ray scene (traffic_scene.h).
#include "nodes/render/traffic_scene.h"

#include <algorithm>
#include <cmath>

#include <osg/CullFace>
#include <osg/Geode>
#include <osg/Geometry>
#include <osg/MatrixTransform>

#include "citygen/labels.h"
#include "citygen/lighting.h"
#include "nodes/label_pass.h"
#include "runtime/engine/ray_scene.h"
#include "runtime/scene/scene_graph.h"

namespace vista {

// The GL side: one MatrixTransform per agent (and its label twin), made
// when the agent is first drawn and a child of node() (labelNode()) from
// then on, in agent-number order; an agent not drawn this frame has node
// mask 0. A frame therefore changes masks and matrices, never the children.
struct TrafficScene::Impl {
    std::vector<osg::ref_ptr<osg::Geode>> protos;                 // colour geometry per prototype
    std::vector<osg::ref_ptr<osg::MatrixTransform>> xf, labelXf;  // per agent, made on first use
    std::vector<uint32_t> children;                               // agents of node()'s children, in order
    std::vector<uint32_t> shown;                                  // agents whose node mask is on
    std::vector<uint8_t> isShown;                                 // per agent: in `shown`
    size_t made = 0;                                              // MatrixTransforms made (colour and label)
    // Scratch of apply(), kept across frames.
    std::vector<uint32_t> castAgents;
    std::vector<glm::dmat4> castXf;
    std::vector<MoverPlacement> movers;
    std::vector<StillPlacement> stills;  // per head: its slot among the ray scene's still objects
    std::vector<uint32_t> nextShown;
    // Per head: what its still slot shows (0 hidden, 1 + LampState cast; kUnplaced: not placed yet).
    std::vector<uint32_t> headKeys;
    // Traffic-light heads: the lamp overlay per LampState, a transform per head.
    std::vector<osg::ref_ptr<osg::Geode>> lampProtos;
    std::vector<osg::ref_ptr<osg::MatrixTransform>> headXf;
    std::vector<glm::dvec3> headCentre;  // world centre of each head's overlay sphere
};

namespace {

osg::ref_ptr<osg::Geometry> protoGeometry(const Mesh& m) {
    osg::ref_ptr<osg::Vec3Array> v = new osg::Vec3Array;
    osg::ref_ptr<osg::Vec3Array> n = new osg::Vec3Array;
    osg::ref_ptr<osg::Vec4ubArray> c = new osg::Vec4ubArray;
    for (size_t i = 0; i < m.positions.size(); ++i) {
        v->push_back(osg::Vec3(m.positions[i].x, m.positions[i].y, m.positions[i].z));
        const glm::vec3 nn = i < m.normals.size() ? m.normals[i] : glm::vec3(0, 0, 1);
        n->push_back(osg::Vec3(nn.x, nn.y, nn.z));
        c->push_back(osg::Vec4ub(m.colors[i].x, m.colors[i].y, m.colors[i].z, m.colors[i].w));
    }
    osg::ref_ptr<osg::Geometry> g = new osg::Geometry;
    g->setUseDisplayList(false);
    g->setUseVertexBufferObjects(true);
    g->setVertexArray(v.get());
    g->setNormalArray(n.get(), osg::Array::BIND_PER_VERTEX);
    g->setColorArray(c.get(), osg::Array::BIND_PER_VERTEX);
    g->addPrimitiveSet(new osg::DrawElementsUInt(GL_TRIANGLES, m.indices.begin(), m.indices.end()));
    return g;
}

osg::ref_ptr<osg::Geode> labelGeode(const osg::Geometry& colour, uint32_t id, uint8_t cls) {
    osg::ref_ptr<osg::Geometry> g = new osg::Geometry;
    g->setUseDisplayList(false);
    g->setUseVertexBufferObjects(true);
    g->setVertexArray(const_cast<osg::Array*>(colour.getVertexArray()));
    g->addPrimitiveSet(const_cast<osg::PrimitiveSet*>(colour.getPrimitiveSet(0)));
    const unsigned nv = colour.getVertexArray()->getNumElements();
    osg::ref_ptr<osg::UIntArray> ids = new osg::UIntArray(nv), classes = new osg::UIntArray(nv);
    std::fill(ids->begin(), ids->end(), GLuint(id));
    std::fill(classes->begin(), classes->end(), GLuint(cls));
    for (osg::UIntArray* a : {ids.get(), classes.get()}) {
        a->setPreserveDataType(true);
        a->setBinding(osg::Array::BIND_PER_VERTEX);
    }
    g->setVertexAttribArray(kLabelAttrib, ids.get(), osg::Array::BIND_PER_VERTEX);
    g->setVertexAttribArray(kLabelClassAttrib, classes.get(), osg::Array::BIND_PER_VERTEX);
    osg::ref_ptr<osg::Geode> geode = new osg::Geode;
    geode->addDrawable(g.get());
    return geode;
}

// True when the eye is inside the agent's body (grown by kCarrierMargin): the
// vehicle an ego path rides, which its own cameras do not see.
constexpr double kCarrierMargin = 0.3;
bool carries(const AgentPlacement& a, const AgentModel& m, const glm::dvec3& eye) {
    const glm::dvec3 d = eye - a.centre;
    const glm::dvec3 fwd(a.transform[0]), left(a.transform[1]);
    return std::abs(glm::dot(d, fwd)) <= 0.5 * m.length + kCarrierMargin &&
           std::abs(glm::dot(d, left)) <= 0.5 * m.width + kCarrierMargin && d.z >= -kCarrierMargin &&
           d.z <= m.height + kCarrierMargin;
}

constexpr uint32_t kUnplaced = ~0u;

osg::Matrixd toOsg(const glm::dmat4& m) {
    osg::Matrixd o;
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) o(c, r) = m[c][r];
    return o;
}

}  // namespace

TrafficScene::TrafficScene(std::shared_ptr<const TrafficTracks> tracks, const CityParams& params, bool labels)
    : _tracks(std::move(tracks)), _params(params), _labels(labels), _impl(new Impl) {
    _models = agentModels(Lighting(params));
    _node = new osg::Group;
    _node->setName("vista.traffic");
    _node->setDataVariance(osg::Object::DYNAMIC);
    osg::StateSet* ss = _node->getOrCreateStateSet();
    ss->setMode(GL_LIGHTING, osg::StateAttribute::OFF);
    ss->setAttributeAndModes(new osg::CullFace(osg::CullFace::BACK), osg::StateAttribute::ON);
    for (const AgentModel& m : _models.models) {
        osg::ref_ptr<osg::Geode> g = new osg::Geode;
        g->addDrawable(protoGeometry(m.mesh).get());
        _impl->protos.push_back(g);
    }
    if (_labels) {
        _labelNode = new osg::Group;
        _labelNode->setName("vista.traffic.labels");
        _labelNode->setDataVariance(osg::Object::DYNAMIC);
        _labelNode->setStateSet(labelRootState().get());
    }
}

Status TrafficScene::showCitySignals(const SceneModel& city, const PagedManifest* paged) {
    if (!_tracks->signals) return Status::ok();
    if (!paged) return setSignalHeads(_tracks->signals, signalHeads(city.streets, _params));
    auto streets = pagedPathStreets(*paged);
    if (!streets) return Status::error("--traffic: the traffic-light heads: " + streets.status().message());
    return setSignalHeads(_tracks->signals, signalHeads(*streets, _params));
}

Status TrafficScene::setSignalHeads(std::shared_ptr<const SignalStates> states, std::vector<SignalHead> heads) {
    Impl& im = *_impl;
    if (_signalNode) _node->removeChild(_signalNode.get());
    _signalNode = nullptr;
    im.headXf.clear();
    im.headCentre.clear();
    _signals = std::move(states);
    _heads = _signals ? std::move(heads) : std::vector<SignalHead>();
    _lamps.assign(_heads.size(), LampState::Off);
    if (!_heads.empty()) {
        if (im.lampProtos.empty())
            for (int k = 0; k < kLampStates; ++k) {
                osg::ref_ptr<osg::Geode> g = new osg::Geode;
                g->addDrawable(protoGeometry(lampOverlay(LampState(k))).get());
                im.lampProtos.push_back(g);
            }
        _signalNode = new osg::Group;
        _signalNode->setName("vista.traffic.signals");
        _signalNode->setDataVariance(osg::Object::DYNAMIC);
        for (const SignalHead& h : _heads) {
            osg::ref_ptr<osg::MatrixTransform> x = new osg::MatrixTransform(toOsg(h.frame));
            x->setDataVariance(osg::Object::DYNAMIC);
            x->addChild(im.lampProtos[0].get());
            _signalNode->addChild(x.get());
            im.headXf.push_back(x);
            im.headCentre.push_back(glm::dvec3(h.frame * glm::dvec4(lampOverlayCentre(), 1.0)));
        }
        _node->addChild(_signalNode.get());  // the last child: agents insert before it
        updateLamps();
    }
    if (_rays) return attachRays(_rays);  // the lamp prototypes join the movers'
    return apply();
}

void TrafficScene::updateLamps() {
    Impl& im = *_impl;
    for (size_t i = 0; i < _heads.size(); ++i) {
        const LampState l = _signals->lampAt(_heads[i].signal, _t);
        if (l == _lamps[i] && im.headXf[i]->getChild(0) == im.lampProtos[size_t(l)].get()) continue;
        _lamps[i] = l;
        im.headXf[i]->setChild(0, im.lampProtos[size_t(l)].get());
    }
}

TrafficScene::~TrafficScene() {
    const std::vector<StillPlacement> none;
    if (_rays && _cast + _headsCast > 0) (void)_rays->placeMovers({}, &none);
}

Status TrafficScene::attachRays(RayScene* rays) {
    const std::vector<StillPlacement> none;
    if (_rays && _rays != rays && _cast + _headsCast > 0) VISTA_RETURN_IF_ERROR(_rays->placeMovers({}, &none));
    _impl->headKeys.assign(_heads.size(), kUnplaced);
    _castAgents.clear();
    _castTransforms.clear();
    _cast = 0;
    _headsCast = 0;
    _rays = rays;
    if (!_rays) return apply();
    std::vector<SceneMesh> protos;
    for (const AgentModel& m : _models.models) {
        SceneMesh s;
        s.material = m.type == AgentType::Pedestrian ? Material::Pedestrian : Material::Vehicle;
        s.positions = m.mesh.positions;
        s.colors = m.mesh.colors;
        s.indices = m.mesh.indices;
        protos.push_back(std::move(s));
    }
    if (!_heads.empty())
        for (int k = 0; k < kLampStates; ++k) {  // prototypes models.size() + LampState
            const Mesh m = lampOverlay(LampState(k));
            SceneMesh s;
            s.material = Material::TrafficLight;
            s.positions = m.positions;
            s.colors = m.colors;
            s.indices = m.indices;
            protos.push_back(std::move(s));
        }
    VISTA_RETURN_IF_ERROR(_rays->setMoverPrototypes(protos));
    return apply();
}

double TrafficScene::tallestAgent() const {
    double h = 0;
    for (const AgentModel& m : _models.models) h = std::max(h, m.height);
    return h;
}

Status TrafficScene::setFrame(double t, const glm::dvec3& eye, bool splitFollows) {
    const bool moved = !_placedValid || t != _t;
    _t = t;
    _eye = eye;
    _split = 1e300;
    if (moved) {
        _placed = placeAgents(*_tracks, _models, _params, t);
        _placedValid = true;
        if (!_heads.empty()) updateLamps();
    }
    return splitFollows ? Status::ok() : apply();
}

Status TrafficScene::setSplit(double nearDistance) {
    _split = nearDistance;
    return apply();
}

size_t TrafficScene::nodesMade() const { return _impl->made; }

// The agent's nodes (made and inserted among node()'s children in agent order
// on its first use), shown at `transform`.
void TrafficScene::show(uint32_t agent, uint32_t prototype, const glm::dmat4& transform) {
    Impl& im = *_impl;
    if (im.xf.size() <= agent) {
        im.xf.resize(size_t(agent) + 1);
        im.labelXf.resize(size_t(agent) + 1);
        im.isShown.resize(size_t(agent) + 1, 0);
    }
    osg::ref_ptr<osg::MatrixTransform>& x = im.xf[agent];
    osg::ref_ptr<osg::MatrixTransform>& lx = im.labelXf[agent];
    if (!x) {
        x = new osg::MatrixTransform;
        x->setDataVariance(osg::Object::DYNAMIC);
        x->addChild(im.protos[prototype].get());
        ++im.made;
        const size_t at = size_t(std::lower_bound(im.children.begin(), im.children.end(), agent) - im.children.begin());
        im.children.insert(im.children.begin() + std::ptrdiff_t(at), agent);
        _node->insertChild(unsigned(at), x.get());
        if (_labelNode) {
            lx = new osg::MatrixTransform;
            lx->setDataVariance(osg::Object::DYNAMIC);
            const AgentType type = _tracks->agentTypes[agent];
            auto* geo = static_cast<osg::Geometry*>(im.protos[prototype]->getDrawable(0));
            lx->addChild(labelGeode(*geo, agentLabel(type, agent), agentClass(type)).get());
            ++im.made;
            _labelNode->insertChild(unsigned(at), lx.get());
        }
    }
    const osg::Matrixd m = toOsg(transform);
    if (x->getMatrix() != m) {
        x->setMatrix(m);
        if (lx) lx->setMatrix(m);
    }
    if (!im.isShown[agent]) {
        x->setNodeMask(~0u);
        if (lx) lx->setNodeMask(~0u);
    }
}

Status TrafficScene::apply() {
    Impl& im = *_impl;
    im.castAgents.clear();
    im.castXf.clear();
    im.movers.clear();
    im.nextShown.clear();
    _drawn = 0;
    for (const AgentPlacement& a : _placed) {
        if (carries(a, _models.models[a.prototype], _eye)) continue;  // the camera's own vehicle
        const double d = glm::length(a.centre - _eye);
        const bool gl = _split > 0 && d - a.radius <= _split;
        const bool rays = d + a.radius > _split;
        if (rays && _rays) {
            im.castAgents.push_back(a.agent);
            im.castXf.push_back(a.transform);
            const AgentType type = _tracks->agentTypes[a.agent];
            im.movers.push_back({a.prototype, a.transform, agentLabel(type, a.agent), agentClass(type)});
        }
        if (!gl) continue;
        show(a.agent, a.prototype, a.transform);
        im.nextShown.push_back(a.agent);
        ++_drawn;
    }
    // Hide the agents drawn before and not now; mark the shown ones.
    for (uint32_t agent : im.shown) im.isShown[agent] = 0;
    for (uint32_t agent : im.nextShown) im.isShown[agent] = 1;
    for (uint32_t agent : im.shown)
        if (!im.isShown[agent]) {
            im.xf[agent]->setNodeMask(0u);
            if (im.labelXf[agent]) im.labelXf[agent]->setNodeMask(0u);
        }
    std::swap(im.shown, im.nextShown);
    // Heads: GL within the split, beyond it the ray scene's still objects (one slot per head,
    // re-placed only when its lamp or side of the split changes).
    _headsDrawn = 0;
    _headsCast = 0;
    const uint32_t lampProto0 = uint32_t(_models.models.size());
    // Outside the run's time span SUMO had no state: the static lamps show.
    const bool live = !_tracks->times.empty() && _t >= _tracks->times.front() && _t <= _tracks->times.back();
    bool headsChanged = false;
    im.headKeys.resize(_heads.size(), kUnplaced);
    im.stills.resize(_heads.size());
    for (size_t i = 0; i < _heads.size(); ++i) {
        const double d = glm::length(im.headCentre[i] - _eye);
        const bool gl = live && _split > 0 && d - kLampOverlayRadius <= _split;
        const bool rays = live && d + kLampOverlayRadius > _split && _rays;
        const unsigned mask = gl ? ~0u : 0u;
        if (im.headXf[i]->getNodeMask() != mask) im.headXf[i]->setNodeMask(mask);
        _headsDrawn += gl ? 1 : 0;
        _headsCast += rays ? 1 : 0;
        const uint32_t lamp = uint32_t(_lamps[i]);
        const uint32_t key = rays ? 1 + lamp : 0;
        if (key == im.headKeys[i]) continue;
        im.headKeys[i] = key;
        headsChanged = true;
        StillPlacement& sp = im.stills[i];
        sp.shown = rays;
        sp.object = {lampProto0 + lamp, _heads[i].frame, makeInstanceId(InstanceKind::TrafficLight, _heads[i].signal),
                     uint8_t(semanticClass(Material::TrafficLight))};
    }
    if (!_rays) {
        _cast = 0;
        return Status::ok();
    }
    _cast = im.movers.size();
    const bool agentsChanged = im.castAgents != _castAgents || im.castXf != _castTransforms;
    if (!agentsChanged && !headsChanged) return Status::ok();
    std::swap(_castAgents, im.castAgents);
    std::swap(_castTransforms, im.castXf);
    return _rays->placeMovers(im.movers, headsChanged ? &im.stills : nullptr);
}

}  // namespace vista
